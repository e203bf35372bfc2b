// Volumetric shadows and scattering (render/Scattering.h): they change the image as VTK's
// semantics say (a blocker between the light and an object darkens it, the blend's ends), stay
// finite at the extremes, and skipping stays lossless: every builder (whose shadow rays skip over
// the brick occupancy) equals Naive (whose shadow rays take every sample), on CPU and CUDA.
#include "TestUtil.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

using namespace spaceskip;

namespace {

RenderParams scattering(double blending, double reach, double g) {
  RenderParams rp;
  rp.shade = true;
  rp.ambient = 0.1;
  rp.scatteringBlending = blending;
  rp.globalIlluminationReach = reach;
  rp.scatteringAnisotropy = g;
  return rp;
}

/// Two directional lights and a positional one, as a light kit and a lamp would give.
void addLights(RenderParams& rp) {
  rp.useLights = true;
  Light key;
  key.position[0] = 3, key.position[1] = 2, key.position[2] = 5;
  key.diffuse[0] = 0.9, key.diffuse[1] = 0.8, key.diffuse[2] = 0.7;
  key.ambient[0] = key.ambient[1] = key.ambient[2] = 0.2;
  Light fill;
  fill.position[0] = -4, fill.position[1] = -1, fill.position[2] = 2;
  fill.diffuse[0] = fill.diffuse[1] = fill.diffuse[2] = 0.3;
  rp.lights = {key, fill};
}

vec4f at(const Image& img, int x, int y) { return img.rgba[size_t(y) * size_t(img.width) + size_t(x)]; }

void expectBuildersEqualNaive(const Volume& v, const TransferFunction& tf, const RenderParams& rp,
                              const std::string& what) {
  const Image ref = test::renderWith(v, tf, test::builder(BuilderKind::Naive), 30, 20, true, 40, BackendKind::CPU, rp);
  ASSERT_GT(test::coverage(ref), 0.0) << what << " renders nothing";
  for (const BuildParams& bp : test::skippingBuilders(true)) {
    const Image img = test::renderWith(v, tf, bp, 30, 20, true, 40, BackendKind::CPU, rp);
    EXPECT_LE(compareImages(ref, img).maxAbs, 1.f / 255.f) << what << " " << builderName(bp.builder) << " brick "
                                                          << bp.brick;
  }
}

TransferFunction rampOf(const Volume& v, const char* preset = "ramp") {
  double lo = 0, hi = 1;
  EXPECT_TRUE(v.scalarRange(lo, hi));
  return TransferFunction::preset(preset, lo, hi, 256);
}

}  // namespace

TEST(Scattering, EveryBuilderEqualsNaive) {
  for (const char* shape : {"nbody", "vessels"}) {
    Volume v = generateVolume(shape, vec3l{36, 40, 33});
    v.spacing[0] = 0.8;  // anisotropic: texture space and world space differ per axis
    v.spacing[2] = 1.3;
    const TransferFunction tf = rampOf(v);
    struct Case {
      double b, reach, g;
      int lights;  // 0: the headlight (a point light at the eye), 1: a directional light, 2: a light list
    };
    for (const Case c : {Case{0.5, 0.4, 0.0, 0}, Case{1.5, 1.0, 0.6, 0}, Case{2.0, 0.7, -0.4, 1}, Case{1.0, 1.0, 0.3, 2},
                         Case{2.0, 0.2, 0.0, 2}}) {
      RenderParams rp = scattering(c.b, c.reach, c.g);
      if (c.lights == 1) rp.lightDirection[0] = 1, rp.lightDirection[1] = 0.5, rp.lightDirection[2] = -0.3;
      if (c.lights == 2) addLights(rp);
      const std::string what = std::string(shape) + " blending " + std::to_string(c.b) + " reach " +
                               std::to_string(c.reach) + " g " + std::to_string(c.g) + " lights " +
                               std::to_string(c.lights);
      expectBuildersEqualNaive(v, tf, rp, what);
    }
    // Cropping: shadow rays then take every sample on every builder (the occupancy has the
    // cropped-away bricks empty; VTK's shadow rays still see those voxels).
    RenderParams cut = scattering(2.0, 1.0, 0.0);
    cut.clipPlanes = {{1, 0, 0, -10}};
    expectBuildersEqualNaive(v, tf, cut, std::string(shape) + " clipped");
  }
}

TEST(Scattering, ABlockerCastsAShadow) {
  // A dense blob at x ~ 12 lit by a directional light from +x; a second blob at x ~ 28, between
  // it and the light, in one of the two volumes. Seen along z, the first blob's pixels are darker
  // with the blocker than without it; with scattering off (gradient shading only) they are not.
  auto scene = [](bool blocker) {
    return test::makeVolume<uint8_t>(40, 24, 24, VoxelType::UInt8, [blocker](int i, int j, int k) {
      const auto blob = [&](int cx) {
        const double d = std::hypot(i - cx, j - 12, k - 12);
        return d < 5 ? 200 : 0;
      };
      return std::max(blob(12), blocker ? blob(28) : 0);
    });
  };
  const Volume with = scene(true), without = scene(false);
  TransferFunction tf = TransferFunction::fromPoints({{0, 1.f, 1.f, 1.f, 0.f}, {100, 1.f, 1.f, 1.f, 0.f},
                                                      {200, 1.f, 0.9f, 0.8f, 0.6f}},
                                                     0, 255, 256);
  auto draw = [&](const Volume& v, const RenderParams& rp) {
    Engine e(BackendKind::CPU);
    test::load(e, v, tf, test::builder(BuilderKind::Grid));
    e.setRenderParams(rp);
    Image img;
    e.render(test::orbit(v, 0, 0), 80, 48, img);
    return img;
  };
  RenderParams rp = scattering(2.0, 1.0, 0.0);  // pure scattering, shadow rays to the box
  rp.lightDirection[0] = 1;
  const Image a = draw(with, rp), b = draw(without, rp);
  // The first blob's centre: x = 12 of 39 cells across the 80 pixels of a square-fitted view.
  int darker = 0, drawn = 0;
  for (int y = 16; y < 32; ++y)
    for (int x = 14; x < 34; ++x) {
      const vec4f pa = at(a, x, y), pb = at(b, x, y);
      if (pb.w < 0.1f) continue;
      ++drawn;
      if (pa.x < pb.x - 0.05f) ++darker;
    }
  ASSERT_GT(drawn, 20);
  EXPECT_GT(darker, drawn / 2) << "the blocker darkens the lit blob";
  RenderParams off = rp;
  off.scatteringBlending = 0;
  // Without scattering, the first blob's pixels do not depend on the blocker (it lies behind
  // them along the light, out of the rays' way: the view is along z).
  const Image oa = draw(with, off), ob = draw(without, off);
  float worst = 0;
  for (int y = 16; y < 32; ++y)
    for (int x = 14; x < 34; ++x) worst = std::max(worst, std::fabs(at(oa, x, y).x - at(ob, x, y).x));
  EXPECT_LE(worst, 1.f / 255.f);
}

TEST(Scattering, BlendEndsAndOff) {
  Volume v = generateVolume("vessels", vec3l{32, 32, 32});
  const TransferFunction tf = rampOf(v);
  const BuildParams grid = test::builder(BuilderKind::Grid);
  RenderParams shaded;
  shaded.shade = true;
  shaded.ambient = 0.1;
  const Image phong = test::renderWith(v, tf, grid, 30, 20, true, 48, BackendKind::CPU, shaded);
  // Not shaded: no scattering either (VTK draws it with shading only).
  RenderParams flat = scattering(2.0, 1.0, 0.0);
  flat.shade = false;
  EXPECT_EQ(compareImages(test::renderWith(v, tf, grid, 30, 20, true, 48, BackendKind::CPU, flat),
                          test::renderWith(v, tf, grid, 30, 20, true, 48))
                .maxAbs,
            0.f);
  // Every blending changes the shaded image; more blending, further from it.
  const float d1 = compareImages(phong, test::renderWith(v, tf, grid, 30, 20, true, 48, BackendKind::CPU,
                                                         scattering(0.3, 1.0, 0.0)))
                       .maxAbs;
  const float d2 = compareImages(phong, test::renderWith(v, tf, grid, 30, 20, true, 48, BackendKind::CPU,
                                                         scattering(2.0, 1.0, 0.0)))
                       .maxAbs;
  EXPECT_GT(d1, 0.f);
  EXPECT_GT(d2, d1);
  EXPECT_GT(d2, 0.05f);
  // Anisotropy changes it (a directional light: the phase function depends on the angle).
  RenderParams iso = scattering(2.0, 1.0, 0.0), fwd = scattering(2.0, 1.0, 0.7);
  iso.lightDirection[0] = fwd.lightDirection[0] = 1;
  EXPECT_GT(compareImages(test::renderWith(v, tf, grid, 30, 20, true, 48, BackendKind::CPU, iso),
                          test::renderWith(v, tf, grid, 30, 20, true, 48, BackendKind::CPU, fwd))
                .maxAbs,
            0.02f);
}

TEST(Scattering, ExtremesStayFinite) {
  // Reach 0 and 1, anisotropy at both ends (the phase function's spike), the largest blending,
  // a single-voxel-thick volume and a tiny sample distance: every pixel finite, in [0, 1].
  struct Case {
    vec3l dims;
    double reach, g, sampleDistance;
  };
  for (const Case c : {Case{{24, 24, 24}, 0.0, 1.0, 0}, Case{{24, 24, 24}, 1.0, -1.0, 0}, Case{{24, 24, 2}, 1.0, 0.5, 0},
                       Case{{20, 20, 20}, 1.0, 0.9, 0.05}}) {
    Volume v = generateVolume("nbody", c.dims);
    const TransferFunction tf = rampOf(v, "opaque");
    RenderParams rp = scattering(2.0, c.reach, c.g);
    rp.sampleDistance = c.sampleDistance;
    rp.lightDirection[2] = 1;
    for (BuilderKind k : {BuilderKind::Naive, BuilderKind::Grid, BuilderKind::KdTreeCPU}) {
      const Image img = test::renderWith(v, tf, test::builder(k), 30, 20, true, 32, BackendKind::CPU, rp);
      for (const vec4f& p : img.rgba) {
        ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::isfinite(p.w));
        ASSERT_GE(p.x, 0.f);
        ASSERT_LE(p.x, 1.f + 1e-6f);
        ASSERT_LE(p.w, 1.f + 1e-6f);
      }
    }
  }
}

TEST(Scattering, CudaBuildersEqualNaive) {
  SKIP_WITHOUT_CUDA();
  for (const char* shape : {"nbody", "vessels"}) {
    Volume v = generateVolume(shape, vec3l{64, 61, 67});
    v.spacing[1] = 0.7;
    const TransferFunction tf = rampOf(v);
    RenderParams head = scattering(1.5, 1.0, 0.5), kit = scattering(2.0, 0.6, -0.3);
    addLights(kit);
    test::expectCudaBuildersEqualNaive(v, tf, head, std::string(shape) + " headlight");
    test::expectCudaBuildersEqualNaive(v, tf, kit, std::string(shape) + " lights");
  }
}

TEST(Scattering, CudaQueuedShadowRaysEqualMarchedInPlace) {
  // On the GPU the primary rays queue their shadow rays and a second kernel marches them
  // (Tuning::deferShadows, render/Scattering.h scatterShade); the image must be the one of the
  // rays marched where their samples are, frame after frame (the queue is sized from the last
  // frame's rays: the first frame may overflow it, and the rays beyond it are marched in place).
  SKIP_WITHOUT_CUDA();
  Volume v = generateVolume("nbody", vec3l{64, 61, 67});
  v.spacing[1] = 0.7;
  const TransferFunction tf = rampOf(v);
  RenderParams head = scattering(1.5, 1.0, 0.5), kit = scattering(2.0, 0.6, -0.3);
  addLights(kit);
  for (const RenderParams& rp : {head, kit}) {
    for (BuilderKind k : {BuilderKind::Naive, BuilderKind::DistanceGrid, BuilderKind::KdTreeGPUFast}) {
      const std::string what = std::string(builderName(k)) + (rp.useLights ? " lights" : " headlight");
      auto engine = [&](bool defer) {
        auto e = std::make_unique<Engine>(BackendKind::CUDA);
        test::load(*e, v, tf, test::builder(k));
        Tuning t;
        t.deferShadows = defer;
        e->setTuning(t);
        e->setRenderParams(rp);
        return e;
      };
      auto inPlace = engine(false), queued = engine(true);
      for (int frame = 0; frame < 3; ++frame) {
        const Camera cam = test::orbit(v, 30 + 10 * frame, 20, true);
        Image a, b;
        inPlace->render(cam, 64, 64, a);
        EXPECT_EQ(inPlace->frameStats().queuedShadowRays, 0) << what;
        queued->render(cam, 64, 64, b);
        EXPECT_GT(queued->frameStats().queuedShadowRays, 0) << what << " frame " << frame << ": nothing queued";
        ASSERT_GT(test::coverage(a), 0.0) << what;
        EXPECT_LE(compareImages(a, b).maxAbs, 1.f / 255.f) << what << " frame " << frame;
      }
    }
  }
}

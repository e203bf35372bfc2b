// Blend modes and gradient shading: what each mode computes (VTK's semantics), and that every
// builder's image equals the Naive traversal's in every mode (lossless skipping).
#include "TestUtil.h"

#include <gtest/gtest.h>

#include "spaceskip/Backend.h"

#include <cstring>

using namespace spaceskip;

namespace {

struct Mode {
  const char* name;
  RenderParams rp;
};

/// The modes under test over a scalar range [lo, hi].
std::vector<Mode> allModes(double lo, double hi) {
  std::vector<Mode> m;
  RenderParams r;
  r.shade = true;
  r.ambient = 0.2;
  r.specular = 0.4;
  m.push_back({"composite+shade", r});
  r = RenderParams{};
  r.blend = BlendMode::MaximumIntensity;
  m.push_back({"mip", r});
  r.blend = BlendMode::MinimumIntensity;
  m.push_back({"minip", r});
  r.blend = BlendMode::AverageIntensity;
  m.push_back({"average", r});
  r.averageRange[0] = lo + 0.35 * (hi - lo);  // only the upper part counts: bricks below are skipped
  r.averageRange[1] = hi;
  m.push_back({"average-range", r});
  r = RenderParams{};
  r.blend = BlendMode::Additive;
  m.push_back({"additive", r});
  r.blend = BlendMode::Isosurface;
  r.isoValues = {lo + 0.6 * (hi - lo), lo + 0.3 * (hi - lo)};
  m.push_back({"iso", r});
  r.shade = true;
  m.push_back({"iso+shade", r});
  return m;
}

/// A w x h x d float volume filled by f(i, j, k), unit spacing.
template <class F>
Volume makeVolume(int w, int h, int d, F f) {
  return test::makeVolume<float>(w, h, d, VoxelType::Float32, f);
}

/// Transfer function with opacity `a` and colour (r, g, b) everywhere over [lo, hi].
TransferFunction flatTF(double lo, double hi, float r, float g, float b, float a) {
  return TransferFunction::fromPoints({{lo, r, g, b, a}, {hi, r, g, b, a}}, lo, hi, 256);
}

/// Opaque at low values, fading towards high values (gives MinIP something to show).
TransferFunction lowTF(double lo, double hi) {
  const double w = hi - lo;
  return TransferFunction::fromPoints({{lo, 0.9f, 0.8f, 0.2f, 0.9f}, {lo + 0.4 * w, 0.2f, 0.6f, 0.9f, 0.4f},
                                       {hi, 0.1f, 0.1f, 0.8f, 0.05f}},
                                      lo, hi, 256);
}

vec4f centre(const Image& img) { return img.rgba[size_t(img.height / 2) * size_t(img.width) + size_t(img.width / 2)]; }

}  // namespace

TEST(BlendModes, EveryBuilderEqualsNaiveInEveryMode) {
  struct Case {
    const char* shape;
    int n;
    bool lowTF;
  };
  const Case cases[] = {{"nbody", 48, false}, {"vessels", 48, false}, {"rm", 40, true}, {"menger", 40, false}};
  struct Cam {
    double az, el;
    bool persp;
  };
  const Cam cams[] = {{30, 20, false}, {200, -35, true}};
  for (const Case& c : cases) {
    Volume v = generateVolume(c.shape, vec3l{c.n, c.n + 2, c.n - 3});
    double lo, hi;
    ASSERT_TRUE(v.scalarRange(lo, hi));
    std::vector<Mode> modes = allModes(lo, hi);
    for (size_t i : {size_t(0), size_t(2), size_t(6)}) {  // VTK's first sample, one step in
      Mode m = modes[i];
      m.rp.firstSampleOffset = 1;
      modes.push_back(m);
    }
    for (const Mode& m : modes) {
      const bool low = c.lowTF || m.rp.blend == BlendMode::MinimumIntensity;
      TransferFunction tf = low ? lowTF(lo, hi) : TransferFunction::preset("ramp", lo, hi, 256);
      for (const Cam& cam : cams) {
        Image ref = test::renderWith(v, tf, test::builder(BuilderKind::Naive), cam.az, cam.el, cam.persp, 48,
                                     BackendKind::CPU, m.rp);
        ASSERT_GT(test::coverage(ref), 0.0) << c.shape << " " << m.name << " renders nothing";
        for (const BuildParams& bp : test::skippingBuilders(true)) {
          Image img = test::renderWith(v, tf, bp, cam.az, cam.el, cam.persp, 48, BackendKind::CPU, m.rp);
          ImageDiff d = compareImages(ref, img);
          EXPECT_LE(d.maxAbs, 1.f / 255.f) << c.shape << " " << m.name << " offset " << m.rp.firstSampleOffset << " "
                                           << builderName(bp.builder) << " brick "
                                           << bp.brick << " az " << cam.az;
          EXPECT_FALSE(hasNonFinite(img)) << c.shape << " " << m.name;
        }
      }
    }
  }
}

TEST(BlendModes, ModesDifferFromEachOther) {
  Volume v = generateVolume("vessels", vec3l{48, 48, 48});
  double lo, hi;
  ASSERT_TRUE(v.scalarRange(lo, hi));
  auto tf = TransferFunction::preset("ramp", lo, hi, 256);
  std::vector<Mode> modes = allModes(lo, hi);
  modes.insert(modes.begin(), Mode{"composite", RenderParams{}});
  std::vector<Image> imgs;
  for (const Mode& m : modes)
    imgs.push_back(test::renderWith(v, m.rp.blend == BlendMode::MinimumIntensity ? lowTF(lo, hi) : tf,
                                    test::builder(BuilderKind::Grid), 30, 20, false, 48, BackendKind::CPU, m.rp));
  for (size_t a = 0; a < imgs.size(); ++a)
    for (size_t b = a + 1; b < imgs.size(); ++b)
      EXPECT_GT(compareImages(imgs[a], imgs[b]).maxAbs, 0.02f) << modes[a].name << " vs " << modes[b].name;
}

TEST(BlendModes, MipAndMinipMapTheExtremeSampleWithRawOpacity) {
  // Values grow with x: viewed along z, each pixel's ray sees one x, so MIP == MinIP == TF(x),
  // with the TF's opacity uncorrected for the sample distance (as VTK's MIP does).
  Volume v = makeVolume(32, 32, 32, [](int i, int, int) { return float(i) * 8.f; });
  TransferFunction tf = TransferFunction::fromPoints({{0, 0.f, 0.f, 1.f, 0.1f}, {248, 1.f, 0.f, 0.f, 0.5f}}, 0, 248, 256);
  RenderParams mip, minip;
  mip.blend = BlendMode::MaximumIntensity;
  minip.blend = BlendMode::MinimumIntensity;
  mip.sampleDistance = minip.sampleDistance = 0.25;  // correction would change the opacity a lot
  Image a = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 0, 0, false, 64, BackendKind::CPU, mip);
  Image b = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 0, 0, false, 64, BackendKind::CPU, minip);
  EXPECT_LE(compareImages(a, b).maxAbs, 1e-4f);
  const vec4f c = centre(a);  // x = 15.5 at the centre: value 124, half way along the TF
  EXPECT_NEAR(c.w, 0.3f, 0.02f);
  EXPECT_NEAR(c.x / c.w, 0.5f, 0.03f);
  EXPECT_NEAR(c.z / c.w, 0.5f, 0.03f);
  // Along x instead, MIP sees the largest value and MinIP the smallest.
  Image mx = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 90, 0, false, 64, BackendKind::CPU, mip);
  Image mn = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 90, 0, false, 64, BackendKind::CPU, minip);
  EXPECT_NEAR(centre(mx).w, 0.5f, 0.01f);
  EXPECT_NEAR(centre(mn).w, 0.1f, 0.01f);
}

TEST(BlendModes, AverageAndAdditiveOfAConstantVolume) {
  // Constant value s (normalised 0.75 over [0, 200]) with opacity a = 0.4 everywhere.
  Volume v = makeVolume(20, 20, 20, [](int, int, int) { return 150.f; });
  TransferFunction tf = flatTF(0, 200, 1, 1, 1, 0.4f);
  RenderParams avg;
  avg.blend = BlendMode::AverageIntensity;
  avg.scalarRange[0] = 0;
  avg.scalarRange[1] = 200;
  Image a = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 0, 0, false, 32, BackendKind::CPU, avg);
  const vec4f c = centre(a);
  EXPECT_NEAR(c.x, 0.4f * 0.75f, 1e-4f);
  EXPECT_EQ(c.w, 1.f);
  avg.averageRange[0] = 160;  // no sample in range: nothing drawn (VTK discards the fragment)
  Image none = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 0, 0, false, 32, BackendKind::CPU, avg);
  EXPECT_EQ(test::coverage(none), 0.0);

  // Additive: opacity scaled by dt / unitDistance, so the sum is about path length * a * s.
  TransferFunction weak = flatTF(0, 200, 1, 1, 1, 0.02f);
  RenderParams add;
  add.blend = BlendMode::Additive;
  add.scalarRange[0] = 0;
  add.scalarRange[1] = 200;
  add.sampleDistance = 0.5;
  Image s = test::renderWith(v, weak, test::builder(BuilderKind::Grid), 0, 0, false, 32, BackendKind::CPU, add);
  const float expected = 19.f * 0.02f * 0.75f;  // 19 cells along z, 38 samples of 0.5 * 0.02 * 0.75
  EXPECT_NEAR(centre(s).x, expected, 0.02f);
  EXPECT_EQ(centre(s).w, 1.f);
  add.sampleDistance = 0.25;  // independent of the sample distance
  Image s2 = test::renderWith(v, weak, test::builder(BuilderKind::Grid), 0, 0, false, 32, BackendKind::CPU, add);
  EXPECT_NEAR(centre(s2).x, centre(s).x, 0.02f);
}

TEST(BlendModes, IsosurfaceCompositesEachCrossingWithTheIsoValuesColour) {
  // A ball: the value falls off from the centre. The central ray enters below the iso value,
  // crosses it going up and again going down: two crossings, both composited.
  const float R = 15.5f;
  Volume v = makeVolume(32, 32, 32, [&](int i, int j, int k) {
    const float x = float(i) - R, y = float(j) - R, z = float(k) - R;
    return 100.f - std::sqrt(x * x + y * y + z * z) * 6.f;
  });
  TransferFunction tf = TransferFunction::fromPoints({{-100, 1.f, 0.f, 0.f, 0.f}, {100, 0.f, 1.f, 0.f, 1.f}}, -100, 100, 256);
  RenderParams iso;
  iso.blend = BlendMode::Isosurface;
  iso.isoValues = {50};  // TF at 50: colour (0.25, 0.75, 0), opacity 0.75
  Image img = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 0, 0, false, 64, BackendKind::CPU, iso);
  const vec4f c = centre(img);
  const float a1 = 0.75f, a2 = 1.f - (1.f - a1) * (1.f - a1);  // two crossings
  EXPECT_NEAR(c.w, a2, 0.01f);
  EXPECT_NEAR(c.y / c.w, 0.75f, 0.01f);
  // Rays that miss the iso surface stay empty although the TF gives them opacity.
  EXPECT_EQ(img.rgba[0].w, 0.f);
  iso.isoValues = {150};  // above every value: nothing
  Image none = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 0, 0, false, 64, BackendKind::CPU, iso);
  EXPECT_EQ(test::coverage(none), 0.0);
}

TEST(Shading, LightFollowsTheGradient) {
  // Values grow with x. A light along x faces the gradient (|n.l| = 1): diffuse 1, ambient 0,
  // specular 0 gives the unshaded image. A light along z is perpendicular to it: black.
  Volume v = makeVolume(24, 24, 24, [](int i, int, int) { return float(i) * 10.f; });
  TransferFunction tf = TransferFunction::fromPoints({{0, 0.8f, 0.5f, 0.2f, 0.3f}, {230, 0.2f, 0.5f, 0.9f, 0.3f}}, 0, 230, 256);
  RenderParams plain, lit;
  lit.shade = true;
  lit.ambient = 0;
  lit.diffuse = 1;
  lit.specular = 0;
  lit.lightDirection[0] = 1;
  Image ref = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 90, 0, false, 32, BackendKind::CPU, plain);
  Image along = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 90, 0, false, 32, BackendKind::CPU, lit);
  EXPECT_LE(compareImages(ref, along).maxAbs, 2e-3f);
  ASSERT_GT(test::coverage(ref), 0.1);
  lit.lightDirection[0] = 0;
  lit.lightDirection[2] = -1;
  Image across = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 0, 0, false, 32, BackendKind::CPU, lit);
  EXPECT_GT(test::coverage(across), 0.1);
  for (const vec4f& p : across.rgba) EXPECT_LT(p.x + p.y + p.z, 1e-4f);
  // The headlight (VTK's: at the camera, seen from each ray's entry point) is within a degree of
  // the view axis at the centre pixel of this orthographic view.
  lit.lightDirection[2] = 0;
  const vec4f h = centre(test::renderWith(v, tf, test::builder(BuilderKind::Grid), 90, 0, false, 32, BackendKind::CPU, lit));
  const vec4f r = centre(ref);
  EXPECT_NEAR(h.x, r.x, 2e-3f);
  EXPECT_NEAR(h.z, r.z, 2e-3f);
  const vec4f c = centre(test::renderWith(v, tf, test::builder(BuilderKind::Grid), 0, 0, false, 32, BackendKind::CPU, lit));
  EXPECT_GT(c.w, 0.1f);
  EXPECT_LT(c.x + c.y + c.z, 0.05f);
  // Specular adds white regardless of colour; ambient scales the colour.
  lit.specular = 0.5;
  lit.diffuse = 0;
  Image spec = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 90, 0, false, 32, BackendKind::CPU, lit);
  const vec4f s = centre(spec);
  EXPECT_NEAR(s.x / s.w, 0.5f, 0.01f);
  EXPECT_NEAR(s.z / s.w, 0.5f, 0.01f);
}

TEST(Shading, AnisotropicSpacingTiltsTheNormal) {
  // f = 4(i + j) with spacing (1, 4, 1) has the world gradient (4, 1, 0), like f = 4i + j with unit
  // spacing (the normal (1, 1, 0) if spacing were ignored). Seen along x, both centres agree and
  // are dimmed by |n.l| = 4 / sqrt(17) = 0.970 (0.707 for the wrong normal).
  Volume a = makeVolume(24, 24, 24, [](int i, int j, int) { return float(i + j) * 4.f; });
  a.spacing[1] = 4;
  Volume b = makeVolume(24, 24, 24, [](int i, int j, int) { return float(4 * i + j); });
  TransferFunction tf = flatTF(0, 184, 1, 1, 1, 0.1f);
  RenderParams plain, lit;
  lit.shade = true;
  lit.ambient = 0;
  lit.diffuse = 1;
  lit.specular = 0;
  const vec4f ra = centre(test::renderWith(a, tf, test::builder(BuilderKind::Grid), 90, 0, false, 32, BackendKind::CPU, plain));
  const vec4f la = centre(test::renderWith(a, tf, test::builder(BuilderKind::Grid), 90, 0, false, 32, BackendKind::CPU, lit));
  const vec4f lb = centre(test::renderWith(b, tf, test::builder(BuilderKind::Grid), 90, 0, false, 32, BackendKind::CPU, lit));
  ASSERT_GT(ra.x, 0.05f);
  // Within 0.01, not closer: the two boxes' sample lattices meet the exit face differently (one
  // ray takes a sample on it, the other not: 0.0045 apart with Naive as with Grid).
  EXPECT_NEAR(la.x, lb.x, 1e-2f);
  EXPECT_NEAR(la.x / ra.x, 4.f / std::sqrt(17.f), 0.02f);
}

TEST(BlendModes, ValueRangesSkipSamplesInMip) {
  // Not a timing assertion: on sparse data MIP with value-range skipping takes fewer samples.
  Volume v = generateVolume("nbody", vec3l{128, 128, 128});
  auto tf = TransferFunction::preset("ramp", 0, 255);
  const Camera cam = test::orbit(v, 10, 10);
  RenderParams mip;
  mip.blend = BlendMode::MaximumIntensity;
  int64_t samples[2];
  Image img[2] = {test::renderCounting(v, tf, BuilderKind::Naive, cam, 64, samples[0], mip),
                  test::renderCounting(v, tf, BuilderKind::Grid, cam, 64, samples[1], mip)};
  EXPECT_GT(samples[0], 0);
  EXPECT_LT(samples[1] * 2, samples[0]) << "naive " << samples[0] << " value ranges " << samples[1];
  EXPECT_LE(compareImages(img[0], img[1]).maxAbs, 1.f / 255.f);
}

TEST(BlendModes, CudaEqualsCpuInEveryMode) {
  SKIP_WITHOUT_CUDA();
  Volume v = generateVolume("vessels", vec3l{64, 61, 67});
  double lo, hi;
  ASSERT_TRUE(v.scalarRange(lo, hi));
  for (const Mode& m : allModes(lo, hi)) {
    TransferFunction tf = m.rp.blend == BlendMode::MinimumIntensity ? lowTF(lo, hi)
                                                                    : TransferFunction::preset("ramp", lo, hi, 256);
    test::expectCudaBuildersEqualNaive(v, tf, m.rp, m.name);
  }
}

// The CPU backend's SIMD ray packets (Core/src/CpuMarch.*) take exactly the scalar integrator's
// samples with the same float operations: the image is the same bit for bit. The scalar
// integrator still renders frames that count samples (RenderParams::countSamples), so the two
// are compared frame against frame: every voxel type, parallel and perspective views, jitter,
// the first sample one step in (as the VTK mapper asks), early ray termination, NaN and Inf
// voxels, a frame whose edges are not multiples of a packet and a camera inside the volume;
// and every skipping structure, each lane walking its own ray's runs; shaded frames (the
// headlight or directional lights, with and without specular reflection) too.
#include "TestUtil.h"

#include "src/CpuMarch.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

namespace spaceskip {
namespace {

/// `src` (uint8 noise-like) as type `t`, values spread over the type's range.
Volume convert(const Volume& src, VoxelType t) {
  Volume v;
  v.allocate(src.dims, t);
  const int64_t n = src.voxelCount();
  const uint8_t* s = static_cast<const uint8_t*>(src.data);
  dispatchVoxelType(t, [&](auto tag) {
    using T = decltype(tag);
    T* d = reinterpret_cast<T*>(v.mutableData());
    for (int64_t i = 0; i < n; ++i) {
      double x = s[i];
      if (std::is_same<T, int8_t>::value) x -= 128;
      if (std::is_same<T, uint16_t>::value) x *= 257;
      if (std::is_same<T, int16_t>::value) x = (x - 128) * 250;
      if (std::is_floating_point<T>::value) x = x * 0.37 - 11.0;
      d[i] = T(x);
    }
  });
  v.data = v.mutableData();
  return v;
}

struct Frame {
  Image img;
};

Image render(const Volume& v, const TransferFunction& tf, RenderParams rp, bool scalar, double az, double el,
             bool persp, int w, int h, double zoom = 1.0, BuildParams bp = test::builder(BuilderKind::Naive),
             const Tuning& tuning = Tuning{}) {
  Engine e(BackendKind::CPU);
  e.setTuning(tuning);
  test::load(e, v, tf, bp);
  rp.countSamples = scalar;  // counting samples keeps the frame on the scalar integrator
  e.setRenderParams(rp);
  double b[6];
  v.worldBounds(b);
  Image img;
  e.render(orbitCamera(b, az, el, zoom, persp, double(w) / double(h)), w, h, img);
  return img;
}

void expectSameBits(const Image& a, const Image& b, const std::string& what) {
  ASSERT_EQ(a.rgba.size(), b.rgba.size()) << what;
  size_t diff = 0, first = 0;
  for (size_t i = 0; i < a.rgba.size(); ++i)
    if (std::memcmp(&a.rgba[i], &b.rgba[i], sizeof(vec4f)) != 0 && diff++ == 0) first = i;
  EXPECT_EQ(diff, 0u) << what << ": first differing pixel " << first << " of " << a.rgba.size();
}

double coverage(const Image& img) {
  double s = 0;
  for (const auto& p : img.rgba) s += p.w;
  return s / double(img.rgba.size());
}

TEST(CpuMarch, PacketsEqualTheScalarIntegratorBitForBit) {
  std::printf("packets run on: %s\n", packetTarget());
  const Volume base = generateVolume("noise", vec3l{37, 29, 33});
  const VoxelType types[] = {VoxelType::UInt8,   VoxelType::Int8,    VoxelType::UInt16,
                             VoxelType::Int16,   VoxelType::Float32, VoxelType::Float64};
  for (VoxelType t : types) {
    const Volume v = t == VoxelType::UInt8 ? base : convert(base, t);
    double lo = 0, hi = 1;
    ASSERT_TRUE(v.scalarRange(lo, hi));
    for (const char* preset : {"ramp", "spike", "coolwarm"}) {
      const TransferFunction tf = TransferFunction::preset(preset, lo, hi);
      for (int variant = 0; variant < 4; ++variant) {
        RenderParams rp;
        rp.firstSampleOffset = variant & 1 ? 1.0 : 0.0;
        rp.jitter = variant == 2;
        rp.jitterSeed = 7;
        rp.ertThreshold = variant == 3 ? 0.9 : 2.0;
        const bool persp = variant >= 2;
        const std::string what = std::string("type ") + std::to_string(int(t)) + " tf " + preset + " variant " +
                                 std::to_string(variant);
        const Image a = render(v, tf, rp, false, 35.0 + 20 * variant, 25.0, persp, 61, 47);
        const Image b = render(v, tf, rp, true, 35.0 + 20 * variant, 25.0, persp, 61, 47);
        ASSERT_GT(coverage(b), 0.0) << what << " renders nothing";
        expectSameBits(a, b, what);
      }
    }
  }
}

TEST(CpuMarch, NanInfVoxelsAndACameraInside) {
  Volume v = convert(generateVolume("noise", vec3l{24, 24, 24}), VoxelType::Float32);
  float* d = reinterpret_cast<float*>(v.mutableData());
  d[100] = std::numeric_limits<float>::quiet_NaN();
  d[2000] = std::numeric_limits<float>::infinity();
  d[3000] = -std::numeric_limits<float>::infinity();
  d[24 * 24 * 24 - 1] = std::numeric_limits<float>::quiet_NaN();
  double lo = 0, hi = 1;
  ASSERT_TRUE(v.scalarRange(lo, hi));
  const TransferFunction tf = TransferFunction::preset("ramp", lo, hi);
  RenderParams rp;
  for (bool persp : {false, true}) {
    expectSameBits(render(v, tf, rp, false, 10, 5, persp, 40, 40), render(v, tf, rp, true, 10, 5, persp, 40, 40),
                   persp ? "nan/inf persp" : "nan/inf ortho");
  }
  // Zoomed far in with a perspective camera: the eye inside the box, rays start at the near plane.
  expectSameBits(render(v, tf, rp, false, 30, 20, true, 33, 33, 8.0), render(v, tf, rp, true, 30, 20, true, 33, 33, 8.0),
                 "camera inside");
}

TEST(CpuMarch, EverySkippingStructureWalksTheSameRunsAsTheScalarIntegrator) {
  // Each lane walks its own ray's runs with the shared iterators: sparse data, where the runs
  // of neighbouring rays differ, with every CPU builder, and Grid and DistanceGrid also with
  // the sub-brick part walk (Tuning::cpuSubMasks).
  struct Case {
    const char* shape;
    VoxelType type;
    const char* tf;
  };
  const Case cases[] = {{"vessels", VoxelType::UInt8, "ramp"},
                        {"nbody", VoxelType::UInt16, "band"},
                        {"menger", VoxelType::Float32, "spike"}};
  const BuilderKind builders[] = {BuilderKind::Naive,   BuilderKind::Grid,   BuilderKind::DistanceGrid,
                                  BuilderKind::LBVHCPU, BuilderKind::KdTreeCPU, BuilderKind::Hybrid};
  for (const Case& c : cases) {
    const Volume g = generateVolume(c.shape, vec3l{48, 40, 44});
    const Volume v = c.type == VoxelType::UInt8 ? g : convert(g, c.type);
    double lo = 0, hi = 1;
    ASSERT_TRUE(v.scalarRange(lo, hi));
    const TransferFunction tf = TransferFunction::preset(c.tf, lo, hi);
    for (BuilderKind b : builders)
      for (int parts = 0; parts < (b == BuilderKind::Grid || b == BuilderKind::DistanceGrid ? 2 : 1); ++parts)
        for (int variant = 0; variant < 2; ++variant) {
          RenderParams rp;
          rp.firstSampleOffset = variant == 0 ? 1.0 : 0.0;
          rp.ertThreshold = variant == 1 ? 0.95 : 2.0;
          Tuning t;
          t.cpuSubMasks = parts == 1;
          const std::string what = std::string(c.shape) + " " + builderName(b) + (parts ? " parts" : "") + " variant " +
                                   std::to_string(variant);
          const BuildParams bp = test::builder(b, LeafCriterion::Deep, 0, 4, variant == 0 ? 8 : 4);
          const Image a = render(v, tf, rp, false, 50, 30 - 40 * variant, variant == 1, 53, 45, 1.0, bp, t);
          const Image s = render(v, tf, rp, true, 50, 30 - 40 * variant, variant == 1, 53, 45, 1.0, bp, t);
          ASSERT_GT(coverage(s), 0.0) << what << " renders nothing";
          expectSameBits(a, s, what);
        }
  }
}

TEST(CpuMarch, PacketsTakeShadedFramesWithDirectionalLights) {
  if (std::strcmp(packetTarget(), "none") == 0) GTEST_SKIP() << "built without Highway: no packets";
  FrameView f{};
  f.blend = BlendMode::Composite;
  f.tf.size = 256;
  f.dt = 0.5f;
  f.shade = 1;
  f.specular = 0.f;
  EXPECT_TRUE(packetMarchable(f, VoxelType::UInt8, 1, 8, 8, 8)) << "headlight, Specular 0";
  f.useLights = 1;
  f.numLights = 2;
  EXPECT_TRUE(packetMarchable(f, VoxelType::UInt8, 1, 8, 8, 8)) << "directional lights, Specular 0";
  f.lights[1].positional = 1;
  EXPECT_TRUE(packetMarchable(f, VoxelType::UInt8, 1, 8, 8, 8)) << "a positional light";
  f.lights[1].positional = 0;
  f.specular = 0.2f;
  EXPECT_TRUE(packetMarchable(f, VoxelType::UInt8, 1, 8, 8, 8)) << "directional lights, Specular 0.2";
  f.useLights = 0;
  EXPECT_TRUE(packetMarchable(f, VoxelType::UInt8, 1, 8, 8, 8)) << "headlight, Specular 0.2";
  f.scatter.on = 1;
  EXPECT_FALSE(packetMarchable(f, VoxelType::UInt8, 1, 8, 8, 8)) << "scattering: the scalar integrator";
}

TEST(CpuMarch, ShadedPacketsEqualTheScalarIntegratorBitForBit) {
  // The headlight (parallel and perspective views, a set light direction), a light kit of
  // directional lights and that kit plus a positional and a spot light (each one-sided and
  // two-sided), without and with specular reflection (VTK's
  // default 0.2, power 10; ParaView's 0), on an anisotropic grid (the gradient goes to
  // world space through the inverse transpose), every voxel type, skipping structures, jitter,
  // early ray termination and NaN/Inf voxels.
  Volume base = generateVolume("noise", vec3l{33, 27, 30});
  base.spacing[0] = 0.7;
  base.spacing[2] = 1.6;
  std::vector<Light> kit(3);
  kit[0].position[0] = 1, kit[0].position[1] = 2, kit[0].position[2] = 3;
  kit[0].diffuse[0] = 0.9, kit[0].diffuse[1] = 0.8, kit[0].diffuse[2] = 0.7;
  kit[0].specular[0] = 0.6, kit[0].specular[1] = 0.7, kit[0].specular[2] = 0.8;
  kit[0].ambient[0] = kit[0].ambient[1] = kit[0].ambient[2] = 0.1;
  kit[1].position[0] = -2, kit[1].position[1] = 0.5, kit[1].position[2] = -1;
  kit[1].diffuse[0] = 0.3, kit[1].diffuse[1] = 0.35, kit[1].diffuse[2] = 0.4;
  kit[2].position[0] = 0, kit[2].position[1] = -1, kit[2].position[2] = 0.2;
  // The kit plus a positional light with attenuation and a spot light (cone 40 degrees, falloff
  // exponent 2.5) whose cone takes in part of the volume.
  std::vector<Light> scene = kit;
  Light point, spot;
  point.positional = true;
  point.position[0] = 12, point.position[1] = -15, point.position[2] = 20;
  point.attenuation[1] = 0.02, point.attenuation[2] = 0.001;
  point.diffuse[0] = 0.7, point.diffuse[1] = 0.9, point.diffuse[2] = 0.6;
  spot.positional = true;
  spot.position[0] = 45, spot.position[1] = 13, spot.position[2] = 24;
  spot.focalPoint[0] = 10, spot.focalPoint[1] = 13, spot.focalPoint[2] = 24;
  spot.coneAngle = 40;
  spot.exponent = 2.5;
  spot.specular[1] = 0.5;
  scene.push_back(point);
  scene.push_back(spot);
  const VoxelType types[] = {VoxelType::UInt8, VoxelType::Int16, VoxelType::UInt16, VoxelType::Float32};
  const BuilderKind builders[] = {BuilderKind::Naive, BuilderKind::Grid, BuilderKind::DistanceGrid,
                                  BuilderKind::KdTreeCPU};
  int variant = 0;
  for (VoxelType t : types) {
    Volume v = t == VoxelType::UInt8 ? base : convert(base, t);
    v.spacing[0] = 0.7;
    v.spacing[2] = 1.6;
    if (t == VoxelType::Float32) {
      float* d = reinterpret_cast<float*>(v.mutableData());
      d[500] = std::numeric_limits<float>::quiet_NaN();
      d[4000] = std::numeric_limits<float>::infinity();
    }
    double lo = 0, hi = 1;
    ASSERT_TRUE(v.scalarRange(lo, hi));
    if (t == VoxelType::Float32) lo = -11.0, hi = 83.0;  // the finite values' range
    for (const char* preset : {"ramp", "spike"})
      for (BuilderKind b : builders)
        for (int lights = 0; lights < 6; ++lights, ++variant) {
          const TransferFunction tf = TransferFunction::preset(preset, lo, hi);
          RenderParams rp;
          rp.shade = true;
          rp.ambient = 0.15;
          rp.diffuse = 0.8;
          // Every other builder with specular reflection (VTK's default 0.2, power 10, or more),
          // the others without (ParaView's default 0).
          rp.specular = (variant / 4) % 2 ? 0.0 : 0.2 + 0.1 * (variant % 3);
          rp.specularPower = (variant / 8) % 2 ? 37.5 : 10.0;
          rp.jitter = variant % 3 == 0;
          rp.jitterSeed = 11;
          rp.firstSampleOffset = variant % 2 ? 1.0 : 0.0;
          rp.ertThreshold = variant % 5 == 0 ? 0.9 : 2.0;
          if (lights == 1) rp.lightDirection[0] = 0.3, rp.lightDirection[1] = -0.5, rp.lightDirection[2] = 0.8;
          if (lights >= 2) {
            rp.useLights = true;
            rp.lights = lights >= 4 ? scene : kit;
            rp.twoSidedLighting = lights % 2 == 1;
          }
          const bool persp = lights != 1;
          const std::string what = std::string("type ") + std::to_string(int(t)) + " tf " + preset + " " +
                                   builderName(b) + " lights " + std::to_string(lights) + " specular " +
                                   std::to_string(rp.specular);
          const BuildParams bp = test::builder(b, LeafCriterion::Deep, 0, 4, 8);
          const double az = 25.0 + 17.0 * (variant % 7), el = 30.0 - 9.0 * (variant % 5);
          const Image a = render(v, tf, rp, false, az, el, persp, 45, 38, 1.0, bp);
          const Image s = render(v, tf, rp, true, az, el, persp, 45, 38, 1.0, bp);
          ASSERT_GT(coverage(s), 0.0) << what << " renders nothing";
          expectSameBits(a, s, what);
        }
  }
}

TEST(CpuMarch, GradientTablePacketsEqualTheScalarIntegratorBitForBit) {
  // Gradient opacity and a 2-D table over (value, gradient magnitude) (ParaView's *Use Transfer
  // 2D*), unshaded and shaded (the headlight, a light kit with a specular part), on an anisotropic
  // grid (VTK's per-axis gradient factors), every voxel type, skipping structures, jitter, early
  // ray termination and NaN/Inf voxels: the packets take these frames and draw the scalar image.
  if (std::strcmp(packetTarget(), "none") == 0) GTEST_SKIP() << "built without Highway: no packets";
  FrameView fv{};
  fv.blend = BlendMode::Composite;
  fv.tf.size = 256;
  fv.dt = 0.5f;
  for (int mode = 1; mode <= 3; ++mode) {
    fv.gtf.mode = mode;
    EXPECT_EQ(packetMarchable(fv, VoxelType::UInt8, 1, 8, 8, 8), mode != 3) << "gradient table mode " << mode;
  }
  Volume base = generateVolume("noise", vec3l{31, 29, 26});
  std::vector<Light> kit(2);
  kit[0].position[0] = 1, kit[0].position[1] = 2, kit[0].position[2] = 3;
  kit[0].diffuse[0] = 0.9, kit[0].diffuse[1] = 0.8, kit[0].diffuse[2] = 0.7;
  kit[0].specular[0] = 0.6, kit[0].specular[1] = 0.7, kit[0].specular[2] = 0.8;
  kit[1].position[0] = -2, kit[1].position[1] = 0.5, kit[1].position[2] = -1;
  const VoxelType types[] = {VoxelType::UInt8, VoxelType::Int16, VoxelType::Float32};
  const BuilderKind builders[] = {BuilderKind::Naive, BuilderKind::Grid, BuilderKind::DistanceGrid,
                                  BuilderKind::KdTreeCPU};
  int variant = 0;
  for (VoxelType t : types) {
    Volume v = t == VoxelType::UInt8 ? base : convert(base, t);
    v.spacing[0] = 0.8;
    v.spacing[2] = 1.5;
    if (t == VoxelType::Float32) {
      float* d = reinterpret_cast<float*>(v.mutableData());
      d[700] = std::numeric_limits<float>::quiet_NaN();
      d[5000] = std::numeric_limits<float>::infinity();
    }
    double lo = 0, hi = 1;
    ASSERT_TRUE(v.scalarRange(lo, hi));
    if (t == VoxelType::Float32) lo = -11.0, hi = 83.0;  // the finite values' range
    TransferFunction table = TransferFunction::preset("ramp", lo, hi, 256);
    test::setBox(table, 40, 20, 0.05f, 0.9f, 0.1f, 0.7f, 0.6f);
    TransferFunction gradientOpacity = TransferFunction::preset("ramp", lo, hi, 256);
    gradientOpacity.gradientOpacity.resize(128);
    for (size_t i = 0; i < gradientOpacity.gradientOpacity.size(); ++i)
      gradientOpacity.gradientOpacity[i] = i < 10 ? 0.f : float(i) / 127.f;
    for (const TransferFunction* tf : {&table, &gradientOpacity})
      for (BuilderKind b : builders)
        for (int shading = 0; shading < 3; ++shading, ++variant) {
          RenderParams rp;
          rp.shade = shading > 0;
          rp.ambient = 0.15;
          rp.diffuse = 0.8;
          rp.specular = shading == 2 ? 0.3 : 0.0;
          rp.useLights = shading == 2;
          if (rp.useLights) rp.lights = kit;
          rp.jitter = variant % 3 == 0;
          rp.jitterSeed = 7;
          rp.firstSampleOffset = variant % 2 ? 1.0 : 0.0;
          rp.ertThreshold = variant % 4 == 0 ? 0.9 : 2.0;
          const std::string what = std::string("type ") + std::to_string(int(t)) +
                                   (tf == &table ? " 2-D table " : " gradient opacity ") + builderName(b) +
                                   " shading " + std::to_string(shading);
          const BuildParams bp = test::builder(b, LeafCriterion::Deep, 0, 4, 8);
          const double az = 25.0 + 17.0 * (variant % 7), el = 30.0 - 9.0 * (variant % 5);
          const Image a = render(v, *tf, rp, false, az, el, variant % 2 == 0, 41, 36, 1.0, bp);
          const Image s = render(v, *tf, rp, true, az, el, variant % 2 == 0, 41, 36, 1.0, bp);
          ASSERT_GT(coverage(s), 0.0) << what << " renders nothing";
          expectSameBits(a, s, what);
        }
  }
}

TEST(CpuMarch, ClippedAndCroppedPacketsEqualTheScalarIntegratorBitForBit) {
  // Clipping planes cut each ray to one drawn part, cropping into up to seven, each walked by a
  // fresh traversal from the same lattice anchor; shaded and unshaded, every builder kind, the
  // first sample one step in (cropped rays start on the region's face), jitter.
  const Volume g = generateVolume("menger", vec3l{46, 38, 42});
  double lo = 0, hi = 1;
  ASSERT_TRUE(g.scalarRange(lo, hi));
  const TransferFunction tf = TransferFunction::preset("ramp", lo, hi);
  double b6[6];
  g.worldBounds(b6);
  const double cx = 0.5 * (b6[0] + b6[1]), cy = 0.5 * (b6[2] + b6[3]), cz = 0.5 * (b6[4] + b6[5]);
  const BuilderKind builders[] = {BuilderKind::Naive, BuilderKind::Grid, BuilderKind::DistanceGrid,
                                  BuilderKind::KdTreeCPU, BuilderKind::Hybrid};
  int variant = 0;
  for (BuilderKind b : builders)
    for (int cut = 0; cut < 4; ++cut, ++variant) {
      RenderParams rp;
      rp.firstSampleOffset = variant % 2 ? 1.0 : 0.0;
      rp.jitter = variant % 3 == 0;
      rp.jitterSeed = 5;
      rp.shade = variant % 4 >= 2;
      rp.specular = 0.0;
      if (cut == 0 || cut == 3) {  // two oblique planes through the middle
        rp.clipPlanes.push_back({0.6, 0.3, -0.74, -(0.6 * cx + 0.3 * cy - 0.74 * cz)});
        rp.clipPlanes.push_back({-0.2, 0.9, 0.38, -(-0.2 * cx + 0.9 * (cy - 6) + 0.38 * cz)});
      }
      if (cut >= 1) {  // the planes at a third and two thirds of each axis
        rp.cropping = true;
        for (int a = 0; a < 3; ++a) {
          rp.croppingPlanes[2 * a] = b6[2 * a] + (b6[2 * a + 1] - b6[2 * a]) / 3.0;
          rp.croppingPlanes[2 * a + 1] = b6[2 * a] + 2.0 * (b6[2 * a + 1] - b6[2 * a]) / 3.0;
        }
        // the sub-volume; a cross of regions (VTK's cross flags); everything but the sub-volume
        rp.croppingFlags = cut == 1 ? 0x2000 : cut == 2 ? 0x0410410 : (0x7ffffff & ~0x2000);
      }
      const std::string what = std::string(builderName(b)) + " cut " + std::to_string(cut) +
                               (rp.shade ? " shaded" : "") + " variant " + std::to_string(variant);
      const BuildParams bp = test::builder(b, LeafCriterion::Deep, 0, 4, 8);
      const double az = 30.0 + 23.0 * variant, el = 20.0 - 7.0 * (variant % 5);
      const Image a = render(g, tf, rp, false, az, el, variant % 2 == 0, 51, 43, 1.0, bp);
      const Image s = render(g, tf, rp, true, az, el, variant % 2 == 0, 51, 43, 1.0, bp);
      ASSERT_GT(coverage(s), 0.0) << what << " renders nothing";
      expectSameBits(a, s, what);
    }
  // The packets take these frames.
  if (std::strcmp(packetTarget(), "none") != 0) {
    FrameView f{};
    f.blend = BlendMode::Composite;
    f.tf.size = 256;
    f.dt = 0.5f;
    f.cut.numClipPlanes = 2;
    f.cut.cropping = 1;
    EXPECT_TRUE(packetMarchable(f, VoxelType::UInt8, 1, 8, 8, 8));
    f.shade = 1;
    EXPECT_TRUE(packetMarchable(f, VoxelType::UInt8, 1, 8, 8, 8));
  }
}

}  // namespace
}  // namespace spaceskip

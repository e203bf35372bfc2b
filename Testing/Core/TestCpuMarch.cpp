// The CPU backend's SIMD ray packets (Core/src/CpuMarch.*) take exactly the scalar integrator's
// samples with the same float operations: the image is the same bit for bit. The scalar
// integrator still renders frames that count samples (RenderParams::countSamples), so the two
// are compared frame against frame: every voxel type, parallel and perspective views, jitter,
// the first sample one step in (as the VTK mapper asks), early ray termination, NaN and Inf
// voxels, a frame whose edges are not multiples of a packet and a camera inside the volume;
// and every skipping structure, each lane walking its own ray's runs.
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
             bool persp, int w, int h, double zoom = 1.0, BuildParams bp = test::builder(BuilderKind::Naive)) {
  Engine e(BackendKind::CPU);
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
  // of neighbouring rays differ, with every CPU builder (the sub-brick part walk among them).
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
      for (int variant = 0; variant < 2; ++variant) {
        RenderParams rp;
        rp.firstSampleOffset = variant == 0 ? 1.0 : 0.0;
        rp.ertThreshold = variant == 1 ? 0.95 : 2.0;
        const std::string what = std::string(c.shape) + " " + builderName(b) + " variant " + std::to_string(variant);
        const BuildParams bp = test::builder(b, LeafCriterion::Deep, 0, 4, variant == 0 ? 8 : 4);
        const Image a = render(v, tf, rp, false, 50, 30 - 40 * variant, variant == 1, 53, 45, 1.0, bp);
        const Image s = render(v, tf, rp, true, 50, 30 - 40 * variant, variant == 1, 53, 45, 1.0, bp);
        ASSERT_GT(coverage(s), 0.0) << what << " renders nothing";
        expectSameBits(a, s, what);
      }
  }
}

}  // namespace
}  // namespace spaceskip

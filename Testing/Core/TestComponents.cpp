// Dependent multi-component volumes (render/Components.h): 2 components (colour value + opacity
// value) and 4 (RGB + opacity value) as vtkGPUVolumeRayCastMapper draws them, classification on
// the opacity channel so that every builder still draws the Naive image, and the CUDA twin.
#include "TestUtil.h"

#include <gtest/gtest.h>

#include "spaceskip/Backend.h"

#include <cmath>
#include <cstring>

using namespace spaceskip;

namespace {

constexpr float kTol = 1.f / 255.f;

float maxDiff(const Image& a, const Image& b) {
  EXPECT_EQ(a.rgba.size(), b.rgba.size());
  float m = 0;
  for (size_t i = 0; i < a.rgba.size() && i < b.rgba.size(); ++i) {
    const vec4f p = a.rgba[i], q = b.rgba[i];
    m = std::max({m, std::fabs(p.x - q.x), std::fabs(p.y - q.y), std::fabs(p.z - q.z), std::fabs(p.w - q.w)});
  }
  return m;
}

// Opacity channel: three soft blobs (0..250) in empty space, so most bricks are empty.
float blobs(int i, int j, int k) {
  const float c[3][3] = {{10, 9, 8}, {28, 24, 20}, {14, 26, 22}};
  float v = 0;
  for (auto& b : c) {
    const float dx = float(i) - b[0], dy = float(j) - b[1], dz = float(k) - b[2];
    v = std::max(v, 250.f - 30.f * std::sqrt(dx * dx + dy * dy + dz * dz));
  }
  return std::max(v, 0.f);
}

// Colour value: low (< 90: where the alpha table is transparent) inside the blobs, high
// elsewhere, so that classifying on this channel instead of the opacity channel would skip every
// blob brick.
float colourValue(int i, int j, int k) { return blobs(i, j, k) > 0 ? 20.f + 2.f * float(i % 30) : 160.f + float(j); }

/// A w x h x d volume of `nc` interleaved components of type T, component c = f(i, j, k, c).
template <class T, class F>
Volume makeVolume(int w, int h, int d, int nc, VoxelType type, F f) {
  Volume v;
  v.allocate(vec3l{w, h, d}, type, nc);
  T* p = reinterpret_cast<T*>(v.mutableData());
  for (int k = 0; k < d; ++k)
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w; ++i)
        for (int c = 0; c < nc; ++c) p[(i + int64_t(w) * (j + int64_t(h) * k)) * nc + c] = T(f(i, j, k, c));
  return v;
}

template <class T>
Volume twoComponents(VoxelType type) {
  return makeVolume<T>(40, 36, 30, 2, type,
                       [](int i, int j, int k, int c) { return c == 0 ? colourValue(i, j, k) : blobs(i, j, k); });
}

template <class T>
Volume fourComponents(VoxelType type) {
  return makeVolume<T>(40, 36, 30, 4, type, [](int i, int j, int k, int c) {
    switch (c) {
      case 0: return 6.f * float(i);
      case 1: return 7.f * float(j);
      case 2: return colourValue(i, j, k);
      default: return blobs(i, j, k);
    }
  });
}

/// Colour ramp over the colour range [0, 250], opacity over the opacity channel's [0, 250]:
/// transparent below 90.
TransferFunction dependentTF() {
  TransferFunction tf = TransferFunction::fromPoints(
      {{0, 1, 0, 0, 0}, {90, 1, 0.5f, 0, 0}, {180, 0, 1, 0.3f, 0.4f}, {250, 0.2f, 0.2f, 1, 0.9f}}, 0, 250, 256);
  tf.ownOpacityRange = true;
  tf.opacityRangeMin = 0;
  tf.opacityRangeMax = 250;
  return tf;
}

RenderParams shaded() {
  RenderParams r;
  r.shade = true;
  r.ambient = 0.2;
  r.specular = 0.4;
  return r;
}

void expectBuildersEqualNaive(const Volume& v, BackendKind backend) {
  const TransferFunction tf = dependentTF();
  for (const RenderParams& rp : {RenderParams{}, shaded()})
    for (const auto& [az, el] : {std::pair{30.0, 20.0}, std::pair{-70.0, 50.0}}) {
      const Image naive = test::renderWith(v, tf, test::builder(BuilderKind::Naive), az, el, false, 80, backend, rp);
      ASSERT_GT(test::coverage(naive), 0.01) << "the blobs must be visible";
      for (const BuildParams& p : test::skippingBuilders()) {
        const Image img = test::renderWith(v, tf, p, az, el, false, 80, backend, rp);
        EXPECT_LE(maxDiff(img, naive), kTol)
            << builderName(p.builder) << " brick " << p.brick << " shade " << rp.shade << " az " << az;
      }
    }
}

}  // namespace

TEST(Components, VolumeValidatesComponentCount) {
  Volume v;
  EXPECT_THROW(v.allocate(vec3l{4, 4, 4}, VoxelType::UInt8, 3), std::runtime_error);
  v.allocate(vec3l{4, 4, 4}, VoxelType::UInt8, 4);
  EXPECT_EQ(v.byteSize(), size_t(4 * 4 * 4 * 4));
  v.components = 3;
  EXPECT_THROW(validate(v), std::runtime_error);
}

TEST(Components, RangeGridReadsTheOpacityChannel) {
  const Volume two = twoComponents<uint8_t>(VoxelType::UInt8);
  const Volume alpha = makeVolume<uint8_t>(40, 36, 30, 1, VoxelType::UInt8,
                                           [](int i, int j, int k, int) { return blobs(i, j, k); });
  const RangeGrid a = computeRangeGrid(two), b = computeRangeGrid(alpha);
  EXPECT_EQ(a.vmin, b.vmin);
  EXPECT_EQ(a.vmax, b.vmax);
  double lo, hi;
  ASSERT_TRUE(two.componentRange(0, lo, hi));
  EXPECT_EQ(lo, 20.0);
  ASSERT_TRUE(two.componentRange(1, lo, hi));
  EXPECT_EQ(hi, 250.0);
}

// Colour and opacity from the same values: the 2-component image is the 1-component image.
TEST(Components, TwoEqualChannelsDrawTheScalarImage) {
  const Volume one = makeVolume<float>(40, 36, 30, 1, VoxelType::Float32,
                                       [](int i, int j, int k, int) { return blobs(i, j, k); });
  const Volume two = makeVolume<float>(40, 36, 30, 2, VoxelType::Float32,
                                       [](int i, int j, int k, int) { return blobs(i, j, k); });
  TransferFunction tf = dependentTF();
  tf.ownOpacityRange = false;
  TransferFunction tf2 = tf;
  tf2.ownOpacityRange = true;
  tf2.opacityRangeMin = tf.rangeMin;
  tf2.opacityRangeMax = tf.rangeMax;
  for (const RenderParams& rp : {RenderParams{}, shaded()}) {
    const Image a = test::renderWith(one, tf, test::builder(BuilderKind::Grid), 30, 20, true, 80, BackendKind::CPU, rp);
    const Image b = test::renderWith(two, tf2, test::builder(BuilderKind::Grid), 30, 20, true, 80, BackendKind::CPU, rp);
    ASSERT_GT(test::coverage(a), 0.01);
    EXPECT_LE(maxDiff(a, b), 1e-6f) << "shade " << rp.shade;
  }
}

// The opacity channel decides opacity, the colour channel colour: a colour TF that is red below
// 90 and green-blue above draws the blobs (colour values < 90) red.
TEST(Components, TwoComponentsColourFromChannelZero) {
  const Volume v = twoComponents<uint8_t>(VoxelType::UInt8);
  TransferFunction tf = TransferFunction::fromPoints({{0, 1, 0, 0, 0}, {89, 1, 0, 0, 0}, {91, 0, 0, 1, 0.5f},
                                                      {250, 0, 0, 1, 0.5f}},
                                                     0, 250, 256);
  tf.ownOpacityRange = true;
  tf.opacityRangeMin = 0;
  tf.opacityRangeMax = 250;
  const Image img = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 30, 20);
  double r = 0, b = 0;
  for (const vec4f& p : img.rgba) {
    r += p.x;
    b += p.z;
  }
  EXPECT_GT(test::coverage(img), 0.01);
  EXPECT_GT(r, 0.0);
  EXPECT_EQ(b, 0.0) << "the colour channel is below 90 wherever the opacity channel is visible";
}

// 4 components: RGB straight from the data, each normalised over its own range as
// vtkVolumeTexture's scale and bias do (red: [0, 255] -> 255 is 1; green, blue constant -> 0).
TEST(Components, FourComponentsDirectColour) {
  const Volume v = makeVolume<uint8_t>(24, 24, 24, 4, VoxelType::UInt8, [](int i, int j, int k, int c) {
    if (c == 0) return i == 0 && j == 0 && k == 0 ? 0.f : 255.f;  // red range [0, 255]
    if (c == 3) return blobs(i, j, k);
    return 0.f;                                                    // green, blue constant 0
  });
  const Image img = test::renderWith(v, dependentTF(), test::builder(BuilderKind::Grid), 30, 20);
  ASSERT_GT(test::coverage(img), 0.01);
  for (const vec4f& p : img.rgba) {
    EXPECT_EQ(p.y, 0.f);
    EXPECT_EQ(p.z, 0.f);
    EXPECT_NEAR(p.x, p.w, 1e-5f) << "red is 1 (premultiplied: equals alpha)";
  }
}

TEST(Components, BuildersEqualNaiveTwoComponents) {
  expectBuildersEqualNaive(twoComponents<uint8_t>(VoxelType::UInt8), BackendKind::CPU);
  expectBuildersEqualNaive(twoComponents<float>(VoxelType::Float32), BackendKind::CPU);
}

TEST(Components, BuildersEqualNaiveFourComponents) {
  expectBuildersEqualNaive(fourComponents<uint8_t>(VoxelType::UInt8), BackendKind::CPU);
  expectBuildersEqualNaive(fourComponents<uint16_t>(VoxelType::UInt16), BackendKind::CPU);
}

// RenderParams::rgbaLightingComponent (VTK >= 9.4 lights RGBA by component 3's gradient, 9.2 by
// component 0's): the two light the blobs differently, and skipping stays lossless with either.
TEST(Components, RgbaLightingComponentPicksTheGradient) {
  const Volume v = fourComponents<uint8_t>(VoxelType::UInt8);
  RenderParams c0 = shaded(), c3 = shaded();
  c3.rgbaLightingComponent = 3;
  const Image naive0 = test::renderWith(v, dependentTF(), test::builder(BuilderKind::Naive), 30, 20, false, 80,
                                        BackendKind::CPU, c0);
  const Image naive3 = test::renderWith(v, dependentTF(), test::builder(BuilderKind::Naive), 30, 20, false, 80,
                                        BackendKind::CPU, c3);
  ASSERT_GT(test::coverage(naive3), 0.01);
  EXPECT_GT(maxDiff(naive0, naive3), 20.f / 255.f) << "component 3's gradient lights the blobs otherwise";
  for (const BuildParams& p : test::skippingBuilders()) {
    const Image img = test::renderWith(v, dependentTF(), p, 30, 20, false, 80, BackendKind::CPU, c3);
    EXPECT_LE(maxDiff(img, naive3), kTol) << builderName(p.builder);
  }
}

// Blend modes other than composite have no dependent-component rule in VTK: one warning, then
// the composite image.
TEST(Components, OtherBlendModesWarnAndComposite) {
  const Volume v = twoComponents<uint8_t>(VoxelType::UInt8);
  std::vector<std::string> log;
  Engine e(BackendKind::CPU);
  e.setVolume(v);
  e.setTransferFunction(dependentTF());
  e.setBuildParams(test::builder(BuilderKind::KdTreeCPU));
  e.setLogger([&](const std::string& m) { log.push_back(m); });
  RenderParams rp;
  rp.blend = BlendMode::MaximumIntensity;
  e.setRenderParams(rp);
  Image mip, mip2, comp;
  e.render(test::orbit(v, 30, 20), 64, 64, mip);
  e.render(test::orbit(v, 30, 20), 64, 64, mip2);
  e.setRenderParams(RenderParams{});
  e.render(test::orbit(v, 30, 20), 64, 64, comp);
  ASSERT_EQ(log.size(), 1u);
  EXPECT_NE(log[0].find("dependent components"), std::string::npos) << log[0];
  EXPECT_EQ(maxDiff(mip, comp), 0.f);
}

// CUDA twin: the same per-ray code on the device: every builder equals Naive, and CUDA the CPU.
TEST(ComponentsCuda, BuildersEqualNaiveAndCpu) {
  SKIP_WITHOUT_CUDA();
  for (const Volume& v : {twoComponents<uint8_t>(VoxelType::UInt8), fourComponents<float>(VoxelType::Float32)}) {
    expectBuildersEqualNaive(v, BackendKind::CUDA);
    RenderParams shaded3 = shaded();
    shaded3.rgbaLightingComponent = 3;
    for (const RenderParams& rp : {RenderParams{}, shaded(), shaded3}) {
      const Image cpu = test::renderWith(v, dependentTF(), test::builder(BuilderKind::Grid), 30, 20, true, 80,
                                         BackendKind::CPU, rp);
      for (BuilderKind k : {BuilderKind::LBVH, BuilderKind::KdTreeGPUFast, BuilderKind::KdTreeGPU}) {
        const Image gpu = test::renderWith(v, dependentTF(), test::builder(k), 30, 20, true, 80, BackendKind::CUDA, rp);
        EXPECT_LE(maxDiff(gpu, cpu), 2.f / 255.f) << builderName(k) << " components " << v.components;
      }
    }
  }
}

// Numerical extremes (DESIGN.md "Extremes"): degenerate dims, constant data, NaN/Inf, tiny and
// huge spacing, axis-parallel rays, camera inside the volume. No crash, no NaN, the right image.
#include "TestUtil.h"
#include "spaceskip/Backend.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace spaceskip;

namespace {
Volume filled(vec3l d, VoxelType t, double value) {
  Volume v;
  v.allocate(d, t);
  for (int64_t i = 0; i < v.voxelCount(); ++i) {
    switch (t) {
      case VoxelType::UInt8: v.mutableData()[i] = uint8_t(value); break;
      case VoxelType::Float32: reinterpret_cast<float*>(v.mutableData())[i] = float(value); break;
      case VoxelType::Float64: reinterpret_cast<double*>(v.mutableData())[i] = value; break;
      default: reinterpret_cast<int16_t*>(v.mutableData())[i] = int16_t(value); break;
    }
  }
  return v;
}

void checkAllBuilders(const Volume& v, const TransferFunction& tf, double az, double el, bool expectVisible) {
  Image naive = test::renderWith(v, tf, test::builder(BuilderKind::Naive), az, el, false, 48);
  EXPECT_FALSE(hasNonFinite(naive));
  if (expectVisible) EXPECT_GT(test::coverage(naive), 0.01);
  Image grid = test::renderWith(v, tf, test::builder(BuilderKind::Grid), az, el, false, 48);
  EXPECT_FALSE(hasNonFinite(grid));
  EXPECT_LE(compareImages(naive, grid).maxAbs, 1.f / 255.f);
}
}  // namespace

TEST(Extremes, OneVoxelVolume) {
  Volume v = filled(vec3l{1, 1, 1}, VoxelType::UInt8, 200);
  checkAllBuilders(v, TransferFunction::preset("opaque", 0, 255), 30, 20, true);
}

TEST(Extremes, OneByNByMSlab) {
  Volume v = generateVolume("noise", vec3l{1, 40, 33});
  double lo, hi;
  ASSERT_TRUE(v.scalarRange(lo, hi));
  checkAllBuilders(v, TransferFunction::preset("ramp", lo, hi), 90, 0, true);
  checkAllBuilders(v, TransferFunction::preset("ramp", lo, hi), 0, 0, false);  // edge-on view
}

TEST(Extremes, ConstantVolume) {
  Volume v = filled(vec3l{17, 9, 5}, VoxelType::Int16, 42);
  double lo, hi;
  ASSERT_TRUE(v.scalarRange(lo, hi));
  EXPECT_EQ(lo, hi);
  checkAllBuilders(v, TransferFunction::preset("opaque", lo, hi), 10, 10, true);
}

TEST(Extremes, NaNAndInfInFloatData) {
  Volume v = generateVolume("noise", vec3l{24, 24, 24});
  float* d = reinterpret_cast<float*>(v.mutableData());
  for (int64_t i = 0; i < v.voxelCount(); i += 7) d[i] = NAN;
  for (int64_t i = 3; i < v.voxelCount(); i += 11) d[i] = INFINITY;
  for (int64_t i = 5; i < v.voxelCount(); i += 13) d[i] = -INFINITY;
  double lo, hi;
  ASSERT_TRUE(v.scalarRange(lo, hi));
  EXPECT_TRUE(std::isfinite(lo) && std::isfinite(hi));
  checkAllBuilders(v, TransferFunction::preset("ramp", lo, hi), 25, 35, true);
}

TEST(Extremes, AllNaNVolumeRendersNothing) {
  Volume v = filled(vec3l{8, 8, 8}, VoxelType::Float64, NAN);
  double lo, hi;
  EXPECT_FALSE(v.scalarRange(lo, hi));
  Image img = test::renderWith(v, TransferFunction::preset("opaque", 0, 1), test::builder(BuilderKind::Grid), 0, 0);
  EXPECT_FALSE(hasNonFinite(img));
  EXPECT_EQ(test::coverage(img), 0.0);
}

TEST(Extremes, TinyAndHugeSpacingGiveTheSameImage) {
  Volume v = generateVolume("shell", vec3l{32, 32, 32});
  auto tf = TransferFunction::preset("ramp", 0, 255);
  Image ref = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 20, 20, false, 48);
  for (double s : {1e-6, 1e6}) {
    Volume w = v;
    w.spacing[0] = w.spacing[1] = w.spacing[2] = s;
    w.origin[0] = 3 * s;
    auto tfs = tf;
    tfs.unitDistance = s;  // same optical depth per voxel
    Image img = test::renderWith(w, tfs, test::builder(BuilderKind::Grid), 20, 20, false, 48);
    EXPECT_FALSE(hasNonFinite(img));
    ImageDiff d = compareImages(ref, img);
    EXPECT_GT(d.psnr, 40.0) << "spacing " << s;
    Image naive = test::renderWith(w, tfs, test::builder(BuilderKind::Naive), 20, 20, false, 48);
    EXPECT_LE(compareImages(naive, img).maxAbs, 1.f / 255.f);
  }
}

TEST(Extremes, AnisotropicSpacing) {
  Volume v = generateVolume("menger", vec3l{27, 27, 27});
  v.spacing[2] = 4.0;
  v.spacing[0] = 0.25;
  checkAllBuilders(v, TransferFunction::preset("ramp", 0, 255), 40, 30, true);
}

TEST(Extremes, AxisParallelRays) {
  Volume v = generateVolume("menger", vec3l{27, 27, 27});
  auto tf = TransferFunction::preset("ramp", 0, 255);
  for (auto cam : {std::pair{0.0, 0.0}, {90.0, 0.0}, {180.0, 0.0}, {270.0, 0.0}, {0.0, 90.0}, {0.0, -90.0}})
    checkAllBuilders(v, tf, cam.first, cam.second, true);
}

TEST(Extremes, CameraInsideTheVolume) {
  Volume v = generateVolume("nbody", vec3l{48, 48, 48});
  auto tf = TransferFunction::preset("ramp", 0, 255);
  double eye[3] = {24, 20, 22}, center[3] = {40, 30, 10}, up[3] = {0, 1, 0};
  Image imgs[2];
  int i = 0;
  for (BuilderKind k : {BuilderKind::Naive, BuilderKind::Grid}) {
    Engine e(BackendKind::CPU);
    e.setVolume(v);
    e.setTransferFunction(tf);
    e.setBuildParams(test::builder(k));
    e.render(lookAtCamera(eye, center, up, true, 70, 1, 0.01, 200), 64, 64, imgs[i++]);
  }
  EXPECT_FALSE(hasNonFinite(imgs[0]));
  EXPECT_GT(test::coverage(imgs[0]), 0.0);
  EXPECT_LE(compareImages(imgs[0], imgs[1]).maxAbs, 1.f / 255.f);
}

TEST(Extremes, BadInputIsRejectedClearly) {
  Volume v;
  EXPECT_THROW(Engine(BackendKind::CPU).setVolume(v), std::runtime_error);  // empty extent
  Volume w = filled(vec3l{2, 2, 2}, VoxelType::UInt8, 1);
  w.spacing[1] = 0;
  EXPECT_THROW(Engine(BackendKind::CPU).setVolume(w), std::runtime_error);
  Engine e(BackendKind::CPU);
  Image img;
  double b[6] = {0, 1, 0, 1, 0, 1};
  EXPECT_THROW(e.render(orbitCamera(b, 0, 0, 1, false, 1), 8, 8, img), std::runtime_error);  // no volume
}

TEST(Extremes, CudaRequestWithoutDeviceFallsBackToCpu) {
  if (cudaAvailable()) GTEST_SKIP() << "a CUDA device is present";
  std::vector<std::string> log;
  Engine e(BackendKind::CUDA, [&](const std::string& m) { log.push_back(m); });
  EXPECT_EQ(e.backendKind(), BackendKind::CPU);
  ASSERT_EQ(log.size(), 1u);  // one clear message, through the caller's logger
  EXPECT_NE(log[0].find("CPU backend"), std::string::npos) << log[0];
  // And it renders.
  Volume v = generateVolume("shell", vec3l{16, 16, 16});
  e.setVolume(v);
  e.setTransferFunction(TransferFunction::preset("ramp", 0, 255));
  double b[6];
  v.worldBounds(b);
  Image img;
  e.render(orbitCamera(b, 0, 0, 1, false, 1), 16, 16, img);
  EXPECT_GT(test::coverage(img), 0.0);
}

// The parallel range pass (many chunks) equals the serial definition: finite values only, the
// extremes found wherever they lie, and no finite value at all reports an empty range.
TEST(Extremes, ScalarRangeParallelSkipsNonFinite) {
  const vec3l d{160, 160, 130};  // 3.3 M voxels: several chunks of the range pass
  Volume f = filled(d, VoxelType::Float32, 5.0);
  float* p = reinterpret_cast<float*>(f.mutableData());
  const int64_t n = f.voxelCount();
  p[0] = std::numeric_limits<float>::quiet_NaN();
  p[n / 3] = std::numeric_limits<float>::infinity();
  p[n / 2] = -std::numeric_limits<float>::infinity();
  p[n - 7] = -2.5f;
  p[(n * 3) / 4] = 11.0f;
  double lo = 0, hi = 0;
  ASSERT_TRUE(f.scalarRange(lo, hi));
  EXPECT_EQ(lo, -2.5);
  EXPECT_EQ(hi, 11.0);

  Volume s = filled(d, VoxelType::Int16, -3);
  reinterpret_cast<int16_t*>(s.mutableData())[n - 1] = 1234;
  reinterpret_cast<int16_t*>(s.mutableData())[1] = -32768;
  ASSERT_TRUE(s.scalarRange(lo, hi));
  EXPECT_EQ(lo, -32768.0);
  EXPECT_EQ(hi, 1234.0);

  Volume nan = filled(vec3l{4, 4, 4}, VoxelType::Float64, std::nan(""));
  EXPECT_FALSE(nan.scalarRange(lo, hi));
}

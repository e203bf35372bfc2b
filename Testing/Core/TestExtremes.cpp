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

// --- Hostile input and extremes (issue 14): bounded work per ray, precision, value extremes.

TEST(Extremes, TinySampleDistanceIsClampedOnceAndBounded) {
  Volume v = generateVolume("shell", vec3l{32, 32, 32});
  auto tf = TransferFunction::preset("ramp", 0, 255);
  const Camera cam = test::orbit(v, 20, 30);
  const double floorDt = 1.0 / kMinStepsPerVoxel;  // spacing 1
  Image ref;
  {
    Engine e(BackendKind::CPU);
    e.setLogger([](const std::string&) {});
    e.setVolume(v);
    e.setTransferFunction(tf);
    RenderParams rp;
    rp.sampleDistance = floorDt;
    e.setRenderParams(rp);
    e.render(cam, 32, 32, ref);
  }
  // 1e-4 ran for minutes; 1e-12 overflowed the int sample index and drew nothing.
  for (double dt : {1e-4, 1e-12, 1e-300}) {
    std::vector<std::string> log;
    Engine e(BackendKind::CPU, [&](const std::string& m) { log.push_back(m); });
    e.setVolume(v);
    e.setTransferFunction(tf);
    RenderParams rp;
    rp.sampleDistance = dt;
    rp.countSamples = true;
    e.setRenderParams(rp);
    Image img;
    for (int frame = 0; frame < 3; ++frame) e.render(cam, 32, 32, img);
    EXPECT_DOUBLE_EQ(e.sampleDistance(), floorDt);
    ASSERT_EQ(log.size(), 1u) << "one warning for three frames";
    EXPECT_NE(log[0].find("clamped"), std::string::npos) << log[0];
    // Work bound: at most the box diagonal / floor (+1 per ray) samples per pixel.
    const double diagonal = std::sqrt(3.0) * 32;
    EXPECT_LE(e.frameStats().samples, int64_t(32 * 32 * (diagonal / floorDt + 1)));
    EXPECT_GT(test::coverage(img), 0.01);
    EXPECT_EQ(compareImages(ref, img).maxAbs, 0.f);
  }
}

TEST(Extremes, SamplesPerRayAreCappedOnVeryLongAxes) {
  Volume v = filled(vec3l{int64_t(1) << 22, 1, 1}, VoxelType::UInt8, 0);  // 4 MiB, 2^22 cells long
  std::string note;
  const double dt = effectiveSampleDistance(v, 0, &note);
  EXPECT_NEAR(double(int64_t(1) << 22) / dt, kMaxSamplesPerRay, 1.0);
  EXPECT_NE(note.find("samples"), std::string::npos) << note;
  EXPECT_EQ(effectiveSampleDistance(filled(vec3l{8, 8, 8}, VoxelType::UInt8, 0), 0.25, &note), 0.25);
  EXPECT_TRUE(note.empty()) << note;
}

// --- Spacing, origin and sample distance outside float's comfortable range (issue 41).

namespace {
struct Drawn {
  Image img;
  int64_t samples = 0;
  double dt = 0;
  std::vector<std::string> log;
};
Drawn drawCounted(const Volume& v, const TransferFunction& tf, BuilderKind k, const Camera& cam, int size,
                  double sampleDistance = 0) {
  Drawn d;
  Engine e(BackendKind::CPU, [&](const std::string& m) { d.log.push_back(m); });
  e.setVolume(v);
  e.setTransferFunction(tf);
  e.setBuildParams(test::builder(k));
  RenderParams rp;
  rp.countSamples = true;
  rp.sampleDistance = sampleDistance;
  e.setRenderParams(rp);
  e.render(cam, size, size, d.img);
  d.samples = e.frameStats().samples;
  d.dt = e.sampleDistance();
  return d;
}
bool logHas(const std::vector<std::string>& log, const std::string& what) {
  for (const std::string& m : log)
    if (m.find(what) != std::string::npos) return true;
  return false;
}
}  // namespace

TEST(Extremes, SpacingBelowFloatOnOneAxisDrawsBoundedWithAWarning) {
  // Spacing 1e-40 on x overflowed the float world-to-index matrix (1e40): NaN rays crashed in
  // ArraySampler::sample; 1e-39 on y clamped dt to diagonal / 2^20, ~2^20 samples a ray (a 64^2
  // CLI image > 30 s). Now: the thin axis is drawn 2^-40 of the extent thin, with a warning, and
  // a ray takes at most kMaxSamplesPerCell samples per cell it can cross.
  const Volume v = generateVolume("shell", vec3l{16, 16, 16});
  const auto tf = TransferFunction::preset("ramp", 0, 255);
  const double cellsCrossed = 15 * 3;
  for (int axis = 0; axis < 3; ++axis)
    for (double tiny : {1e-40, 1e-39, 1e-300}) {
      Volume w = v;
      w.spacing[axis] = tiny;
      for (BuilderKind k : {BuilderKind::Naive, BuilderKind::Grid, BuilderKind::KdTreeCPU, BuilderKind::Auto})
        for (auto view : {std::pair{30.0, 20.0}, {0.0, 0.0}, {90.0, 0.0}, {0.0, 90.0}}) {
          SCOPED_TRACE(::testing::Message() << "axis " << axis << " spacing " << tiny << " builder " << int(k)
                                          << " view " << view.first << "," << view.second);
          const Drawn d = drawCounted(w, tf, k, test::orbit(w, view.first, view.second), 32);
          EXPECT_FALSE(hasNonFinite(d.img));
          EXPECT_GE(d.samples, 0);
          EXPECT_LE(d.samples, int64_t(32 * 32 * (kMaxSamplesPerCell * cellsCrossed + 2)));
          EXPECT_TRUE(logHas(d.log, "drawn that thin")) << (d.log.empty() ? "" : d.log[0]);
          EXPECT_TRUE(logHas(d.log, "clamped")) << "the automatic sample distance is bounded, and says so";
        }
    }
}

TEST(Extremes, UniformSpacingsFarFromOneDrawLikeSpacingOne) {
  // Spacing <= 1e-30 or >= 1e20 (astrophysics in cgs units) drew blank; with the camera and the
  // opacity unit distance scaled alike the image is spacing 1's.
  const Volume v = generateVolume("shell", vec3l{24, 24, 24});
  const auto tf = TransferFunction::preset("ramp", 0, 255);
  for (bool persp : {false, true}) {
    const Image ref = test::renderWith(v, tf, test::builder(BuilderKind::Naive), 30, 25, persp, 48);
    ASSERT_GT(test::coverage(ref), 0.05);
    for (double s : {1e-30, 1e-38, 1e-100, 1e20, 1e21, 1e22, 1e100}) {  // (1e300: the orbit camera overflows)
      Volume w = v;
      for (int i = 0; i < 3; ++i) {
        w.spacing[i] = s;
        w.origin[i] = -5 * s;
      }
      auto tfs = tf;
      tfs.unitDistance = s;  // the same optical depth per voxel
      for (BuilderKind k : {BuilderKind::Naive, BuilderKind::Grid, BuilderKind::KdTreeCPU}) {
        const Image img = test::renderWith(w, tfs, test::builder(k), 30, 25, persp, 48);
        EXPECT_FALSE(hasNonFinite(img));
        EXPECT_LE(compareImages(ref, img).maxAbs, 1.f / 255.f)
            << "spacing " << s << " persp " << persp << " builder " << int(k);
      }
    }
  }
}

TEST(Extremes, OriginFarBeyondFloatDrawsLikeTheOrigin) {
  // Origin 1e15, spacing 1 (a double ulp is 0.125 there): 229/255 off in the CLI when the camera
  // was inverted with its 1e15 translation and shifted afterwards. Cameras whose matrices are
  // exact at 1e15 (axis-aligned orbits, integer eyes) must draw the origin-0 image.
  const Volume v = generateVolume("nbody", vec3l{40, 40, 40});
  const auto tf = TransferFunction::preset("ramp", 0, 255);
  for (bool persp : {false, true})
    for (auto view : {std::pair{0.0, 0.0}, {90.0, 0.0}, {180.0, 0.0}, {0.0, 90.0}}) {
      const Image ref = test::renderWith(v, tf, test::builder(BuilderKind::Grid), view.first, view.second, persp, 64);
      ASSERT_GT(test::coverage(ref), 0.01);
      for (double o : {1e15, -1e15, 3e15}) {
        Volume w = v;
        for (int i = 0; i < 3; ++i) w.origin[i] = o;
        for (BuilderKind k : {BuilderKind::Naive, BuilderKind::Grid, BuilderKind::KdTreeCPU}) {
          const Image img = test::renderWith(w, tf, test::builder(k), view.first, view.second, persp, 64);
          EXPECT_LE(compareImages(ref, img).maxAbs, 1.f / 255.f)
              << "origin " << o << " persp " << persp << " view " << view.first << "," << view.second;
        }
      }
    }
}

TEST(Extremes, SampleDistanceLargerThanTheVolumeIsClampedWithAWarning) {
  // 1e6 and 1e300 drew blank without a word; they are clamped to half the diagonal, as tiny
  // ones are clamped to the floor, and the image shows the volume.
  const Volume v = generateVolume("shell", vec3l{16, 16, 16});
  const auto tf = TransferFunction::preset("opaque", 0, 255);
  const double diagonal = std::sqrt(3.0) * 15;
  const Camera cam = test::orbit(v, 20, 30);
  for (double dt : {1e6, 1e300, 100.0}) {
    const Drawn d = drawCounted(v, tf, BuilderKind::Naive, cam, 32, dt);
    EXPECT_DOUBLE_EQ(d.dt, 0.5 * diagonal) << dt;
    EXPECT_TRUE(logHas(d.log, "clamped")) << dt;
    EXPECT_TRUE(logHas(d.log, "half the volume's diagonal")) << (d.log.empty() ? "" : d.log[0]);
    EXPECT_GT(test::coverage(d.img), 0.05) << dt;
  }
  // Up to half the diagonal it is taken as asked, silently.
  const Drawn ok = drawCounted(v, tf, BuilderKind::Naive, cam, 32, 10.0);
  EXPECT_DOUBLE_EQ(ok.dt, 10.0);
  EXPECT_TRUE(ok.log.empty()) << ok.log[0];
}

TEST(Extremes, SamplesPerRayFollowTheCellsCrossed) {
  // The bound is per cell a ray can cross: the automatic step of a 1e-39-thin axis gives at most
  // kMaxSamplesPerCell * (cells along x + y + z) samples; usual anisotropy (1:10) stays unclamped.
  Volume thin = filled(vec3l{16, 16, 16}, VoxelType::UInt8, 0);
  thin.spacing[1] = 1e-39;
  std::string note;
  const double dt = effectiveSampleDistance(thin, 0, &note);
  const double diagonal = std::hypot(15.0, 15.0 * 1e-39, 15.0);
  EXPECT_NEAR(diagonal / dt, kMaxSamplesPerCell * 45, 1e-6);
  EXPECT_NE(note.find("per cell"), std::string::npos) << note;
  Volume ct = filled(vec3l{64, 64, 64}, VoxelType::UInt8, 0);
  ct.spacing[2] = 10;
  EXPECT_EQ(effectiveSampleDistance(ct, 0, &note), 0.5);
  EXPECT_TRUE(note.empty()) << note;
}

TEST(Extremes, FarFromTheOriginEqualsAtTheOrigin) {
  // Georeferenced data: origins of 1e6..1e7 (a float ulp is 0.06..1 world unit there).
  Volume v = generateVolume("nbody", vec3l{40, 40, 40});
  auto tf = TransferFunction::preset("ramp", 0, 255);
  for (bool persp : {false, true}) {
    Image ref = test::renderWith(v, tf, test::builder(BuilderKind::Grid), 30, 25, persp, 64);
    ASSERT_GT(test::coverage(ref), 0.01);
    for (double o : {1e6, 1e7, -3.3e7}) {
      Volume w = v;
      w.origin[0] = o;
      w.origin[1] = -0.7 * o;
      w.origin[2] = 0.3 * o;
      for (BuilderKind k : {BuilderKind::Naive, BuilderKind::Grid, BuilderKind::KdTreeCPU}) {
        Image img = test::renderWith(w, tf, test::builder(k), 30, 25, persp, 64);
        EXPECT_LE(compareImages(ref, img).maxAbs, 1.f / 255.f) << "origin " << o << " persp " << persp;
      }
    }
  }
}

namespace {
// `v`'s values mapped by `f` into a float64 volume with the same layout.
template <class F>
Volume mapToDouble(const Volume& v, F f) {
  Volume w;
  w.allocate(v.dims, VoxelType::Float64);
  double* d = reinterpret_cast<double*>(w.mutableData());
  for (int64_t i = 0; i < v.voxelCount(); ++i)
    d[i] = f(double(reinterpret_cast<const uint8_t*>(v.data)[i]));
  return w;
}
}  // namespace

TEST(Extremes, ValuesNearTheEndsOfDoubleRenderLikeModestOnes) {
  // +-1e308 gave a blank image (float overflow in sampling); denormals collapsed to one entry.
  Volume v = generateVolume("nbody", vec3l{32, 32, 32});  // uint8
  auto modest = mapToDouble(v, [](double x) { return (x - 127.5) / 127.5; });
  auto tf = TransferFunction::preset("ramp", -1, 1);
  Image ref = test::renderWith(modest, tf, test::builder(BuilderKind::Grid), 15, 40, false, 48);
  ASSERT_GT(test::coverage(ref), 0.01);
  for (double scale : {1e308, 1e-310, 3e38, 1e-40}) {
    auto w = mapToDouble(v, [&](double x) { return (x - 127.5) / 127.5 * scale; });
    auto tfw = TransferFunction::preset("ramp", -scale, scale);
    for (BuilderKind k : {BuilderKind::Naive, BuilderKind::Grid}) {
      Engine e(BackendKind::CPU);
      e.setVolume(w);
      EXPECT_NE(e.valueExponent(), 0) << scale;
      Image img = test::renderWith(w, tfw, test::builder(k), 15, 40, false, 48);
      EXPECT_FALSE(hasNonFinite(img));
      EXPECT_LE(compareImages(ref, img).maxAbs, 2.f / 255.f) << "scale " << scale;
    }
  }
}

TEST(Extremes, InfinityTakesTheEndOfTheTableAndNeverMakesNaN) {
  // A float32 volume of +Inf in one half and finite values in the other: no NaN pixel, the Inf
  // half drawn with the table's last entry (as a value above the range would be), lossless.
  Volume v = filled(vec3l{16, 16, 16}, VoxelType::Float32, 0.25);
  float* d = reinterpret_cast<float*>(v.mutableData());
  for (int64_t i = 0; i < v.voxelCount(); ++i)
    if (i % 16 >= 8) d[i] = INFINITY;
  auto tf = TransferFunction::fromPoints({{0, 0, 0, 1, 0.f}, {0.5, 0, 0, 1, 0.f}, {1, 1, 0, 0, 1.f}}, 0, 1, 256);
  Image naive = test::renderWith(v, tf, test::builder(BuilderKind::Naive), 0, 0, false, 32);
  EXPECT_FALSE(hasNonFinite(naive));
  EXPECT_GT(test::coverage(naive), 0.1);  // the Inf half is opaque red
  checkAllBuilders(v, tf, 0, 0, true);
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

// Found by fuzz_render (issue 41): a double volume whose values lie near DBL_MIN (2.644e-308, the
// engine's value exponent 1021) drew NaN pixels in MIP and MinIP (an infinite normalising
// scale); the seed is Testing/Fuzz/corpus/render/nan_image_double_value_2.6e-308_minip.
TEST(Extremes, ValuesNearDoubleMinimumDrawFiniteInEveryBlendMode) {
  for (double value : {2.644e-308, 2.3e-308, 1e-300}) {
    Volume v = filled(vec3l{2, 2, 2}, VoxelType::Float64, value);
    reinterpret_cast<double*>(v.mutableData())[0] = 0.5 * value;
    auto tf = TransferFunction::preset("ramp", 0.5 * value, value);
    for (BlendMode m : {BlendMode::Composite, BlendMode::MaximumIntensity, BlendMode::MinimumIntensity,
                        BlendMode::Additive, BlendMode::AverageIntensity}) {
      RenderParams rp;
      rp.blend = m;
      for (BuilderKind k : {BuilderKind::Naive, BuilderKind::Grid}) {
        Image img = test::renderWith(v, tf, test::builder(k), 30, 20, false, 16, BackendKind::CPU, rp);
        EXPECT_FALSE(hasNonFinite(img)) << "value " << value << " blend " << int(m) << " builder " << int(k);
        EXPECT_GT(test::coverage(img), 0.01) << "value " << value << " blend " << int(m);
      }
    }
  }
}

// Found by fuzz_render in CI: a double volume of denormal values (0 and 4.94e-323, ten times the
// smallest denormal) with jittered rays drew NaN colour in MinIP, average and additive blending.
// The seed is Testing/Fuzz/corpus/render/nan_image_denormal_values_jitter_average.
TEST(Extremes, DenormalValuesDrawFiniteWithJitter) {
  for (double value : {4.94e-323, 4.94e-324 * 3, 1e-310}) {
    Volume v = filled(vec3l{1, 1, 4}, VoxelType::Float64, 0.0);
    reinterpret_cast<double*>(v.mutableData())[0] = value;
    for (const char* preset : {"band", "ramp"}) {
      auto tf = TransferFunction::preset(preset, 0.0, value);
      for (BlendMode m : {BlendMode::Composite, BlendMode::MaximumIntensity, BlendMode::MinimumIntensity,
                          BlendMode::Additive, BlendMode::AverageIntensity}) {
        RenderParams rp;
        rp.blend = m;
        rp.jitter = true;
        for (BuilderKind k : {BuilderKind::Naive, BuilderKind::Grid}) {
          Image img = test::renderWith(v, tf, test::builder(k), 30, 20, false, 16, BackendKind::CPU, rp);
          EXPECT_FALSE(hasNonFinite(img)) << "value " << value << " " << preset << " blend " << int(m)
                                          << " builder " << int(k);
        }
      }
    }
  }
}

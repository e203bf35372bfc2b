// Time series (issue 38): a new volume of the same shape is a time step. The played frames equal
// each step's static render, Builder Auto keeps its choice across steps (no measuring again while
// the occupancy holds), and a volume of another shape starts afresh. On the CPU and, where a
// device answers, on CUDA (the upload through pinned staging, the device allocation kept).
#include "TestUtil.h"

#include "spaceskip/Builders.h"

#include <cstring>

using namespace spaceskip;

namespace {

std::vector<Volume> nbodySteps(int n, int count, VoxelType type) {
  std::vector<Volume> s;
  for (int k = 0; k < count; ++k) s.push_back(generateTimeStep("nbody", vec3l{n, n, n}, k, type));
  return s;
}

/// Plays `steps` (each twice, the second time at another view) in one engine of `backend` and
/// compares every frame with a static render of that step by a fresh Naive engine on the CPU.
/// With `prefetch`, each next step is prefetched (Engine::prefetchVolume) while a step is drawn;
/// on CUDA then every played step after the first was found on the device.
void expectPlaybackEqualsStatic(BackendKind backend, const std::vector<Volume>& steps, const BuildParams& bp,
                                float tolerance, bool prefetch = false) {
  double lo = 0, hi = 1;
  ASSERT_TRUE(steps[0].scalarRange(lo, hi));
  const TransferFunction tf = TransferFunction::preset("ramp", lo, hi);
  Engine e(backend);
  test::load(e, steps[0], tf, bp);
  Image img, ref;
  for (int k = 0; k < 2 * int(steps.size()); ++k) {
    const Volume& v = steps[size_t(k) % steps.size()];
    const Camera cam = test::orbit(v, 25.0 * k, 20);
    e.setVolume(v);
    e.update();
    if (prefetch) EXPECT_EQ(e.prefetchVolume(steps[size_t(k + 1) % steps.size()]), backend == BackendKind::CUDA);
    e.render(cam, 80, 80, img);
    Engine naive(BackendKind::CPU);
    test::load(naive, v, tf, test::builder(BuilderKind::Naive));
    naive.render(cam, 80, 80, ref);
    EXPECT_LE(compareImages(ref, img).maxAbs, tolerance) << "step " << k % steps.size() << " played as frame " << k
                                                           << " with " << builderName(bp.builder);
    EXPECT_GT(test::coverage(img), 0.0) << "step " << k;
  }
  EXPECT_EQ(e.counters().timeSteps, 2 * int(steps.size()));  // every setVolume after load()'s
  // Prefetched: every step after the first played one (the CPU reads the steps in place).
  if (prefetch) EXPECT_EQ(e.counters().prefetchedSteps, backend == BackendKind::CUDA ? 2 * int(steps.size()) - 1 : 0);
}

}  // namespace

TEST(TimeSeries, MixingLayerStepsGrowDenser) {
  // The rm time series: every step differs from the one before, and the drawn share grows.
  const vec3l d{48, 48, 48};
  auto nonZero = [](const Volume& v) {
    const auto* p = static_cast<const unsigned char*>(v.data);
    int64_t n = 0;
    for (int64_t i = 0; i < v.voxelCount(); ++i) n += p[i] != 0;
    return n;
  };
  const Volume s0 = generateTimeStep("rm", d, 0), s1 = generateTimeStep("rm", d, 1), s99 = generateTimeStep("rm", d, 24);
  int64_t differ = 0;
  for (int64_t i = 0; i < s0.voxelCount(); ++i)
    differ += static_cast<const unsigned char*>(s0.data)[i] != static_cast<const unsigned char*>(s1.data)[i];
  EXPECT_GT(differ, 0);
  EXPECT_GT(nonZero(s99), 3 * nonZero(s0));
  EXPECT_GT(nonZero(s0), 0);
  const Volume f = generateTimeStep("rm", d, 5, VoxelType::Float32);
  EXPECT_EQ(f.type, VoxelType::Float32);
  // Played steps equal their static renders, as for the N-body.
  std::vector<Volume> steps;
  for (int k : {0, 12, 24}) steps.push_back(generateTimeStep("rm", d, k));
  expectPlaybackEqualsStatic(BackendKind::CPU, steps, test::builder(BuilderKind::Grid), 1.f / 255.f);
}

TEST(TimeSeries, StepsDifferAndStaySparse) {
  const std::vector<Volume> s = nbodySteps(64, 3, VoxelType::UInt8);
  for (int k = 1; k < 3; ++k) {
    const auto* a = static_cast<const unsigned char*>(s[0].data);
    const auto* b = static_cast<const unsigned char*>(s[size_t(k)].data);
    int64_t differ = 0, occupied = 0;
    for (int64_t i = 0; i < s[0].voxelCount(); ++i) {
      differ += a[i] != b[i];
      occupied += b[i] != 0;
    }
    EXPECT_GT(differ, 100) << "step " << k;
    EXPECT_LT(occupied, s[0].voxelCount() / 10) << "step " << k;  // 6.3 % at 64^3
  }
  const Volume f = generateTimeStep("nbody", vec3l{32, 32, 32}, 2, VoxelType::Float32);
  EXPECT_EQ(f.type, VoxelType::Float32);
  EXPECT_THROW(generateTimeStep("menger", vec3l{32, 32, 32}, 1), std::invalid_argument);
}

TEST(TimeSeries, PlayedFramesEqualStaticRendersOnEveryBuilder) {
  const std::vector<Volume> steps = nbodySteps(48, 3, VoxelType::UInt8);
  for (BuilderKind k : {BuilderKind::Auto, BuilderKind::Grid, BuilderKind::LBVH, BuilderKind::KdTreeCPU,
                        BuilderKind::Hybrid, BuilderKind::DistanceGrid})
    expectPlaybackEqualsStatic(BackendKind::CPU, steps, test::builder(k), 1.f / 255.f);
  expectPlaybackEqualsStatic(BackendKind::CPU, nbodySteps(40, 2, VoxelType::Float32), test::builder(BuilderKind::Auto),
                             1.f / 255.f);
}

TEST(TimeSeries, AutoKeepsItsChoiceAcrossStepsAndStartsAfreshOnANewShape) {
  const std::vector<Volume> steps = nbodySteps(64, 4, VoxelType::UInt8);
  double lo = 0, hi = 1;
  ASSERT_TRUE(steps[0].scalarRange(lo, hi));
  const TransferFunction tf = TransferFunction::preset("ramp", lo, hi);
  Engine e(BackendKind::CPU);
  test::load(e, steps[0], tf, test::builder(BuilderKind::Auto));
  Image img;
  const Camera cam = test::orbit(steps[0], 30, 20);
  e.render(cam, 96, 96, img);
  for (int i = 0; i < 40 && e.exploring(); ++i) e.render(cam, 96, 96, img);
  ASSERT_FALSE(e.exploring());
  const int measurings = e.counters().autoProbeMeasurings;
  const std::string choice = e.buildStats().choice;
  for (int k = 1; k < 4; ++k) {
    const int builds = e.counters().builds, ranges = e.counters().rangeGrids;
    e.setVolume(steps[size_t(k)]);
    e.render(cam, 96, 96, img);
    EXPECT_FALSE(e.exploring()) << "step " << k;
    EXPECT_EQ(e.counters().rangeGrids, ranges + 1) << "step " << k;  // the new voxels' ranges, once
    EXPECT_GE(e.counters().builds, builds + 1) << "step " << k;      // the kept structure, rebuilt
  }
  EXPECT_EQ(e.counters().autoProbeMeasurings, measurings) << choice;
  EXPECT_EQ(e.counters().timeSteps, 3);
  // Another shape (dims) is another volume: Auto measures again.
  const Volume other = generateTimeStep("nbody", vec3l{48, 48, 48}, 0);
  e.setVolume(other);
  e.render(test::orbit(other, 30, 20), 96, 96, img);
  EXPECT_EQ(e.counters().timeSteps, 3);
  EXPECT_GT(e.counters().autoProbeMeasurings, measurings);
}

/// Float32 steps of extreme magnitude (the check left to the brick ranges, no host range pass):
/// scaled as before, drawn as the modest steps are.
void expectExtremeStepsDrawLikeModestOnes(BackendKind backend) {
  std::vector<Volume> modest = nbodySteps(40, 2, VoxelType::Float32);
  double lo = 0, hi = 1;
  ASSERT_TRUE(modest[0].scalarRange(lo, hi));
  for (double scale : {1e30, 1e-30}) {
    std::vector<Volume> steps;
    for (const Volume& m : modest) {
      Volume v;
      v.allocate(m.dims, VoxelType::Float32);
      const float* in = static_cast<const float*>(m.data);
      float* out = reinterpret_cast<float*>(v.mutableData());
      for (int64_t i = 0; i < m.voxelCount(); ++i) out[i] = float(in[i] * scale);
      steps.push_back(v);
    }
    Engine e(backend), ref(backend);
    test::load(e, steps[0], TransferFunction::preset("ramp", lo * scale, hi * scale), test::builder(BuilderKind::Grid));
    test::load(ref, modest[0], TransferFunction::preset("ramp", lo, hi), test::builder(BuilderKind::Grid));
    Image a, b;
    for (int k = 0; k < 4; ++k) {
      e.setVolume(steps[size_t(k) % 2]);
      ref.setVolume(modest[size_t(k) % 2]);
      const int passes = e.counters().voxelPasses, refPasses = ref.counters().voxelPasses;
      e.render(test::orbit(modest[0], 30.0 * k, 20), 64, 64, a);
      ref.render(test::orbit(modest[0], 30.0 * k, 20), 64, 64, b);
      EXPECT_NE(e.valueExponent(), 0) << scale;
      // No host range pass beyond what the modest steps take (the check read the brick ranges).
      EXPECT_EQ(e.counters().voxelPasses - passes, ref.counters().voxelPasses - refPasses) << "scale " << scale;
      EXPECT_LE(compareImages(b, a).maxAbs, 2.f / 255.f) << "scale " << scale << " step " << k;
      EXPECT_GT(test::coverage(a), 0.0);
    }
  }
}

TEST(TimeSeries, ExtremeFloatStepsAreScaledFromTheBrickRanges) { expectExtremeStepsDrawLikeModestOnes(BackendKind::CPU); }

TEST(TimeSeries, CudaExtremeFloatStepsAreScaledFromTheBrickRanges) {
  SKIP_WITHOUT_CUDA();
  expectExtremeStepsDrawLikeModestOnes(BackendKind::CUDA);
}

TEST(TimeSeries, CudaPlaybackEqualsStaticRenders) {
  SKIP_WITHOUT_CUDA();
  // Steps above HostStaging::kChunk (32 MiB) go through the pinned chunks: 384^3 uint8 is 54 MiB.
  const std::vector<Volume> big = nbodySteps(384, 2, VoxelType::UInt8);
  expectPlaybackEqualsStatic(BackendKind::CUDA, big, test::builder(BuilderKind::Auto), 1.f / 255.f);
  const std::vector<Volume> steps = nbodySteps(48, 3, VoxelType::UInt8);
  for (BuilderKind k : {BuilderKind::Grid, BuilderKind::LBVH, BuilderKind::KdTreeGPUFast, BuilderKind::DistanceGrid})
    expectPlaybackEqualsStatic(BackendKind::CUDA, steps, test::builder(k), 1.f / 255.f);
  expectPlaybackEqualsStatic(BackendKind::CUDA, nbodySteps(200, 2, VoxelType::Float32), test::builder(BuilderKind::Auto),
                             1.f / 255.f);
}

TEST(TimeSeries, PrefetchIsANoOpOnTheCpu) {
  expectPlaybackEqualsStatic(BackendKind::CPU, nbodySteps(40, 3, VoxelType::UInt8), test::builder(BuilderKind::Grid),
                             1.f / 255.f, true);
}
TEST(TimeSeries, CudaPrefetchedPlaybackEqualsStaticRenders) {
  SKIP_WITHOUT_CUDA();
  // Through the pinned chunks (54 MiB) and below them; uint8 and float32; a structure and Auto.
  expectPlaybackEqualsStatic(BackendKind::CUDA, nbodySteps(384, 2, VoxelType::UInt8), test::builder(BuilderKind::Auto),
                             1.f / 255.f, true);
  expectPlaybackEqualsStatic(BackendKind::CUDA, nbodySteps(48, 3, VoxelType::UInt8), test::builder(BuilderKind::Grid),
                             1.f / 255.f, true);
  expectPlaybackEqualsStatic(BackendKind::CUDA, nbodySteps(200, 3, VoxelType::Float32),
                             test::builder(BuilderKind::DistanceGrid), 1.f / 255.f, true);
  // A prefetch of another shape, or of a step never shown: nothing breaks, setVolume uploads.
  const std::vector<Volume> a = nbodySteps(48, 2, VoxelType::UInt8), other = nbodySteps(40, 1, VoxelType::UInt8);
  double lo = 0, hi = 1;
  ASSERT_TRUE(a[0].scalarRange(lo, hi));
  Engine e(BackendKind::CUDA);
  test::load(e, a[0], TransferFunction::preset("ramp", lo, hi), test::builder(BuilderKind::Grid));
  Image img, ref;
  e.render(test::orbit(a[0], 10, 20), 64, 64, img);
  EXPECT_FALSE(e.prefetchVolume(other[0]));  // another shape
  EXPECT_TRUE(e.prefetchVolume(a[1]));
  e.setVolume(a[0]);  // not the prefetched step: uploaded as before
  e.render(test::orbit(a[0], 10, 20), 64, 64, ref);
  EXPECT_EQ(compareImages(img, ref).maxAbs, 0.f);
  EXPECT_EQ(e.counters().prefetchedSteps, 0);
}
/// `steps` copied into `e`'s step memory (Engine::allocateStepMemory), as a reader that reads
/// each step there hands them over; `keep` holds the memory.
std::vector<Volume> inStepMemory(Engine& e, const std::vector<Volume>& steps,
                                 std::vector<std::shared_ptr<unsigned char>>& keep) {
  std::vector<Volume> out = steps;
  for (Volume& v : out) {
    keep.push_back(e.allocateStepMemory(v.byteSize()));
    std::memcpy(keep.back().get(), v.data, v.byteSize());
    v.data = keep.back().get();
    v.storage.reset();
  }
  return out;
}
TEST(TimeSeries, StepsInTheEnginesStepMemoryPlayAsOthers) {
  // Page-locked on CUDA (one DMA a step, above the staging's two-chunk threshold and below it),
  // plain memory on the CPU: every played frame equals its step's static render.
  std::vector<std::shared_ptr<unsigned char>> keep;
  Engine cpu(BackendKind::CPU);
  expectPlaybackEqualsStatic(BackendKind::CPU, inStepMemory(cpu, nbodySteps(48, 3, VoxelType::UInt8), keep),
                             test::builder(BuilderKind::Grid), 1.f / 255.f, true);
  if (!cudaAvailable()) return;
  Engine cuda(BackendKind::CUDA);
  expectPlaybackEqualsStatic(BackendKind::CUDA, inStepMemory(cuda, nbodySteps(384, 2, VoxelType::UInt8), keep),
                             test::builder(BuilderKind::Auto), 1.f / 255.f, true);
  expectPlaybackEqualsStatic(BackendKind::CUDA, inStepMemory(cuda, nbodySteps(200, 3, VoxelType::Float32), keep),
                             test::builder(BuilderKind::DistanceGrid), 1.f / 255.f, true);
  expectPlaybackEqualsStatic(BackendKind::CUDA, inStepMemory(cuda, nbodySteps(48, 3, VoxelType::UInt8), keep),
                             test::builder(BuilderKind::Grid), 1.f / 255.f, false);
}
TEST(TimeSeries, CudaUploadRatesAreMeasured) {
  SKIP_WITHOUT_CUDA();
  Engine e(BackendKind::CUDA);
  const UploadRates r = e.measureUpload(size_t(64) << 20);
  EXPECT_GT(r.pinned, 1e9);
  EXPECT_GT(r.pageable, 1e8);
  EXPECT_GT(r.staged, 1e8);
  Engine cpu(BackendKind::CPU);
  EXPECT_EQ(cpu.measureUpload(size_t(1) << 20).pinned, 0.0);
}

namespace {
/// Engine::valueRange equals the host's pass over the voxels for uint8, int16 and float32 steps,
/// needs none of its own (the upload's brick ranges; update() then does not upload again), and
/// declines (false) where it cannot know: no volume, a float volume with an infinity.
void expectValueRangeFromBrickRanges(BackendKind backend) {
  Engine none(backend);
  double lo = 0, hi = 0;
  EXPECT_FALSE(none.valueRange(lo, hi));
  for (VoxelType type : {VoxelType::UInt8, VoxelType::Float32}) {
    const std::vector<Volume> steps = nbodySteps(72, 2, type);
    double a = 0, b = 0;
    ASSERT_TRUE(steps[1].scalarRange(a, b));
    // The same step with valueRange (e) and without (ref): the same passes over the voxels.
    Engine e(backend), ref(backend);
    for (Engine* x : {&e, &ref}) {
      test::load(*x, steps[0], TransferFunction::preset("ramp", a, b), test::builder(BuilderKind::Grid));
      x->update();
      x->setVolume(steps[1]);
    }
    const int grids = e.counters().rangeGrids;
    ASSERT_TRUE(e.valueRange(lo, hi)) << voxelTypeName(type);
    EXPECT_EQ(lo, a) << voxelTypeName(type);
    EXPECT_EQ(hi, b) << voxelTypeName(type);
    EXPECT_EQ(e.counters().rangeGrids, grids + 1);  // the step's upload and brick ranges, done here
    e.update();
    ref.update();
    EXPECT_EQ(e.counters().rangeGrids, ref.counters().rangeGrids);  // and not again in update()
    EXPECT_EQ(e.counters().voxelPasses, ref.counters().voxelPasses);
  }
  // int16 with negative values.
  const Volume s = test::makeVolume<int16_t>(20, 17, 9, VoxelType::Int16,
                                            [](int i, int j, int k) { return (i * 7919 + j * 31 + k * 977) % 6001 - 3000; });
  double a = 0, b = 0;
  ASSERT_TRUE(s.scalarRange(a, b));
  Engine e(backend);
  test::load(e, s, TransferFunction::preset("ramp", a, b), test::builder(BuilderKind::Grid));
  ASSERT_TRUE(e.valueRange(lo, hi));
  EXPECT_EQ(lo, a);
  EXPECT_EQ(hi, b);
  // An infinity: not known from the brick ranges (the host's finite range is the caller's).
  const Volume f = test::makeVolume<float>(16, 16, 16, VoxelType::Float32, [](int i, int j, int k) {
    return i == 5 && j == 6 && k == 7 ? INFINITY : float(i + j + k) / 45.f;
  });
  Engine g(backend);
  test::load(g, f, TransferFunction::preset("ramp", 0, 1), test::builder(BuilderKind::Grid));
  EXPECT_FALSE(g.valueRange(lo, hi));
}
}  // namespace

TEST(TimeSeries, ValueRangeComesFromTheBrickRanges) { expectValueRangeFromBrickRanges(BackendKind::CPU); }
TEST(TimeSeries, CudaValueRangeComesFromTheBrickRanges) {
  SKIP_WITHOUT_CUDA();
  expectValueRangeFromBrickRanges(BackendKind::CUDA);
}

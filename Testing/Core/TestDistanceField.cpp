// DistanceGrid: the distance field is the capped Chebyshev distance to the nearest occupied
// brick (checked against brute force), and leaping with it is lossless (same image and same
// samples as the plain grid DDA, same image as naive).
#include "TestUtil.h"

#include "spaceskip/Backend.h"
#include "spaceskip/DistanceField.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <random>
#include <vector>
#include <string>

using namespace spaceskip;

namespace {


std::vector<uint8_t> bruteForce(const OccupancyGrid& g, int cap) {
  std::vector<uint8_t> d(size_t(g.size()));
  for (int z = 0; z < g.dims.z; ++z)
    for (int y = 0; y < g.dims.y; ++y)
      for (int x = 0; x < g.dims.x; ++x) {
        int best = cap;
        for (int k = 0; k < g.dims.z; ++k)
          for (int j = 0; j < g.dims.y; ++j)
            for (int i = 0; i < g.dims.x; ++i)
              if (g.at(i, j, k)) best = std::min(best, std::max({std::abs(i - x), std::abs(j - y), std::abs(k - z)}));
        d[size_t(g.index(x, y, z))] = uint8_t(best);
      }
  return d;
}

/// How many entries of two fields differ (a size mismatch counts as every entry of the larger).
int64_t differing(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  if (a.size() != b.size()) return int64_t(std::max(a.size(), b.size()));
  int64_t n = 0;
  for (size_t i = 0; i < a.size(); ++i) n += a[i] != b[i];
  return n;
}

}  // namespace

TEST(DistanceField, EqualsBruteForceChebyshevDistance) {
  const vec3i shapes[] = {{17, 13, 11}, {1, 1, 40}, {40, 1, 1}, {3, 29, 2}, {14, 15, 13}};
  unsigned seed = 1;
  for (vec3i dims : shapes)
    for (double p : {0.0, 0.002, 0.03, 0.4, 1.0})
      for (int cap : {kMaxSkipDistance, 5, 1}) {
        OccupancyGrid g = test::randomBrickGrid(dims, p, seed++);
        const auto field = computeDistanceField(g, cap);
        const auto ref = bruteForce(g, cap);
        ASSERT_EQ(field.size(), ref.size());
        EXPECT_EQ(differing(field, ref), 0) << dims.x << "x" << dims.y << "x" << dims.z << " p " << p << " cap " << cap;
        for (size_t i = 0; i < ref.size(); ++i) EXPECT_EQ(field[i] == 0, g.occ[i] != 0);
      }
}

TEST(DistanceField, TheLinearLinePassEqualsThePerBrickPass) {
  // distanceLine (two O(n) sweeps, what the builds run) against distancePass (the definition,
  // per brick) on lines of every kind of input a pass sees: 0/cap (pass 1), earlier passes'
  // values (any in [0, cap], here random, sparse or smooth), values above cap, strided lines.
  std::mt19937 rng(7);
  int64_t checked = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const int cap = trial % 7 == 0 ? 1 + int(rng() % 3) : trial % 5 == 0 ? 255 : int(1 + rng() % 70);
    const int n = int(rng() % (trial % 3 == 0 ? 300 : 40));
    const int64_t stride = 1 + int64_t(rng() % 3);
    std::vector<uint8_t> in(size_t(std::max<int64_t>(1, n * stride + 1)), 0), out(in.size(), 77);
    const int kind = trial % 4;
    for (int i = 0; i < n; ++i) {
      uint8_t v = 0;
      if (kind == 0) v = rng() % 50 == 0 ? 0 : uint8_t(cap);                        // pass 1
      else if (kind == 1) v = uint8_t(rng() % (cap + 1));                           // any value
      else if (kind == 2) v = uint8_t(std::min<int>(cap, int(std::abs(i - n / 2))));  // smooth
      else v = uint8_t(rng() % 256);                                                // above cap too
      in[size_t(i * stride)] = v;
    }
    std::vector<int> last(size_t(cap) + 1);
    distanceLine(in.data(), out.data(), 0, stride, n, cap, last.data(), 1);
    for (int i = 0; i < n; ++i) {
      const uint8_t ref = distancePass(in.data(), i * stride, stride, i, n, cap);
      ASSERT_EQ(int(out[size_t(i * stride)]), int(ref))
          << "trial " << trial << " n " << n << " cap " << cap << " brick " << i;
      ++checked;
    }
    for (size_t k = 0; k < out.size(); ++k)
      if (k % size_t(stride) != 0 || k >= size_t(n) * size_t(stride)) ASSERT_EQ(out[k], 77) << "wrote off the line";
  }
  EXPECT_GT(checked, 100000);
}

TEST(DistanceField, SegmentsOfALineComputedApartEqualTheWholeLine) {
  // distanceSegment (what the CUDA passes run, up to 8 threads a line) against distanceLine: a
  // line cut into 1 to 9 segments of any length, each computed alone with its own int16 scratch,
  // on lines shorter and longer than the cap and every kind of input a pass sees.
  std::mt19937 rng(11);
  int64_t checked = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const int cap = trial % 6 == 0 ? 1 + int(rng() % 3) : trial % 5 == 0 ? 255 : int(1 + rng() % 70);
    const int n = 1 + int(rng() % (trial % 2 == 0 ? 320 : 50));
    const int64_t stride = 1 + int64_t(rng() % 3);
    std::vector<uint8_t> in(size_t(n * stride), 0), whole(in.size(), 77), parts(in.size(), 77);
    for (int i = 0; i < n; ++i) {
      const int kind = trial % 3;
      in[size_t(i * stride)] = kind == 0 ? (rng() % 40 == 0 ? 0 : uint8_t(cap))
                               : kind == 1 ? uint8_t(rng() % (cap + 1))
                                           : uint8_t(rng() % 256);
    }
    std::vector<int> last(size_t(cap) + 1);
    distanceLine(in.data(), whole.data(), 0, stride, n, cap, last.data(), 1);
    const int segs = 1 + int(rng() % 9), segLen = (n + segs - 1) / segs;
    std::vector<int16_t> last16(size_t(cap) + 1);
    for (int a = 0; a < n; a += segLen)
      distanceSegment(in.data(), parts.data(), 0, stride, n, a, std::min(n, a + segLen), cap, last16.data(), 1);
    for (int i = 0; i < n; ++i, ++checked)
      ASSERT_EQ(int(parts[size_t(i * stride)]), int(whole[size_t(i * stride)]))
          << "trial " << trial << " n " << n << " cap " << cap << " segments " << segs << " brick " << i;
    EXPECT_EQ(parts, whole) << "wrote off the line";
  }
  EXPECT_GT(checked, 100000);
}

TEST(DistanceField, TheCudaFieldEqualsTheCpuField) {
  // The CUDA kernels (up to 8 threads a line, lines staged in shared memory) against the oneTBB
  // build, on shapes with lines of 1 to 300 bricks (a last block of fewer than 32 lines), sparse
  // to full grids and every cap. The last two stage their lines in 16-byte pieces (dims that are
  // multiples of 16), the last one mixing such blocks with blocks whose lines straddle two rows.
  SKIP_WITHOUT_CUDA();
  const vec3i shapes[] = {{17, 13, 11}, {1, 1, 300}, {300, 1, 1}, {3, 29, 2}, {64, 48, 40},
                           {260, 37, 35}, {33, 257, 5}, {256, 144, 160}, {144, 256, 160}};
  unsigned seed = 100;
  for (vec3i dims : shapes)
    for (double p : {0.0, 0.001, 0.03, 0.4, 1.0})
      for (int cap : {kMaxSkipDistance, 255, 5, 1}) {
        const OccupancyGrid g = test::randomBrickGrid(dims, p, seed++);
        const auto cpu = computeDistanceField(g, cap);
        const auto gpu = computeDistanceFieldCuda(g, cap);
        EXPECT_EQ(differing(gpu, cpu), 0) << dims.x << "x" << dims.y << "x" << dims.z << " p " << p << " cap " << cap;
      }
}

TEST(DistanceField, LeapingIsLosslessAndTakesTheGridsSamples) {
  // Sparse N-body data leave long empty stretches, so most grid steps become leaps; cameras
  // include axis-aligned rays (zero direction components), perspective, and one inside the volume.
  Volume v = generateVolume("nbody", vec3l{128, 128, 128});
  auto tf = TransferFunction::preset("ramp", 0, 255);
  double b[6];
  v.worldBounds(b);
  struct Cam {
    double az, el;
    bool persp;
  };
  const Cam cams[] = {{0, 0, false}, {0, 90, false}, {33, 21, false}, {200, -60, true}, {90, 0, true}};
  for (const Cam& c : cams) {
    const Camera cam = orbitCamera(b, c.az, c.el, 1, c.persp, 1);
    int64_t samples[2];
    Image img[2] = {test::renderCounting(v, tf, BuilderKind::Grid, cam, 96, samples[0]),
                    test::renderCounting(v, tf, BuilderKind::DistanceGrid, cam, 96, samples[1])};
    ASSERT_GT(test::coverage(img[0]), 0.001);
    EXPECT_EQ(samples[0], samples[1]) << "az " << c.az << " el " << c.el;
    EXPECT_LE(compareImages(img[0], img[1]).maxAbs, 1.f / 255.f) << "az " << c.az << " el " << c.el;
  }
  // A camera inside the volume, looking along a diagonal.
  const double eye[3] = {0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), 0.5 * (b[4] + b[5])};
  const double at[3] = {b[1], b[3], b[5]}, up[3] = {0, 1, 0};
  Camera inside = lookAtCamera(eye, at, up, true, 60, 1, 0.1, 1000);
  int64_t samples[3];
  Image img[3] = {test::renderCounting(v, tf, BuilderKind::Naive, inside, 96, samples[0]),
                  test::renderCounting(v, tf, BuilderKind::Grid, inside, 96, samples[1]),
                  test::renderCounting(v, tf, BuilderKind::DistanceGrid, inside, 96, samples[2])};
  EXPECT_EQ(samples[1], samples[2]);
  ASSERT_GT(test::coverage(img[0]), 0.001);
  EXPECT_LE(compareImages(img[0], img[2]).maxAbs, 1.f / 255.f);
  EXPECT_LE(compareImages(img[1], img[2]).maxAbs, 1.f / 255.f);
}

TEST(DistanceField, RebuiltOnlyWhenTheOccupancyChanges) {
  Volume v = generateVolume("shell", vec3l{48, 48, 48});
  Engine e(BackendKind::CPU);
  e.setVolume(v);
  e.setTransferFunction(TransferFunction::preset("ramp", 0, 255));
  e.setBuildParams(test::builder(BuilderKind::DistanceGrid));
  double b[6];
  v.worldBounds(b);
  Image img;
  e.render(orbitCamera(b, 10, 10, 1, false, 1), 32, 32, img);
  const int builds = e.counters().builds;
  TransferFunction recolored = TransferFunction::preset("coolwarm", 0, 255);
  recolored.table = TransferFunction::preset("ramp", 0, 255).table;
  for (size_t k = 0; k < recolored.table.size(); ++k) recolored.table[k].x = 1.f - recolored.table[k].x;
  e.setTransferFunction(recolored);  // colour only
  e.render(orbitCamera(b, 10, 10, 1, false, 1), 32, 32, img);
  EXPECT_EQ(e.counters().builds, builds);
  e.setTransferFunction(TransferFunction::preset("spike", 0, 255));  // new occupancy
  e.render(orbitCamera(b, 10, 10, 1, false, 1), 32, 32, img);
  EXPECT_EQ(e.counters().builds, builds + 1);
}

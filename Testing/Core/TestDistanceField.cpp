// DistanceGrid: the distance field is the capped Chebyshev distance to the nearest occupied
// brick (checked against brute force), and leaping with it is lossless (same image and same
// samples as the plain grid DDA, same image as naive).
#include "TestUtil.h"

#include "spaceskip/DistanceField.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <random>

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
        int64_t bad = 0;
        for (size_t i = 0; i < ref.size(); ++i) bad += field[i] != ref[i];
        EXPECT_EQ(bad, 0) << dims.x << "x" << dims.y << "x" << dims.z << " p " << p << " cap " << cap;
        for (size_t i = 0; i < ref.size(); ++i) EXPECT_EQ(field[i] == 0, g.occ[i] != 0);
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

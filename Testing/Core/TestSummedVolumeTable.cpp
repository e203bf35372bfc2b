// Summed volume table: counts and tight boxes against brute force on random occupancy grids.
#include "spaceskip/SummedVolumeTable.h"
#include "TreeInvariants.h"

#include "TestUtil.h"

#include <gtest/gtest.h>

#include <random>

using namespace spaceskip;

namespace {
using test::randomBrickGrid;

int64_t bruteCount(const OccupancyGrid& g, const box3i& b) {
  int64_t c = 0;
  for (int z = b.lo.z; z < b.hi.z; ++z)
    for (int y = b.lo.y; y < b.hi.y; ++y)
      for (int x = b.lo.x; x < b.hi.x; ++x) c += g.at(x, y, z);
  return c;
}

box3i randomBox(vec3i d, std::mt19937& rng) {
  box3i b;
  for (int a = 0; a < 3; ++a) {
    int u = int(rng() % unsigned(d[a] + 1)), v = int(rng() % unsigned(d[a] + 1));
    b.lo[a] = std::min(u, v);
    b.hi[a] = std::max(u, v);
  }
  return b;
}
}  // namespace

TEST(SummedVolumeTable, CountsAndShrinkMatchBruteForce) {
  for (double p : {0.002, 0.05, 0.5, 1.0}) {
    OccupancyGrid g = randomBrickGrid(vec3i{23, 17, 31}, p, unsigned(p * 1000) + 7);
    SummedVolumeTable svt(g);
    EXPECT_EQ(svt.count(box3i{vec3i{0, 0, 0}, g.dims}), g.occupied);
    std::mt19937 rng(42);
    for (int i = 0; i < 400; ++i) {
      box3i b = randomBox(g.dims, rng);
      ASSERT_EQ(svt.count(b), bruteCount(g, b)) << "p=" << p << " query " << i;
      box3i s = svt.shrink(b), r = test::bruteTightBox(g, b);
      for (int a = 0; a < 3; ++a) {
        ASSERT_EQ(s.lo[a], r.lo[a]) << "p=" << p << " query " << i << " axis " << a;
        ASSERT_EQ(s.hi[a], r.hi[a]) << "p=" << p << " query " << i << " axis " << a;
      }
    }
  }
}

TEST(SummedVolumeTable, EmptyAndSingleBrick) {
  OccupancyGrid g = randomBrickGrid(vec3i{9, 9, 9}, 0.0, 1);
  SummedVolumeTable svt(g);
  EXPECT_EQ(svt.count(box3i{vec3i{0, 0, 0}, g.dims}), 0);
  EXPECT_TRUE(svt.shrink(box3i{vec3i{0, 0, 0}, g.dims}).empty());
  g.occ[size_t(g.index(4, 0, 8))] = 1;
  g.occupied = 1;
  SummedVolumeTable one(g);
  box3i s = one.shrink(box3i{vec3i{0, 0, 0}, g.dims});
  EXPECT_EQ(s.lo.x, 4);
  EXPECT_EQ(s.hi.x, 5);
  EXPECT_EQ(s.lo.y, 0);
  EXPECT_EQ(s.hi.y, 1);
  EXPECT_EQ(s.lo.z, 8);
  EXPECT_EQ(s.hi.z, 9);
  // Boxes reaching outside the grid are clipped.
  EXPECT_EQ(one.count(box3i{vec3i{-5, -5, -5}, vec3i{50, 50, 50}}), 1);
}

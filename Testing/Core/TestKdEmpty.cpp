// Leaf criterion Empty (KdTreeSplit.h, kdEmptySplit): the split rule for the paper's open problem.
// The greedy cost stalls on empty space inside a node (the Xmas-tree leaf), MLS over-splits
// homogeneous space (the Richtmyer-Meshkov case). Empty must bound less empty space than Deep
// and MLS-128, build fewer nodes than MLS-32 on homogeneous space, keep every invariant, and
// render Naive's image.
#include "Options.h"
#include "TestUtil.h"
#include "TreeInvariants.h"

#include "spaceskip/Builders.h"
#include "spaceskip/KdTreeBuilder.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

using namespace spaceskip;

namespace {

BuildParams kd(LeafCriterion leaf, int mls = 0) { return test::builder(BuilderKind::KdTreeCPU, leaf, mls, 0, 8); }

OccupancyGrid occupancyOf(const Volume& v, int brick = 8) {
  double lo = 0, hi = 255;
  v.scalarRange(lo, hi);
  return classify(computeRangeGrid(v, brick), TransferFunction::preset("ramp", lo, hi));
}

/// Empty bricks inside the leaves (what a ray marches through without need), and the largest
/// leaf in bricks.
struct LeafWaste {
  int64_t emptyBricks = 0, largest = 0;
};
LeafWaste leafWaste(const Tree& t, const OccupancyGrid& g) {
  LeafWaste w;
  for (const Node& n : t.nodes) {
    if (n.child >= 0) continue;
    const box3i b = cellBrickBox(n.box, g.brick);
    int64_t o = 0;
    for (int z = b.lo.z; z < b.hi.z; ++z)
      for (int y = b.lo.y; y < b.hi.y; ++y)
        for (int x = b.lo.x; x < b.hi.x; ++x) o += g.at(x, y, z) ? 1 : 0;
    w.emptyBricks += b.volume() - o;
    w.largest = std::max<int64_t>(w.largest, b.volume());
  }
  return w;
}

}  // namespace

TEST(KdEmpty, HollowBoxIsResolvedWhereDeepStalls) {
  // The surface of a box of bricks: no plane removes empty space (Deep keeps one leaf around the
  // whole hollow); Empty splits it into its walls.
  OccupancyGrid g;
  g.brick = 8;
  g.dims = vec3i{24, 20, 16};
  g.cellDims = vec3i{g.dims.x * 8, g.dims.y * 8, g.dims.z * 8};
  g.occ.assign(size_t(g.size()), 0);
  for (int z = 0; z < g.dims.z; ++z)
    for (int y = 0; y < g.dims.y; ++y)
      for (int x = 0; x < g.dims.x; ++x)
        if (x == 0 || y == 0 || z == 0 || x == g.dims.x - 1 || y == g.dims.y - 1 || z == g.dims.z - 1)
          g.occ[size_t(g.index(x, y, z))] = 1, ++g.occupied;
  const Tree deep = buildKdTree(g, kd(LeafCriterion::Deep));
  const Tree empty = buildKdTree(g, kd(LeafCriterion::Empty));
  test::checkTreeInvariants(empty, g, "hollow empty");
  EXPECT_EQ(deep.nodes.size(), 1u);
  EXPECT_EQ(leafWaste(empty, g).emptyBricks, 0) << "the walls are full boxes: no empty brick left in a leaf";
  EXPECT_LE(empty.leaves, 12) << "about one leaf per wall, not per brick";
}

TEST(KdEmpty, HomogeneousBlocksStayOneLeafEach) {
  // A full block below and a full layer above, empty space between: no plane along the longest
  // axis (x, first on ties) removes anything, so Deep keeps one leaf with the gap inside; MLS-32
  // cuts both blocks into 32-cell leaves; Empty splits at the gap and keeps each block whole.
  OccupancyGrid g;
  g.brick = 8;
  g.dims = vec3i{32, 32, 32};
  g.cellDims = vec3i{256, 256, 256};
  g.occ.assign(size_t(g.size()), 0);
  for (int z = 0; z < 32; ++z)
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x)
        if (z < 14 || z >= 24) g.occ[size_t(g.index(x, y, z))] = 1, ++g.occupied;
  const Tree deep = buildKdTree(g, kd(LeafCriterion::Deep));
  const Tree m32 = buildKdTree(g, kd(LeafCriterion::Deep, 32));
  const Tree empty = buildKdTree(g, kd(LeafCriterion::Empty));
  test::checkTreeInvariants(empty, g, "homogeneous empty");
  EXPECT_EQ(deep.nodes.size(), 1u);
  EXPECT_EQ(empty.nodes.size(), 3u);
  const LeafWaste w = leafWaste(empty, g);
  EXPECT_EQ(w.largest, 32 * 32 * 14) << "the lower block is one leaf";
  EXPECT_EQ(w.emptyBricks, 0);
  EXPECT_GT(m32.nodes.size(), 100u) << "MLS-32 over-splits the blocks";
}

TEST(KdEmpty, XmasAndRichtmyerMeshkovStandIns) {
  // The paper's two cases at 128^3-class sizes: on the Xmas tree Empty leaves less empty space in
  // leaves than Deep and MLS-128; on Richtmyer-Meshkov fewer nodes than MLS-32 and MLS-128.
  {
    const Volume v = generateVolume("xmas_tree", vec3l{128, 125, 128}, 1);
    const OccupancyGrid g = occupancyOf(v);
    const Tree deep = buildKdTree(g, kd(LeafCriterion::Deep));
    const Tree m128 = buildKdTree(g, kd(LeafCriterion::Deep, 128));
    const Tree empty = buildKdTree(g, kd(LeafCriterion::Empty));
    test::checkTreeInvariants(empty, g, "xmas empty");
    const int64_t we = leafWaste(empty, g).emptyBricks, wd = leafWaste(deep, g).emptyBricks,
                  wm = leafWaste(m128, g).emptyBricks;
    std::printf("xmas 128: empty bricks in leaves: deep %lld, mls128 %lld, empty %lld; nodes %zu %zu %zu\n",
                (long long)wd, (long long)wm, (long long)we, deep.nodes.size(), m128.nodes.size(), empty.nodes.size());
    EXPECT_LT(we, wd);
    EXPECT_LT(we, wm);
  }
  {
    const Volume v = generateVolume("richtmyer_meshkov", vec3l{256, 256, 240}, 1);
    const OccupancyGrid g = occupancyOf(v);
    const Tree m32 = buildKdTree(g, kd(LeafCriterion::Deep, 32));
    const Tree m128 = buildKdTree(g, kd(LeafCriterion::Deep, 128));
    const Tree empty = buildKdTree(g, kd(LeafCriterion::Empty));
    test::checkTreeInvariants(empty, g, "rm empty");
    std::printf("rm 256: nodes mls32 %zu, mls128 %zu, empty %zu; largest leaf (bricks) %lld %lld %lld\n", m32.nodes.size(),
                m128.nodes.size(), empty.nodes.size(), (long long)leafWaste(m32, g).largest,
                (long long)leafWaste(m128, g).largest, (long long)leafWaste(empty, g).largest);
    EXPECT_LT(empty.nodes.size(), m32.nodes.size());
    EXPECT_GT(leafWaste(empty, g).largest, leafWaste(m128, g).largest) << "the homogeneous region is not cut by size";
  }
}

TEST(KdEmpty, ImagesEqualNaive) {
  for (const char* shape : {"xmas_tree", "richtmyer_meshkov", "stag_beetle", "menger"}) {
    const Volume v = generateVolume(shape, vec3l{64, 62, 60}, 1);
    double lo = 0, hi = 255;
    ASSERT_TRUE(v.scalarRange(lo, hi));
    const TransferFunction tf = TransferFunction::preset("ramp", lo, hi);
    for (double az : {30.0, 200.0}) {
      const Image ref = test::renderWith(v, tf, test::builder(BuilderKind::Naive), az, 20, az > 100, 64);
      ASSERT_GT(test::coverage(ref), 0.0) << shape;
      for (BuildParams p : {kd(LeafCriterion::Empty), test::builder(BuilderKind::KdTreeGPUFast, LeafCriterion::Empty, 0, 0),
                            test::builder(BuilderKind::KdTreeGPU, LeafCriterion::Empty, 0, 4)}) {
        const Image img = test::renderWith(v, tf, p, az, 20, az > 100, 64);
        EXPECT_LE(compareImages(ref, img).maxAbs, 1.f / 255.f) << shape << " " << builderName(p.builder) << " az " << az;
      }
    }
  }
}

TEST(KdEmpty, CliParsesTheCriterion) {
  cli::Options o;
  EXPECT_EQ(cli::buildParams(o, "kdtree-cpu:empty").leaf, LeafCriterion::Empty);
  o.kv["--leaf"] = "empty";
  EXPECT_EQ(cli::buildParams(o, "kdtree-gpu-fast").leaf, LeafCriterion::Empty);
  EXPECT_EQ(cli::buildParams(o, "kdtree-gpu-fast:deep").leaf, LeafCriterion::Deep);
  o.kv["--leaf"] = "hollow";
  EXPECT_THROW(cli::buildParams(o, "kdtree-cpu"), std::invalid_argument);
}

// The shared k-d split rule's sweep mode (bins = 0, spaceskip/KdTreeSplit.h) against KdTreeCPU: a
// serial host recursion over decideKdSplit with a brute-force (or SVT) tight box must build the
// KdTreeCPU tree (task-parallel, SvtView tight boxes) node for node, for procedural volumes, random
// TFs, several brick sizes, volumes that are not a multiple of the brick (clamped boxes), and every
// leaf criterion. KdTreeGPU and KdTreeGPUFast run that same rule (TestCuda.cpp checks them on a device).
#include "TestUtil.h"
#include "TreeInvariants.h"

#include "spaceskip/Builders.h"
#include "spaceskip/Generators.h"
#include "spaceskip/KdTreeBuilder.h"
#include "spaceskip/KdTreeSplit.h"
#include "spaceskip/SummedVolumeTable.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <tuple>
#include <vector>

using namespace spaceskip;

namespace {

/// Tight cell box of the occupied bricks inside a cell region on the brick raster (what the GPU
/// builders' tight() returns); an empty box when none. Brute force over the bricks unless an
/// SVT is given (for the larger grids).
struct HostTight {
  const OccupancyGrid& g;
  const SummedVolumeTable* svt = nullptr;
  int calls = 0;

  box3i operator()(const box3i& region) {
    ++calls;
    const box3i b = cellBrickBox(region, g.brick);
    const box3i t = svt ? svt->shrink(b) : test::bruteTightBox(g, b);
    if (t.empty()) return box3i{region.lo, region.lo};
    return brickCellBox(t, g.brick, g.cellDims);
  }
  /// Occupied bricks in [lo, hi) (brick coordinates): leaf criterion Empty's query.
  int64_t count(vec3i lo, vec3i hi) const {
    if (svt) return svt->count(box3i{lo, hi});
    int64_t o = 0;
    for (int z = lo.z; z < hi.z; ++z)
      for (int y = lo.y; y < hi.y; ++y)
        for (int x = lo.x; x < hi.x; ++x) o += g.at(x, y, z) ? 1 : 0;
    return o;
  }
};

/// Host recursion over the shared decision, in KdTreeCPU's layout (root at 0, each split node's
/// children appended when it is reached depth-first, left first).
struct SharedDecisionTree {
  const OccupancyGrid& g;
  BuildParams p;
  HostTight tight;
  detail::KdSplitParams sp{};
  Tree t;

  void node(int index, int depth) {
    ASSERT_LT(depth, kMaxTreeHeight);
    const detail::KdDecision d = detail::decideKdSplit(t.nodes[size_t(index)].box, sp, tight);
    if (!d.split) return;
    const int c = int(t.nodes.size());
    t.nodes[size_t(index)].child = c;
    t.nodes.push_back(Node{d.left, -1, 0});
    t.nodes.push_back(Node{d.right, -1, 0});
    node(c, depth + 1);
    node(c + 1, depth + 1);
  }
  Tree build() {
    const box3i root = tight(box3i{vec3i{0, 0, 0}, g.cellDims});
    if (root.empty()) return t;
    sp.deep = p.leaf != LeafCriterion::Shallow ? 1 : 0;
    sp.empty = p.leaf == LeafCriterion::Empty ? 1 : 0;
    sp.mls = p.maxLeafSize;
    sp.bins = p.bins;
    sp.brick = g.brick;
    sp.rootVol = root.volume();
    t.nodes.push_back(Node{root, -1, 0});
    node(0, 1);
    computeTreeStats(t);
    return t;
  }
};

Tree sharedDecisionTree(const OccupancyGrid& g, const BuildParams& p, bool useSvt) {
  SummedVolumeTable svt;
  if (useSvt) svt = SummedVolumeTable(g);
  SharedDecisionTree b{g, p, HostTight{g, useSvt ? &svt : nullptr}};
  return b.build();
}

BuildParams kd(LeafCriterion leaf, int mls, int bins, int brick) {
  return test::builder(BuilderKind::KdTreeCPU, leaf, mls, bins, brick);
}

std::string describe(const BuildParams& p) {
  return std::string(p.leaf == LeafCriterion::Shallow ? "shallow" : p.leaf == LeafCriterion::Empty ? "empty" : "deep") + ":mls" + std::to_string(p.maxLeafSize) +
         ":bins" + std::to_string(p.bins) + ":brick" + std::to_string(p.brick);
}

using LeafKey = std::tuple<int, int, int, int, int, int>;
std::vector<LeafKey> leafBoxes(const Tree& t) {
  std::vector<LeafKey> v;
  for (const Node& n : t.nodes)
    if (n.child < 0) v.emplace_back(n.box.lo.x, n.box.lo.y, n.box.lo.z, n.box.hi.x, n.box.hi.y, n.box.hi.z);
  std::sort(v.begin(), v.end());
  return v;
}

/// True when both trees are identical: same leaf-box multiset, node count, height, and (same
/// layout) the same box and child link at every index. Adds failures when `expect` is set.
bool sameTree(const Tree& a, const Tree& b, const std::string& what, bool expect) {
  bool same = a.nodes.size() == b.nodes.size() && a.height == b.height && a.leaves == b.leaves &&
              leafBoxes(a) == leafBoxes(b);
  for (size_t i = 0; same && i < a.nodes.size(); ++i)
    same = test::sameBox(a.nodes[i].box, b.nodes[i].box) && a.nodes[i].child == b.nodes[i].child;
  if (expect && !same)
    ADD_FAILURE() << what << ": nodes " << a.nodes.size() << " vs " << b.nodes.size() << ", height " << a.height
                  << " vs " << b.height << ", leaves " << a.leaves << " vs " << b.leaves
                  << (leafBoxes(a) == leafBoxes(b) ? " (same leaf boxes)" : " (leaf boxes differ)");
  return same;
}

using test::randomTF;

std::vector<BuildParams> sweepVariants(int brick) {
  return {kd(LeafCriterion::Shallow, 0, 0, brick), kd(LeafCriterion::Deep, 0, 0, brick),
          kd(LeafCriterion::Deep, 32, 0, brick), kd(LeafCriterion::Deep, 128, 0, brick),
          kd(LeafCriterion::Shallow, 32, 0, brick), kd(LeafCriterion::Deep, 4, 0, brick),
          kd(LeafCriterion::Empty, 0, 0, brick)};
}

}  // namespace

TEST(KdSweep, CandidatesAreKdTreeCpuBrickBoundaries) {
  // Node of bricks [3, 3 + nb) along x, its last brick clamped (hi = cellDims 61 for brick 8).
  for (int brick : {1, 2, 3, 4, 8, 16}) {
    const int step = std::max(1, (8 + brick - 1) / brick);
    for (int nb = 1; nb <= 40; ++nb) {
      for (int clamp : {0, 1}) {
        box3i box{vec3i{3 * brick, 0, 0}, vec3i{(3 + nb) * brick - (clamp && brick > 1 ? brick / 2 : 0), 1, 1}};
        detail::KdSplitParams p{1, 0, 0, brick, 1};
        std::vector<int> planes;
        for (int k = 1; k <= detail::kdCandidateCount(box, 0, p); ++k)
          planes.push_back(detail::kdCandidatePlane(box, 0, k, p));
        std::vector<int> expected;  // Vidal's sweep: first + step * k, 0 < k < nb / step (bricks)
        for (int k = 1; k < nb / step; ++k) expected.push_back((3 + step * k) * brick);
        EXPECT_EQ(planes, expected) << "brick " << brick << " bricks " << nb << " clamped " << clamp;
      }
    }
  }
}

TEST(KdSweep, SharedDecisionBuildsTheKdTreeCpuTree) {
  struct Case {
    const char* shape;
    vec3l dims;
    int brick;
  };
  // Dims off the brick raster on purpose: clamped boxes are where MLS placement could diverge.
  const Case cases[] = {{"nbody", {128, 128, 128}, 8}, {"nbody", {100, 77, 90}, 8}, {"menger", {81, 81, 81}, 8},
                        {"vessels", {96, 96, 96}, 4},  {"shell", {61, 50, 45}, 8}, {"rm", {64, 48, 40}, 2},
                        {"nbody", {150, 140, 130}, 16}, {"vessels", {70, 66, 75}, 3}};
  unsigned seed = 7;
  int trees = 0, splitting = 0;
  for (const Case& c : cases) {
    const Volume v = generateVolume(c.shape, c.dims, 3);
    const RangeGrid rg = computeRangeGrid(v, c.brick);
    for (int k = 0; k < 3; ++k) {
      double lo = 0, hi = 255;
      v.scalarRange(lo, hi);
      const TransferFunction tf = k == 0 ? TransferFunction::preset("ramp", lo, hi) : randomTF(seed++);
      const OccupancyGrid g = classify(rg, tf);
      for (const BuildParams& p : sweepVariants(c.brick)) {
        const std::string what = std::string(c.shape) + " " + std::to_string(c.dims.x) + " tf " + std::to_string(k) +
                                 " " + describe(p);
        const Tree cpu = buildKdTree(g, p);
        const Tree shared = sharedDecisionTree(g, p, g.size() > 40000);
        sameTree(shared, cpu, what, true);
        test::checkTreeInvariants(shared, g, what);
        ++trees;
        splitting += cpu.nodes.size() > 1;
      }
    }
  }
  EXPECT_GT(2 * splitting, trees) << "most cases must exercise real splits";
}

TEST(KdSweep, RejectionThresholdMatches) {
  // A one-brick-thick slab of bricks, all occupied but the corner brick (X-1, Y-1, 0). The only
  // plane that removes empty space is the last brick boundary along x; it removes exactly one
  // brick (512 cells). 50x15 bricks: 512 > vol/1000 = 384, a split (3 nodes). 50x20 bricks:
  // 512 == vol/1000, rejected (one leaf). Catches an off-by-one or a different 1/1000 rule.
  for (auto [ny, nodes] : {std::pair{15, 3u}, std::pair{20, 1u}}) {
    OccupancyGrid g;
    g.brick = 8;
    g.dims = vec3i{50, ny, 1};
    g.cellDims = vec3i{400, 8 * ny, 8};
    g.occ.assign(size_t(g.size()), 1);
    g.occ[size_t(g.index(49, ny - 1, 0))] = 0;
    g.occupied = g.size() - 1;
    const BuildParams p = kd(LeafCriterion::Deep, 0, 0, 8);
    const Tree cpu = buildKdTree(g, p);
    EXPECT_EQ(cpu.nodes.size(), nodes) << "ny " << ny;
    sameTree(sharedDecisionTree(g, p, false), cpu, "corner slab ny " + std::to_string(ny), true);
  }
}

TEST(KdSweep, LargerNbodyWithSvtTight) {
  // The bench's volume at a size the host can afford: 256^3 N-body, 32^3 bricks.
  const Volume v = generateVolume("nbody", vec3l{256, 256, 256}, 1);
  const OccupancyGrid g = classify(computeRangeGrid(v, 8), TransferFunction::preset("ramp", 0, 255));
  for (const BuildParams& p : sweepVariants(8)) {
    const Tree cpu = buildKdTree(g, p);
    sameTree(sharedDecisionTree(g, p, true), cpu, "nbody 256 " + describe(p), true);
  }
}

TEST(KdSweep, BinnedTreesDifferFromKdTreeCpu) {
  // The comparison above is not vacuous: the paper's binned candidates (bins >= 2) give other
  // trees than the sweep on the same data (the fps gap that bins 0 closes).
  const Volume v = generateVolume("nbody", vec3l{128, 128, 128}, 3);
  const OccupancyGrid g = classify(computeRangeGrid(v, 8), TransferFunction::preset("ramp", 0, 255));
  int differ = 0;
  for (int bins : {2, 4, 8}) {
    for (BuildParams p : sweepVariants(8)) {
      const Tree cpu = buildKdTree(g, p);
      p.bins = bins;
      differ += !sameTree(sharedDecisionTree(g, p, false), cpu, describe(p), false);
    }
  }
  EXPECT_GT(differ, 0);
}

TEST(KdSweep, EngineAcceptsBinsZeroAndRejectsOneAndNegative) {
  const Volume v = generateVolume("nbody", vec3l{64, 64, 64}, 2);
  Engine e(BackendKind::CPU);
  e.setLogger([](const std::string&) {});
  e.setVolume(v);
  e.setTransferFunction(TransferFunction::preset("ramp", 0, 255));
  BuildParams p = kd(LeafCriterion::Deep, 32, 0, 8);
  p.builder = BuilderKind::KdTreeGPUFast;  // the CPU backend builds KdTreeCPU in its place
  e.setBuildParams(p);
  EXPECT_EQ(e.buildParams().bins, 0);
  e.update();
  sameTree(e.tree(), buildKdTree(e.occupancy(), p), "engine bins 0", true);
  for (int bad : {1, -1, -4}) {
    BuildParams q = p;
    q.bins = bad;
    EXPECT_THROW(e.setBuildParams(q), std::invalid_argument) << "bins " << bad;
    EXPECT_EQ(e.buildParams().bins, 0) << "a rejected value must leave the parameters as they were";
  }
  p.bins = 2;
  EXPECT_NO_THROW(e.setBuildParams(p));
  EXPECT_EQ(e.buildParams().bins, 2);
}

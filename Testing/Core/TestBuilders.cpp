// CPU builders (KdTreeCPU shallow/deep/MLS, Hybrid, LBVH twin): tree invariants on procedural
// volumes and random occupancy, a brute-force reference k-d build, and images equal to naive.
#include "TestUtil.h"
#include "TreeInvariants.h"

#include "spaceskip/Builders.h"
#include "spaceskip/KdTreeBuilder.h"
#include "spaceskip/LbvhBuilder.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <set>

using namespace spaceskip;

namespace {

OccupancyGrid randomGrid(vec3i cellDims, int brick, double p, unsigned seed, bool clustered = false) {
  OccupancyGrid g;
  g.brick = brick;
  g.cellDims = cellDims;
  g.dims = vec3i{(cellDims.x + brick - 1) / brick, (cellDims.y + brick - 1) / brick, (cellDims.z + brick - 1) / brick};
  g.occ.assign(size_t(g.size()), 0);
  std::mt19937 rng(seed);
  std::bernoulli_distribution b(p);
  if (!clustered) {
    for (auto& o : g.occ) o = b(rng) ? 1 : 0;
  } else {
    // A few random blobs: the kind of occupancy where the sweep finds real splits.
    for (int k = 0; k < 6; ++k) {
      int cx = int(rng() % unsigned(g.dims.x)), cy = int(rng() % unsigned(g.dims.y)), cz = int(rng() % unsigned(g.dims.z));
      int r = 1 + int(rng() % 3u);
      for (int z = std::max(0, cz - r); z < std::min(g.dims.z, cz + r + 1); ++z)
        for (int y = std::max(0, cy - r); y < std::min(g.dims.y, cy + r + 1); ++y)
          for (int x = std::max(0, cx - r); x < std::min(g.dims.x, cx + r + 1); ++x)
            if (b(rng)) g.occ[size_t(g.index(x, y, z))] = 1;
    }
  }
  for (auto o : g.occ) g.occupied += o;
  return g;
}

using test::randomTF;

BuildParams kd(LeafCriterion leaf, int mls = 0, int brick = 8) {
  BuildParams p;
  p.builder = BuilderKind::KdTreeCPU;
  p.leaf = leaf;
  p.maxLeafSize = mls;
  p.brick = brick;
  return p;
}

// ---- Brute-force reference of the k-d build (no SVT, same rules, recursive layout). ----
struct RefKd {
  const OccupancyGrid& g;
  BuildParams p;
  int64_t rootVol = 0;
  Tree t;

  box3i tight(const box3i& b) const { return test::bruteTightBox(g, b); }
  box3i cells(const box3i& b) const {
    const int B = g.brick;
    return box3i{vec3i{b.lo.x * B, b.lo.y * B, b.lo.z * B},
                 vec3i{std::min(b.hi.x * B, g.cellDims.x), std::min(b.hi.y * B, g.cellDims.y),
                       std::min(b.hi.z * B, g.cellDims.z)}};
  }
  void node(int index, box3i b) {
    box3i cb = cells(b);
    int64_t vol = cb.volume();
    int len[3] = {cb.hi.x - cb.lo.x, cb.hi.y - cb.lo.y, cb.hi.z - cb.lo.z};
    int axis = len[1] > len[0] ? 1 : 0;
    if (len[2] > len[axis]) axis = 2;
    bool halt = p.leaf == LeafCriterion::Shallow ? vol < rootVol / 10 : vol <= 512;
    int step = std::max(1, (8 + g.brick - 1) / g.brick);
    box3i bl{}, br{};
    bool found = false;
    if (!halt) {
      int64_t best = std::numeric_limits<int64_t>::max();
      for (int pl = b.lo[axis] + step; pl + step <= b.hi[axis]; pl += step) {
        box3i l = b, r = b;
        l.hi[axis] = r.lo[axis] = pl;
        l = tight(l);
        r = tight(r);
        int64_t c = cells(l).volume() + cells(r).volume();
        if (vol - c > vol / 1000 && c < best) {
          best = c;
          bl = l;
          br = r;
          found = true;
        }
      }
    }
    if (!found && !halt && p.leaf == LeafCriterion::Empty) {
      // Empty's rule, brute force: a leaf when <= 1/8 of its bricks are empty, else the plane of
      // largest between-class variance of the brick occupancy over all three axes.
      auto bricks = [&](const box3i& r) {
        int64_t o = 0;
        for (int z = r.lo.z; z < r.hi.z; ++z)
          for (int y = r.lo.y; y < r.hi.y; ++y)
            for (int x = r.lo.x; x < r.hi.x; ++x) o += g.at(x, y, z) ? 1 : 0;
        return o;
      };
      const int64_t n = int64_t(b.hi.x - b.lo.x) * (b.hi.y - b.lo.y) * (b.hi.z - b.lo.z), o = bricks(b);
      if (n > 1 && 8 * (n - o) > n) {
        double bestScore = 0;
        int ba = -1, bp = 0;
        for (int a = 0; a < 3; ++a)
          for (int pl = b.lo[a] + step; pl < b.hi[a]; pl += step) {
            box3i l = b;
            l.hi[a] = pl;
            const int64_t nl = int64_t(l.hi.x - l.lo.x) * (l.hi.y - l.lo.y) * (l.hi.z - l.lo.z), nr = n - nl;
            const int64_t ol = bricks(l), orr = o - ol;
            const double diff = double(ol * nr - orr * nl), score = diff * diff / (double(nl) * double(nr));
            if (score > bestScore) {
              bestScore = score;
              ba = a;
              bp = pl;
            }
          }
        if (ba < 0 && b.hi[axis] - b.lo[axis] >= 2) {
          ba = axis;
          bp = b.lo[axis] + (b.hi[axis] - b.lo[axis]) / 2;
        }
        if (ba >= 0) {
          box3i l = b, r = b;
          l.hi[ba] = r.lo[ba] = bp;
          bl = tight(l);
          br = tight(r);
          found = true;
        }
      }
    }
    if (!found && p.leaf != LeafCriterion::Empty && p.maxLeafSize > 0 && len[axis] > p.maxLeafSize &&
        b.hi[axis] - b.lo[axis] >= 2) {
      box3i l = b, r = b;
      l.hi[axis] = r.lo[axis] = b.lo[axis] + (b.hi[axis] - b.lo[axis]) / 2;
      bl = tight(l);
      br = tight(r);
      found = true;
    }
    if (!found) return;
    int c = int(t.nodes.size());
    t.nodes[size_t(index)].child = c;
    t.nodes.push_back(Node{cells(bl), -1, 0});
    t.nodes.push_back(Node{cells(br), -1, 0});
    node(c, bl);
    node(c + 1, br);
  }
  Tree build() {
    box3i root = tight(box3i{vec3i{0, 0, 0}, g.dims});
    if (root.empty()) return t;
    rootVol = cells(root).volume();
    t.nodes.push_back(Node{cells(root), -1, 0});
    node(0, root);
    computeTreeStats(t);
    return t;
  }
};

void expectSameTree(const Tree& a, const Tree& b, const std::string& what) {
  SCOPED_TRACE(what);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    ASSERT_TRUE(test::sameBox(a.nodes[i].box, b.nodes[i].box)) << "node " << i;
    ASSERT_EQ(a.nodes[i].child, b.nodes[i].child) << "node " << i;
  }
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.leaves, b.leaves);
}

std::vector<BuildParams> allCpuVariants(int brick = 8) {
  std::vector<BuildParams> v = {kd(LeafCriterion::Shallow, 0, brick), kd(LeafCriterion::Deep, 0, brick),
                                kd(LeafCriterion::Deep, 32, brick), kd(LeafCriterion::Deep, 128, brick),
                                kd(LeafCriterion::Shallow, 32, brick), kd(LeafCriterion::Empty, 0, brick),
                                kd(LeafCriterion::Empty, 32, brick)};
  BuildParams h = kd(LeafCriterion::Deep, 0, brick);
  h.builder = BuilderKind::Hybrid;
  v.push_back(h);
  BuildParams l = h;
  l.builder = BuilderKind::LBVHCPU;
  v.push_back(l);
  return v;
}

std::string describe(const BuildParams& p) {
  return std::string(builderName(p.builder)) +
         (p.leaf == LeafCriterion::Shallow ? ":shallow" : p.leaf == LeafCriterion::Empty ? ":empty" : ":deep") +
         ":mls" + std::to_string(p.maxLeafSize) + ":brick" + std::to_string(p.brick);
}

}  // namespace

TEST(Morton, InterleavesBitsAndMatches30BitCode) {
  EXPECT_EQ(mortonCode3(1, 0, 0), 1u);
  EXPECT_EQ(mortonCode3(0, 1, 0), 2u);
  EXPECT_EQ(mortonCode3(0, 0, 1), 4u);
  EXPECT_EQ(mortonCode3(3, 0, 0), 9u);
  EXPECT_EQ(mortonCode3(1023, 1023, 1023), (1u << 30) - 1);
  // The classic 30-bit expansion (10 bits per axis).
  auto expand10 = [](uint32_t v) {
    v = (v * 0x00010001u) & 0xFF0000FFu;
    v = (v * 0x00000101u) & 0x0F00F00Fu;
    v = (v * 0x00000011u) & 0xC30C30C3u;
    v = (v * 0x00000005u) & 0x49249249u;
    return v;
  };
  std::mt19937 rng(3);
  for (int i = 0; i < 1000; ++i) {
    uint32_t x = rng() % 1024, y = rng() % 1024, z = rng() % 1024;
    ASSERT_EQ(mortonCode3(x, y, z), uint64_t(expand10(x) | expand10(y) << 1 | expand10(z) << 2));
  }
}

TEST(Karras, EveryLeafAndInternalNodeReachedOnceAndRangesContiguous) {
  std::mt19937_64 rng(11);
  for (int n : {2, 3, 5, 64, 1000}) {
    std::set<uint64_t> s;
    while (int(s.size()) < n) s.insert(rng() >> 34);
    std::vector<uint64_t> codes(s.begin(), s.end());
    auto k = detail::karrasHierarchy(codes);
    ASSERT_EQ(int(k.size()), n - 1);
    // Walk from the root: the leaves reached left to right must be 0..n-1 in order.
    std::vector<int> order;
    std::vector<int> internalSeen(size_t(n - 1), 0);
    std::vector<std::pair<int, bool>> stack{{0, false}};
    while (!stack.empty()) {
      auto [i, leaf] = stack.back();
      stack.pop_back();
      if (leaf) {
        order.push_back(i);
        continue;
      }
      ++internalSeen[size_t(i)];
      stack.push_back({k[size_t(i)].right, k[size_t(i)].rightLeaf});
      stack.push_back({k[size_t(i)].left, k[size_t(i)].leftLeaf});
    }
    ASSERT_EQ(int(order.size()), n);
    for (int i = 0; i < n; ++i) ASSERT_EQ(order[size_t(i)], i);
    for (int c : internalSeen) ASSERT_EQ(c, 1);
  }
}

TEST(Builders, EmptyOccupancyGivesEmptyTree) {
  OccupancyGrid g = randomGrid(vec3i{40, 33, 17}, 8, 0.0, 1);
  for (const BuildParams& p : allCpuVariants()) {
    Tree t = buildTreeCPU(g, p);
    EXPECT_TRUE(t.nodes.empty()) << describe(p);
    EXPECT_EQ(t.height, 0);
    EXPECT_EQ(t.leaves, 0);
  }
}

TEST(Builders, SingleBrickIsOneLeaf) {
  OccupancyGrid g = randomGrid(vec3i{61, 40, 33}, 8, 0.0, 1);
  g.occ[size_t(g.index(7, 2, 4))] = 1;  // the clamped last brick along x: cells [56, 61)
  g.occupied = 1;
  for (const BuildParams& p : allCpuVariants()) {
    Tree t = buildTreeCPU(g, p);
    ASSERT_EQ(t.nodes.size(), 1u) << describe(p);
    EXPECT_EQ(t.height, 1);
    EXPECT_TRUE(test::sameBox(t.nodes[0].box, box3i{vec3i{56, 16, 32}, vec3i{61, 24, 33}})) << describe(p);
  }
}

TEST(Builders, InvariantsOnRandomOccupancy) {
  int round = 0;
  for (int brick : {8, 4, 2}) {
    for (double p : {0.01, 0.2, 0.7}) {
      for (bool clustered : {false, true}) {
        vec3i cd = brick == 8 ? vec3i{150, 97, 121} : vec3i{61, 50, 45};
        OccupancyGrid g = randomGrid(cd, brick, p, unsigned(100 + round++), clustered);
        for (BuildParams bp : allCpuVariants(brick)) {
          std::string what = describe(bp) + " p=" + std::to_string(p) + (clustered ? " clustered" : " uniform");
          Tree t = buildTreeCPU(g, bp);
          test::checkTreeInvariants(t, g, what);
          if (bp.builder == BuilderKind::LBVHCPU) {
            EXPECT_EQ(int64_t(t.nodes.size()), 2 * g.occupied - 1) << what;
            EXPECT_EQ(t.leaves, g.occupied) << what;
          } else {
            BuildParams q = bp;
            if (q.builder == BuilderKind::Hybrid) q.leaf = LeafCriterion::Shallow;
            expectSameTree(t, buildKdTreeSerial(g, q), what + " parallel vs serial");
            if (g.size() <= 20000) expectSameTree(t, RefKd{g, q}.build(), what + " vs brute force");
          }
        }
      }
    }
  }
}

TEST(Builders, InvariantsOnProceduralVolumesAndRandomTFs) {
  struct Case {
    const char* shape;
    int n;
  };
  const Case cases[] = {{"menger", 64}, {"nbody", 96}, {"shell", 48}, {"vessels", 96}, {"rm", 32}};
  unsigned seed = 1;
  for (const Case& c : cases) {
    Volume v = generateVolume(c.shape, vec3l{c.n, c.n, c.n});
    for (int brick : {8, 4}) {
      RangeGrid rg = computeRangeGrid(v, brick);
      for (int k = 0; k < 3; ++k) {
        TransferFunction tf = k == 0 ? TransferFunction::preset("ramp", 0, 255) : randomTF(seed++);
        OccupancyGrid g = classify(rg, tf);
        for (BuildParams bp : allCpuVariants(brick)) {
          std::string what = std::string(c.shape) + " " + describe(bp) + " tf " + std::to_string(k);
          test::checkTreeInvariants(buildTreeCPU(g, bp), g, what);
        }
      }
    }
  }
}

TEST(Builders, HybridAlwaysBuildsTheShallowTree) {
  Volume v = generateVolume("vessels", vec3l{96, 96, 96});
  OccupancyGrid g = classify(computeRangeGrid(v, 8), TransferFunction::preset("ramp", 0, 255));
  BuildParams h = kd(LeafCriterion::Deep);
  h.builder = BuilderKind::Hybrid;
  expectSameTree(buildTreeCPU(g, h), buildKdTree(g, kd(LeafCriterion::Shallow)), "hybrid == shallow");
  EXPECT_EQ(traversalFor(BuilderKind::Hybrid), TraversalKind::Hybrid);
}

TEST(Builders, ShallowDeepAndMlsDiffer) {
  // Vessels: the sweep finds splits, shallow stops early. Menger: no plane removes empty space
  // (the paper's shallow sponge is one node), only MLS splits it.
  {
    Volume v = generateVolume("vessels", vec3l{96, 96, 96});
    OccupancyGrid g = classify(computeRangeGrid(v, 4), TransferFunction::preset("ramp", 0, 255));
    Tree s = buildKdTree(g, kd(LeafCriterion::Shallow, 0, 4));
    Tree d = buildKdTree(g, kd(LeafCriterion::Deep, 0, 4));
    Tree m = buildKdTree(g, kd(LeafCriterion::Deep, 32, 4));
    EXPECT_LT(s.nodes.size(), d.nodes.size());
    EXPECT_LT(s.height, d.height);
    EXPECT_LE(d.nodes.size(), m.nodes.size());
    for (const Node& n : m.nodes)
      if (n.child < 0) {
        // MLS bounds leaf edges unless a leaf is a single brick along that axis.
        for (int a = 0; a < 3; ++a)
          EXPECT_TRUE(n.box.hi[a] - n.box.lo[a] <= 32 || n.box.hi[a] - n.box.lo[a] <= 4);
      }
  }
  {
    Volume v = generateVolume("menger", vec3l{96, 96, 96});
    OccupancyGrid g = classify(computeRangeGrid(v, 8), TransferFunction::preset("ramp", 0, 255));
    Tree s = buildKdTree(g, kd(LeafCriterion::Shallow));
    Tree d = buildKdTree(g, kd(LeafCriterion::Deep));
    Tree m32 = buildKdTree(g, kd(LeafCriterion::Deep, 32));
    Tree m128 = buildKdTree(g, kd(LeafCriterion::Deep, 64));
    EXPECT_LE(s.nodes.size(), d.nodes.size());
    EXPECT_LT(d.nodes.size(), m32.nodes.size());
    EXPECT_LT(m128.nodes.size(), m32.nodes.size());
  }
}

TEST(Builders, HeightBoundIsEnforcedNotOverrun) {
  // A diagonal line of bricks: every k-d split peels a little, the deepest kind of input here.
  OccupancyGrid g = randomGrid(vec3i{512, 512, 512}, 8, 0.0, 1);
  for (int i = 0; i < 64; ++i) g.occ[size_t(g.index(i, i, i))] = 1;
  g.occupied = 64;
  for (const BuildParams& bp : allCpuVariants()) {
    Tree t = buildTreeCPU(g, bp);
    EXPECT_LT(t.height, kMaxTreeHeight) << describe(bp);
    test::checkTreeInvariants(t, g, describe(bp));
  }
}

TEST(Builders, ImagesEqualNaive) {
  struct Case {
    const char* shape;
    int n;
    const char* tf;
  };
  const Case cases[] = {{"menger", 48, "ramp"}, {"nbody", 64, "ramp"}, {"vessels", 64, "band"},
                        {"shell", 40, "spike"}, {"vessels", 48, "spike"}, {"rm", 48, "spike"}};
  struct Cam {
    double az, el;
    bool persp;
  };
  const Cam cams[] = {{30, 20, false}, {-75, 50, false}, {200, -35, true}, {0, 0, true}};
  for (const Case& c : cases) {
    Volume v = generateVolume(c.shape, vec3l{c.n, c.n, c.n});
    double lo = 0, hi = 255;
    ASSERT_TRUE(v.scalarRange(lo, hi));
    TransferFunction tf = TransferFunction::preset(c.tf, lo, hi);
    for (const Cam& cam : cams) {
      Image ref = test::renderWith(v, tf, test::builder(BuilderKind::Naive), cam.az, cam.el, cam.persp, 64);
      ASSERT_GT(test::coverage(ref), 0.0) << c.shape << " " << c.tf << " renders nothing";
      std::vector<BuildParams> variants = allCpuVariants();
      variants.push_back(test::builder(BuilderKind::LBVH));  // the CPU backend builds it with the twin
      for (BuildParams bp : variants) {
        Image img = test::renderWith(v, tf, bp, cam.az, cam.el, cam.persp, 64);
        ImageDiff d = compareImages(ref, img);
        EXPECT_LE(d.maxAbs, 1.f / 255.f) << c.shape << " " << c.tf << " " << describe(bp) << " az " << cam.az
                                         << (cam.persp ? " persp" : " ortho");
      }
    }
  }
}

TEST(Builders, ImagesEqualNaiveWithRandomTFsAndSmallBricks) {
  Volume v = generateVolume("vessels", vec3l{64, 64, 64});
  for (unsigned s = 1; s <= 3; ++s) {
    TransferFunction tf = randomTF(1000 + s);
    Image ref = test::renderWith(v, tf, test::builder(BuilderKind::Naive), 40.0 * s, 15, s == 2, 64);
    for (BuildParams bp : allCpuVariants(s == 3 ? 2 : 4)) {
      Image img = test::renderWith(v, tf, bp, 40.0 * s, 15, s == 2, 64);
      EXPECT_LE(compareImages(ref, img).maxAbs, 1.f / 255.f) << describe(bp) << " tf " << s;
    }
  }
}

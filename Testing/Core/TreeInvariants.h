// Invariant checks shared by the builder tests: structure, coverage, disjointness, tightness.
#pragma once
#include "spaceskip/Classification.h"
#include "spaceskip/Tree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

namespace spaceskip::test {

/// Brute-force tight box (brick coordinates) of the occupied bricks inside `b`; empty at b.lo
/// when none is occupied. The reference for the SVT's shrink and the reference k-d builder.
inline box3i bruteTightBox(const OccupancyGrid& g, const box3i& b) {
  box3i t{vec3i{1 << 30, 1 << 30, 1 << 30}, vec3i{-1, -1, -1}};
  bool any = false;
  for (int z = b.lo.z; z < b.hi.z; ++z)
    for (int y = b.lo.y; y < b.hi.y; ++y)
      for (int x = b.lo.x; x < b.hi.x; ++x)
        if (g.at(x, y, z)) {
          any = true;
          t.lo = vec3i{std::min(t.lo.x, x), std::min(t.lo.y, y), std::min(t.lo.z, z)};
          t.hi = vec3i{std::max(t.hi.x, x + 1), std::max(t.hi.y, y + 1), std::max(t.hi.z, z + 1)};
        }
  return any ? t : box3i{b.lo, b.lo};
}

inline bool contains(const box3i& outer, const box3i& inner) {
  for (int a = 0; a < 3; ++a)
    if (inner.lo[a] < outer.lo[a] || inner.hi[a] > outer.hi[a]) return false;
  return true;
}
inline bool overlaps(const box3i& a, const box3i& b) {
  for (int k = 0; k < 3; ++k)
    if (a.hi[k] <= b.lo[k] || b.hi[k] <= a.lo[k]) return false;
  return true;
}
inline bool sameBox(const box3i& a, const box3i& b) {
  for (int k = 0; k < 3; ++k)
    if (a.lo[k] != b.lo[k] || a.hi[k] != b.hi[k]) return false;
  return true;
}
inline box3i unite(const box3i& a, const box3i& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  box3i u;
  for (int k = 0; k < 3; ++k) {
    u.lo[k] = std::min(a.lo[k], b.lo[k]);
    u.hi[k] = std::max(a.hi[k], b.hi[k]);
  }
  return u;
}

/// Checks, for any builder's tree over `occ`: a binary tree rooted at 0 with adjacent children;
/// stats match; height < kMaxTreeHeight; children separated by an axis-aligned plane; every
/// occupied brick lies in exactly one leaf; leaves pairwise disjoint; every leaf box is exactly
/// the union of the occupied bricks inside it (tight) and every inner box the union of its
/// children's, so each node box tightly bounds the occupied bricks below it.
inline void checkTreeInvariants(const Tree& t, const OccupancyGrid& occ, const std::string& what) {
  SCOPED_TRACE(what);
  if (occ.occupied == 0) {
    EXPECT_TRUE(t.nodes.empty());
    return;
  }
  ASSERT_FALSE(t.nodes.empty());
  const int n = int(t.nodes.size());
  std::vector<int> parentCount(size_t(n), 0);
  std::vector<int> leaves;
  for (int i = 0; i < n; ++i) {
    const Node& nd = t.nodes[size_t(i)];
    ASSERT_FALSE(nd.box.empty()) << "node " << i;
    for (int a = 0; a < 3; ++a) {
      ASSERT_GE(nd.box.lo[a], 0);
      ASSERT_LE(nd.box.hi[a], occ.cellDims[a]);
    }
    if (nd.child < 0) {
      leaves.push_back(i);
      continue;
    }
    ASSERT_GT(nd.child, 0);
    ASSERT_LT(nd.child + 1, n);
    ++parentCount[size_t(nd.child)];
    ++parentCount[size_t(nd.child + 1)];
    const box3i& a = t.nodes[size_t(nd.child)].box;
    const box3i& b = t.nodes[size_t(nd.child + 1)].box;
    bool separated = false;
    for (int k = 0; k < 3; ++k) separated |= a.hi[k] <= b.lo[k] || b.hi[k] <= a.lo[k];
    EXPECT_TRUE(separated) << "children of node " << i << " not separated by a plane";
    EXPECT_TRUE(sameBox(nd.box, test::unite(a, b))) << "inner node " << i << " is not the union of its children";
  }
  EXPECT_EQ(parentCount[0], 0);
  for (int i = 1; i < n; ++i) ASSERT_EQ(parentCount[size_t(i)], 1) << "node " << i << " not referenced once";
  {  // and every node is reachable from the root (no detached cycles)
    std::vector<int> stack{0};
    int reached = 0;
    while (!stack.empty() && reached <= n) {
      const Node& nd = t.nodes[size_t(stack.back())];
      stack.pop_back();
      ++reached;
      if (nd.child >= 0) {
        stack.push_back(nd.child);
        stack.push_back(nd.child + 1);
      }
    }
    ASSERT_EQ(reached, n);
  }
  Tree copy = t;
  computeTreeStats(copy);
  EXPECT_EQ(copy.height, t.height);
  EXPECT_EQ(copy.leaves, t.leaves);
  EXPECT_EQ(int64_t(leaves.size()), t.leaves);
  EXPECT_LT(t.height, kMaxTreeHeight);

  // Leaves: tight and covering; bricks in exactly one leaf.
  std::vector<box3i> tight(leaves.size());
  std::vector<int> hits(size_t(occ.size()), 0);
  for (size_t li = 0; li < leaves.size(); ++li) {
    const box3i& lb = t.nodes[size_t(leaves[li])].box;
    box3i u{};
    u.lo = u.hi = vec3i{0, 0, 0};
    for (int z = lb.lo.z / occ.brick; z < occ.dims.z && z * occ.brick < lb.hi.z; ++z)
      for (int y = lb.lo.y / occ.brick; y < occ.dims.y && y * occ.brick < lb.hi.y; ++y)
        for (int x = lb.lo.x / occ.brick; x < occ.dims.x && x * occ.brick < lb.hi.x; ++x) {
          if (!occ.at(x, y, z)) continue;
          box3i bb = occ.brickBox(x, y, z);
          if (!overlaps(bb, lb)) continue;
          EXPECT_TRUE(contains(lb, bb)) << "leaf " << leaves[li] << " cuts an occupied brick";
          ++hits[size_t(occ.index(x, y, z))];
          u = test::unite(u, bb);
        }
    EXPECT_TRUE(sameBox(u, lb)) << "leaf " << leaves[li] << " is not tight";
  }
  for (int z = 0; z < occ.dims.z; ++z)
    for (int y = 0; y < occ.dims.y; ++y)
      for (int x = 0; x < occ.dims.x; ++x)
        if (occ.at(x, y, z))
          ASSERT_EQ(hits[size_t(occ.index(x, y, z))], 1) << "occupied brick " << x << "," << y << "," << z;
  if (leaves.size() <= 4000)
    for (size_t i = 0; i < leaves.size(); ++i)
      for (size_t j = i + 1; j < leaves.size(); ++j)
        ASSERT_FALSE(overlaps(t.nodes[size_t(leaves[i])].box, t.nodes[size_t(leaves[j])].box))
            << "leaves " << leaves[i] << " and " << leaves[j] << " overlap";
}

}  // namespace spaceskip::test

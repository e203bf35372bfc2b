// LBVH on the CPU (paper 3.1; Karras 2012): occupied bricks, Morton order, radix-tree hierarchy,
// bottom-up boxes. The oneTBB twin of the CUDA LBVH (cuda/LbvhBuilder.cu): both run karrasNode and
// emit this exact tree.
#pragma once
#include "Classification.h"
#include "Macros.h"
#include "Math.h"
#include "Tree.h"
#include "Types.h"

#include <cstdint>
#include <vector>

namespace spaceskip {

/// Morton code of brick (x,y,z): bit i of x, y, z goes to bit 3i, 3i+1, 3i+2. For coordinates
/// below 1024 this is the paper's 30-bit code; up to 21 bits per axis are kept, so grids of up
/// to 2^21 bricks per axis order the same way (the high bits are zero for smaller grids).
uint64_t mortonCode3(uint32_t x, uint32_t y, uint32_t z);

/// Builds the LBVH. With n occupied bricks (n >= 1) the tree has 2n-1 nodes, laid out
/// deterministically so a GPU twin can emit the same array in parallel:
///  1. the occupied bricks are sorted by Morton code (codes are unique: one per brick);
///     leaf j of Karras is the j-th brick in that order, internal node i (0 <= i < n-1) is
///     Karras' internal node i (Karras 2012, sec. 4: node 0 is the root; node i's range
///     [first, last] holds i at one end; split gamma = last index with the same prefix as first);
///  2. output node 0 is Karras' root; internal node i's children are written at output
///     2i+1 (left: leaf/internal gamma) and 2i+2 (right: leaf/internal gamma+1), so
///     child = 2i+1 and children are adjacent (every non-root node is the child of exactly one
///     internal node, so positions 1..2n-2 are each filled once);
///  3. a leaf's box is the cell-space box of its brick (clamped to the volume): at brick
///     granularity that is the tight box of its occupied cells; an inner box is the union of its
///     children's boxes (bottom-up, Karras' atomic-flag scheme).
/// n == 1: one leaf node. n == 0: no nodes. Morton splits put children on either side of an
/// axis-aligned plane. Throws std::runtime_error when the height would reach kMaxTreeHeight.
Tree buildLbvh(const OccupancyGrid& occ);

namespace detail {
/// Karras 2012 for sorted unique codes: per internal node i the children in Karras' numbering
/// (leaf indices flagged by isLeaf).
struct KarrasNode {
  int left, right;
  bool leftLeaf, rightLeaf;
};

/// Karras 2012, sec. 4: length of the common prefix of keys i and j; -1 outside [0, n).
SS_FUNC int karrasDelta(const uint64_t* keys, int n, int i, int j) {
  if (j < 0 || j >= n) return -1;
  return clz64(keys[i] ^ keys[j]);  // keys are unique (one per brick)
}

/// Karras 2012, sec. 4 (Fig. 4): internal node i (0 <= i < n-1) of the radix tree over n sorted
/// unique keys: its range [i, j] (or [j, i]) and split gamma, the last position sharing more than
/// the range's common prefix with i. One call per node on both twins (oneTBB loop, CUDA thread).
/// 32-bit positions: n <= 2^30 keeps i + lmax * d in range.
SS_FUNC KarrasNode karrasNode(const uint64_t* keys, int n, int i) {
  // Direction of the range: towards the neighbour sharing the longer prefix (never equal for
  // unique keys).
  const int d = karrasDelta(keys, n, i, i + 1) - karrasDelta(keys, n, i, i - 1) > 0 ? 1 : -1;
  // Upper bound on the range's length, then its other end j by binary search.
  const int dmin = karrasDelta(keys, n, i, i - d);
  int lmax = 2;
  while (karrasDelta(keys, n, i, i + lmax * d) > dmin) lmax *= 2;
  int l = 0;
  for (int t = lmax / 2; t >= 1; t /= 2)
    if (karrasDelta(keys, n, i, i + (l + t) * d) > dmin) l += t;
  const int j = i + l * d;
  // Split: binary search with t = ceil(l / 2), ceil(l / 4), ... down to 1.
  const int dnode = karrasDelta(keys, n, i, j);
  int s = 0, t = l;
  do {
    t = (t + 1) >> 1;
    if (karrasDelta(keys, n, i, i + (s + t) * d) > dnode) s += t;
  } while (t > 1);
  const int gamma = i + s * d + (d < 0 ? -1 : 0);
  return KarrasNode{gamma, gamma + 1, (i < j ? i : j) == gamma, (i > j ? i : j) == gamma + 1};
}

/// karrasNode for every internal node (oneTBB). Exposed for tests.
std::vector<KarrasNode> karrasHierarchy(const std::vector<uint64_t>& sortedCodes);
}  // namespace detail

namespace cuda {
struct BuildContext;
/// The registry's device builder (cuda/LbvhBuilder.cu): paper 3.1 on the GPU.
void buildLbvh(BuildContext& ctx, const BuildParams& p);
}  // namespace cuda

}  // namespace spaceskip

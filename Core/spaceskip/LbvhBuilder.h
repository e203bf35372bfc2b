// LBVH on the CPU (paper 3.1; Karras 2012): occupied bricks, Morton order, radix-tree hierarchy,
// bottom-up boxes. The oneTBB reference twin of the CUDA LBVH: both must emit this exact tree.
#pragma once
#include "Classification.h"
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
/// (leaf indices flagged by isLeaf). Exposed for tests and the CUDA twin's cross-check.
struct KarrasNode {
  int left, right;
  bool leftLeaf, rightLeaf;
};
std::vector<KarrasNode> karrasHierarchy(const std::vector<uint64_t>& sortedCodes);
}  // namespace detail

namespace cuda {
struct BuildContext;
/// The registry's device builder (cuda/LbvhBuilder.cu): paper 3.1 on the GPU.
void buildLbvh(BuildContext& ctx, const BuildParams& p);
}  // namespace cuda

}  // namespace spaceskip

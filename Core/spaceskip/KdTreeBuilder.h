// KdTreeCPU (paper 3.2.1; Vidal et al. 2008): top-down k-d tree over the brick occupancy with
// tight node boxes from a summed volume table, built with oneTBB tasks over the split rule the GPU
// builders share (KdTreeSplit.h).
#pragma once
#include "Classification.h"
#include "Types.h"
#include "Tree.h"

#include <cstdint>

namespace spaceskip {

/// Subtrees whose node box holds at least this many bricks are split in their own oneTBB task;
/// smaller ones recurse serially in the task that reached them.
constexpr int64_t kKdTreeSerialCutoffBricks = 4096;

/// Builds the k-d tree:
///  - the root box is the tight box of all occupied bricks (empty occupancy: no nodes);
///  - candidate planes run along the node's longest axis at every brick boundary for bricks of
///    8 cells or more, else every ceil(8/brick) bricks (every 8 cells for brick 1, 2, 4), placed
///    relative to the node's low face as in Vidal's code. KdTreeCPU always sweeps and ignores
///    BuildParams::bins: it runs the GPU builders' rule with bins = 0 (KdTreeSplit.h), so those
///    give this very tree (TestKdSweep.cpp, TestCuda.cpp check it);
///  - cost = volume of the tight left box + volume of the tight right box (cells); a plane is
///    rejected when it removes <= 1/1000 of the node volume as empty space; least cost wins;
///  - halting: Shallow = node volume < 10% of the root volume, Deep = node volume <= 8^3 cells,
///    or no acceptable plane;
///  - MLS (p.maxLeafSize > 0): a node that would become a leaf with its longest edge > MLS cells
///    is split in the middle of that axis (snapped to a brick boundary) and recursion continues.
/// Every node box is tight around the occupied bricks below it (cell coordinates, clamped to
/// the volume); children are separated by the split plane. Node order is deterministic and the
/// same for the parallel and the serial build: root at 0, then the children pair of each inner
/// node appended when that node is reached in depth-first (left before right) order.
/// Throws std::runtime_error when the tree would reach kMaxTreeHeight.
Tree buildKdTree(const OccupancyGrid& occ, const BuildParams& p);

/// The same build with no task parallelism: the reference the tests compare against.
Tree buildKdTreeSerial(const OccupancyGrid& occ, const BuildParams& p);

namespace cuda {
struct BuildContext;
/// The registry's device builders (cuda/KdTreeBuilder.cu): paper 3.2.2 and the level-parallel one.
void buildKdTreeGpu(BuildContext& ctx, const BuildParams& p);
void buildKdTreeGpuFast(BuildContext& ctx, const BuildParams& p);
}  // namespace cuda

}  // namespace spaceskip

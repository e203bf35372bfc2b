// GPU k-d trees over the brick occupancy (the split rule of spaceskip/KdTreeSplit.h, as KdTreeCPU):
//  - KdTreeGPU: the paper's method (3.2.2): Morton-ordered brick boxes, one reduction per
//    candidate child over the region's Morton range, recursion driven by the host.
//  - KdTreeGPUFast (ours): breadth-first, one kernel pass per level for all nodes, tight boxes
//    and counts from a 3-D summed volume table over the bricks.
// bins == 0 (the sweep) builds KdTreeCPU's tree: every brick boundary is a candidate. KdTreeGPUFast
// evaluates a node's candidates with one warp; KdTreeGPU runs them one by one on the host (two
// reductions and two synchronizations per candidate, up to 255 candidates per node at 2048^3), so
// it accepts bins 0 but is slow with it: it is there for tests, not for benchmarks.
#pragma once
#include "DeviceTree.cuh"
#include "spaceskip/KdTreeSplit.h"
#include "spaceskip/SummedVolumeTable.h"
#include "spaceskip/Types.h"

namespace spaceskip::cuda {

struct KdParams {
  LeafCriterion leaf = LeafCriterion::Deep;
  int maxLeafSize = 0;
  int bins = 4;  ///< >= 2: bins - 1 planes per node; 0: sweep (KdTreeSplit.h); 1 or < 0: std::invalid_argument
};

struct KdTreeGpuWorkspace {
  DeviceBuffer<box3i> mortonBoxes;  ///< brick boxes in Morton order, padded to a 2^k cube
  DeviceBuffer<box3i> result;
  DeviceBuffer<int> count;  ///< leaf criterion Empty's brick counts
  TempStorage temp, countTemp;
  box3i* h_result = nullptr;  ///< pinned
  ~KdTreeGpuWorkspace();
};

struct KdTreeGpuFastWorkspace {
  DeviceBuffer<uint32_t> svt;  ///< (dims+1)^3 inclusive prefix counts (read through SvtView)
  DeviceBuffer<box3i> levelBoxes[2];
  DeviceBuffer<box3i> childBoxes;
  DeviceBuffer<int> splitFlags, splitOffsets;
  DeviceBuffer<int> counter;
  TempStorage temp;
  int* h_counter = nullptr;  ///< pinned
  ~KdTreeGpuFastWorkspace();
};

/// The paper's KdTreeGPU. Synchronizes `stream` (it must: the recursion runs on the host).
void buildKdTreeGpu(const BrickGridView& g, const KdParams& p, KdTreeGpuWorkspace& ws, DeviceTree& out,
                    cudaStream_t stream);

/// KdTreeGPUFast. Synchronizes `stream` once per tree level (to size the next level's launch).
void buildKdTreeGpuFast(const BrickGridView& g, const KdParams& p, KdTreeGpuFastWorkspace& ws, DeviceTree& out,
                        cudaStream_t stream);

}  // namespace spaceskip::cuda

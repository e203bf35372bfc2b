// LBVH over occupied bricks (paper 3.1; Karras 2012): CUB select + radix sort on Morton codes,
// Karras hierarchy, bottom-up tight boxes, remapped to Core's flat layout (root 0, children adjacent).
#pragma once
#include "DeviceTree.cuh"

namespace spaceskip::cuda {

/// Device scratch kept between builds so a rebuild allocates nothing.
struct LbvhWorkspace {
  DeviceBuffer<int> brickIds, brickIdsSorted;
  DeviceBuffer<uint64_t> codes, codesSorted;
  DeviceBuffer<int> parent, outIndex, arrivals, heights;
  DeviceBuffer<int> numSelected;
  TempStorage temp;
};

/// Builds the LBVH of `g`'s occupied bricks into `out`. Leaves are single bricks with their
/// clamped cell boxes; inner boxes are unions (tight). Synchronizes `stream` before returning.
void buildLbvh(const BrickGridView& g, LbvhWorkspace& ws, DeviceTree& out, cudaStream_t stream);

}  // namespace spaceskip::cuda

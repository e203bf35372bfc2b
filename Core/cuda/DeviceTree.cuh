// The brick grid the GPU builders read and the device-side tree they emit (Core's flat Node layout).
#pragma once
#include "CudaCommon.cuh"
#include "spaceskip/Tree.h"

#include <cstdint>

namespace spaceskip::cuda {

/// Brick occupancy on the device: one byte per brick, x fastest (OccupancyGrid's layout).
struct BrickGridView {
  const uint8_t* d_occ;
  vec3i dims;      ///< bricks per axis
  int brick;       ///< cells per brick edge
  vec3i cellDims;  ///< cells per axis (brick boxes are clamped to it)
  int64_t occupied;

  int64_t size() const { return int64_t(dims.x) * dims.y * dims.z; }
};

/// A tree in device memory: node 0 is the root, children adjacent, leaves have child < 0.
struct DeviceTree {
  DeviceBuffer<Node> nodes;
  int numNodes = 0;
  int height = 0;
  int64_t leaves = 0;

  /// Back to the empty tree (the nodes' storage is kept for the next build).
  void clear() {
    numNodes = 0;
    height = 0;
    leaves = 0;
  }
};

}  // namespace spaceskip::cuda

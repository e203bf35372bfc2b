// Conservative classification: per-brick value ranges (once per volume) and per-brick
// occupancy (once per opacity edit). See DESIGN.md "Conservative classification".
#pragma once
#include "TransferFunction.h"
#include "Volume.h"

#include <cstdint>
#include <vector>

namespace spaceskip {

/// Min/max of the voxels a trilinear sample inside each brick of `brick`^3 cells can touch:
/// cells [b*B, (b+1)*B) use voxels [b*B, (b+1)*B] (the +1 halo). NaN voxels are skipped
/// (a sample touching one is NaN, which the integrator treats as transparent).
struct RangeGrid {
  int brick = 8;
  vec3i cellDims{0, 0, 0};
  vec3i dims{0, 0, 0};  ///< bricks per axis
  std::vector<float> vmin, vmax;

  int64_t size() const { return int64_t(dims.x) * dims.y * dims.z; }
  int64_t index(int x, int y, int z) const { return x + int64_t(dims.x) * (y + int64_t(dims.y) * z); }
  /// Cell-space box of brick (x,y,z), clamped to the volume.
  box3i brickBox(int x, int y, int z) const;
};

/// Parallel (oneTBB) computation of the range grid.
RangeGrid computeRangeGrid(const Volume& v, int brick = 8);

/// One byte per brick: 1 when some sample inside can have opacity > 0.
struct OccupancyGrid {
  int brick = 8;
  vec3i cellDims{0, 0, 0};
  vec3i dims{0, 0, 0};
  std::vector<uint8_t> occ;
  int64_t occupied = 0;

  int64_t size() const { return int64_t(dims.x) * dims.y * dims.z; }
  int64_t index(int x, int y, int z) const { return x + int64_t(dims.x) * (y + int64_t(dims.y) * z); }
  bool at(int x, int y, int z) const { return occ[size_t(index(x, y, z))] != 0; }
  box3i brickBox(int x, int y, int z) const;
  double occupancy() const { return size() ? double(occupied) / double(size()) : 0.0; }
};

/// Re-classifies bricks (never voxels) against the TF's opacity (oneTBB).
OccupancyGrid classify(const RangeGrid& ranges, const TransferFunction& tf);

}  // namespace spaceskip

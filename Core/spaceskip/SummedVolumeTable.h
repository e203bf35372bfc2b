// Summed volume table (3-D prefix sums) over a brick occupancy grid: O(1) occupied-brick counts
// in any box and tight-box shrinking by binary search per axis (Vidal et al. 2008).
#pragma once
#include "Classification.h"

#include <cstdint>
#include <memory>

namespace spaceskip {

/// Boxes here are in BRICK coordinates, half-open, like OccupancyGrid's (x,y,z) indices.
/// The table is global (one prefix sum over the whole grid, built with two parallel passes)
/// rather than one per 32^3 brick as in the paper: a query is then 8 lookups wherever the box lies.
class SummedVolumeTable {
 public:
  SummedVolumeTable() = default;  ///< empty table (dims 0): every count is 0
  /// Builds the table in parallel (oneTBB). Throws std::length_error when the grid has 2^32 or
  /// more bricks (counts are 32-bit).
  explicit SummedVolumeTable(const OccupancyGrid& occ);

  vec3i dims() const { return dims_; }
  /// Occupied bricks in `b` (brick coordinates; clipped to the grid).
  int64_t count(const box3i& b) const;
  /// The smallest box inside `b` holding all its occupied bricks; an empty (lo == hi) box at
  /// b.lo when `b` holds none. Six binary searches of O(log n) count queries each.
  box3i shrink(const box3i& b) const;

 private:
  // Inclusive prefix sums with a zero border at index 0 on each axis: (dims+1)^3 entries.
  uint32_t at(int x, int y, int z) const {
    return sums_[size_t(x) + size_t(stride_.x) * (size_t(y) + size_t(stride_.y) * size_t(z))];
  }
  vec3i dims_{0, 0, 0};
  vec3i stride_{1, 1, 1};
  std::unique_ptr<uint32_t[]> sums_;
};

}  // namespace spaceskip

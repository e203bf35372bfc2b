// Summed volume table (3-D prefix sums) over a brick occupancy grid: O(1) occupied-brick counts
// in any box and tight-box shrinking by binary search per axis (Vidal et al. 2008). The queries
// (SvtView) are written once for the oneTBB table here and KdTreeGPUFast's device table.
#pragma once
#include "Classification.h"
#include "Math.h"

#include <cstdint>
#include <memory>

namespace spaceskip {

/// A summed volume table in host or device memory: sums[x,y,z] = occupied bricks in
/// [0,x) x [0,y) x [0,z), (dims+1)^3 entries, x fastest (zero faces at index 0). Plain data, so
/// a kernel takes it by value.
struct SvtView {
  vec3i dims;      ///< bricks per axis
  int brick;       ///< cells per brick edge
  vec3i cellDims;  ///< cells per axis (brick boxes are clamped to it)
  const uint32_t* sums;

  SS_FUNC uint32_t at(int x, int y, int z) const {
    return sums[x + int64_t(dims.x + 1) * (y + int64_t(dims.y + 1) * z)];
  }
  /// Occupied bricks in [lo, hi), inside [0, dims]: 8 lookups, inclusion-exclusion (unsigned
  /// wrap-around cancels exactly).
  SS_FUNC uint32_t count(vec3i lo, vec3i hi) const {
    return at(hi.x, hi.y, hi.z) - at(lo.x, hi.y, hi.z) - at(hi.x, lo.y, hi.z) - at(hi.x, hi.y, lo.z) +
           at(lo.x, lo.y, hi.z) + at(lo.x, hi.y, lo.z) + at(hi.x, lo.y, lo.z) - at(lo.x, lo.y, lo.z);
  }
  /// Shrinks [lo, hi) (inside the grid, holding an occupied brick) to the tight box of its
  /// occupied bricks: per axis, binary searches for the first and the last slab holding one,
  /// O(log n) counts per face; later axes search inside the faces already found.
  SS_FUNC void shrink(vec3i& lo, vec3i& hi) const {
    for (int a = 0; a < 3; ++a) {
      int L = lo[a], H = hi[a] - 1;
      while (L < H) {  // first slab (from lo) with an occupied brick
        const int m = (L + H) / 2;
        vec3i h2 = hi;
        h2[a] = m + 1;
        if (count(lo, h2) > 0) H = m;
        else L = m + 1;
      }
      const int newLo = L;
      H = hi[a] - 1;
      while (L < H) {  // last slab (towards hi) with an occupied brick
        const int m = (L + H + 1) / 2;
        vec3i l2 = lo;
        l2[a] = m;
        if (count(l2, hi) > 0) L = m;
        else H = m - 1;
      }
      lo[a] = newLo;
      hi[a] = L + 1;
    }
  }
  /// Tight cell box of the occupied bricks in a cell region on the brick raster (inside the
  /// volume); an empty box at region.lo when none. The `tight` of decideKdSplit (KdTreeSplit.h).
  SS_FUNC box3i operator()(const box3i& region) const {
    if (region.empty()) return box3i{region.lo, region.lo};
    box3i b = cellBrickBox(region, brick);
    if (count(b.lo, b.hi) == 0) return box3i{region.lo, region.lo};
    shrink(b.lo, b.hi);
    return brickCellBox(b, brick, cellDims);
  }
};

/// Boxes here are in BRICK coordinates, half-open, like OccupancyGrid's (x,y,z) indices.
/// The table is global (one prefix sum over the whole grid, built with two parallel passes)
/// rather than one per 32^3 brick as in the paper: a query is then 8 lookups wherever the box lies.
class SummedVolumeTable {
 public:
  SummedVolumeTable() = default;  ///< empty table (dims 0): every count is 0
  /// Builds the table in parallel (oneTBB). Throws std::length_error when the grid has 2^32 or
  /// more bricks (counts are 32-bit).
  explicit SummedVolumeTable(const OccupancyGrid& occ);

  vec3i dims() const { return view_.dims; }
  /// The shared queries over this table (valid while the table lives).
  const SvtView& view() const { return view_; }
  /// Occupied bricks in `b` (brick coordinates; clipped to the grid).
  int64_t count(const box3i& b) const;
  /// The smallest box inside `b` holding all its occupied bricks; an empty (lo == hi) box at
  /// b.lo when `b` holds none. Six binary searches of O(log n) count queries each.
  box3i shrink(const box3i& b) const;

 private:
  box3i clip(const box3i& b) const;
  SvtView view_{vec3i{0, 0, 0}, 1, vec3i{0, 0, 0}, nullptr};
  std::unique_ptr<uint32_t[]> sums_;
};

}  // namespace spaceskip

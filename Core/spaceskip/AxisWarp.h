// A rectilinear grid drawn through its coordinates. The engine draws the grid as a uniform image
// over the grid's bounds with the grid's point counts (the "virtual lattice": first coordinate at
// virtual index 0, the last at n - 1, spacing (last - first) / (n - 1)), whose sampler reads the
// grid through its coordinates: virtual index u on an axis is the grid position c = u in virtual
// units, which lies in grid cell i (c[i] <= u < c[i + 1]) at grid index i + (u - c[i]) / (c[i + 1]
// - c[i]). A sample is then trilinear in the grid's own cell, as VTK interpolates a rectilinear
// grid's point data; nothing is resampled.
//
// Everything the engine derives from the volume in index space (rays, gradients, opacity unit
// distance, cropping, clipping) is the virtual lattice's, an affine image of world space. Skipping
// stays lossless through the brick value ranges: a virtual brick's range is the union of the
// ranges of the grid's bricks whose cells its samples read (remapRangeGrid, Classification.h), so
// every rule that bounds a brick's samples by its range (occupancy, the 2-D gradient bound, the
// value-range marches) holds unchanged. What reads voxels by index directly (sub-brick masks,
// label sets, sparse residency, the CPU's SIMD packets, the texture path) is not used for a warped
// volume.
#pragma once
#include "Macros.h"
#include "Math.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace spaceskip {

/// What a sampler reads of the warp (device or host pointers): per axis the n coordinates in
/// virtual units (c[0] = 0, c[n - 1] = n - 1, strictly increasing) and, for each virtual index j
/// (0 .. n - 1), the last grid cell i <= n - 2 with c[i] <= j (where a binary search starts).
/// Null pointers: no warp (a uniform image).
struct AxisWarpView {
  const float* c[3] = {nullptr, nullptr, nullptr};
  const int32_t* cell[3] = {nullptr, nullptr, nullptr};
  int32_t n[3] = {0, 0, 0};

  SS_FUNC bool on() const { return c[0] != nullptr; }

  /// Virtual index u -> grid index on one axis. Outside (0, n - 1) and NaN: u itself (the
  /// sampler clamps there, as for an image). Exact (u itself) where the grid is uniform.
  SS_FUNC static float axis(float u, const float* c, const int32_t* cell, int32_t n) {
    if (!(u > 0.f) || !(u < float(n - 1))) return u;
    const int32_t j = int32_t(u);
    int32_t lo = cell[j], hi = cell[j + 1];  // j <= n - 2: u < n - 1
    while (lo < hi) {  // the last i in [lo, hi] with c[i] <= u
      const int32_t mid = (lo + hi + 1) >> 1;
      if (c[mid] <= u) {
        lo = mid;
      } else {
        hi = mid - 1;
      }
    }
    return float(lo) + (u - c[lo]) / (c[lo + 1] - c[lo]);
  }
  SS_FUNC vec3f apply(vec3f p) const {
    return vec3f{axis(p.x, c[0], cell[0], n[0]), axis(p.y, c[1], cell[1], n[1]), axis(p.z, c[2], cell[2], n[2])};
  }
};

/// The host's warp: the tables AxisWarpView reads, and the grid's coordinates.
struct AxisWarp {
  std::vector<float> c[3];
  std::vector<int32_t> cell[3];
  /// Per axis: first coordinate, last coordinate (descending axes: last < first).
  double first[3] = {0, 0, 0}, last[3] = {0, 0, 0};

  /// From a grid's coordinates (n[a] values per axis, each axis strictly increasing or strictly
  /// decreasing, finite; an axis of one point is uniform). Throws std::runtime_error naming the
  /// axis and index otherwise.
  static std::shared_ptr<AxisWarp> fromCoordinates(const double* const coords[3], const int64_t n[3]);

  int64_t points(int a) const { return int64_t(c[a].size()); }
  /// The virtual lattice's spacing on axis a (> 0; 1 for an axis of one point).
  double spacing(int a) const;
  /// The grid cells [i0, i1] (inclusive, clamped to the grid's cells) that samples at virtual
  /// positions [u0, u1] read, widened by one cell each side (float rounding at a brick face).
  void cellSpan(int a, int64_t u0, int64_t u1, int64_t& i0, int64_t& i1) const;
  /// Pointers into the host tables.
  AxisWarpView view() const;
};

}  // namespace spaceskip

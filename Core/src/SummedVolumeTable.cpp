// Summed volume table: parallel construction (per-slice 2-D sums, then along z) and box queries.
#include "spaceskip/SummedVolumeTable.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <stdexcept>

namespace spaceskip {

SummedVolumeTable::SummedVolumeTable(const OccupancyGrid& occ) : dims_(occ.dims) {
  if (occ.size() >= (int64_t(1) << 32)) throw std::length_error("summed volume table: 2^32 or more bricks");
  const int nx = dims_.x, ny = dims_.y, nz = dims_.z;
  stride_ = vec3i{nx + 1, ny + 1, nz + 1};
  const size_t sx = size_t(stride_.x), sxy = sx * size_t(stride_.y);
  // No serial zero fill: the zero borders are written by the parallel passes (first touch in
  // parallel too), every other entry by pass 1.
  sums_.reset(new uint32_t[sxy * size_t(stride_.z)]);  // default-initialised: no zero fill
  // Pass 1: a 2-D summed area table per z slice (x running sum plus the row below); slices are
  // independent and a slice stays in cache while it is summed. Slice 0 is the zero border.
  tbb::parallel_for(tbb::blocked_range<int>(-1, nz), [&](const tbb::blocked_range<int>& r) {
    for (int z = r.begin(); z != r.end(); ++z) {
      uint32_t* slice = sums_.get() + sxy * size_t(z + 1);
      if (z < 0) {
        std::fill(slice, slice + sxy, 0u);
        continue;
      }
      std::fill(slice, slice + sx, 0u);  // row y = 0
      for (int y = 0; y < ny; ++y) {
        const uint8_t* src = occ.occ.data() + occ.index(0, y, z);
        uint32_t* cur = slice + sx * size_t(y + 1);
        const uint32_t* prev = cur - sx;
        uint32_t s = 0;
        cur[0] = 0;
        for (int x = 0; x < nx; ++x) {
          s += src[x] ? 1u : 0u;
          cur[x + 1] = s + prev[x + 1];
        }
      }
    }
  });
  // Pass 2 (z): add the previous slice, per y row (rows are independent along z).
  tbb::parallel_for(tbb::blocked_range<int>(1, ny + 1), [&](const tbb::blocked_range<int>& r) {
    for (int y = r.begin(); y != r.end(); ++y)
      for (int z = 2; z <= nz; ++z) {
        uint32_t* cur = sums_.get() + sxy * size_t(z) + sx * size_t(y);
        const uint32_t* prev = cur - sxy;
        for (int x = 1; x <= nx; ++x) cur[x] += prev[x];
      }
  });
}

int64_t SummedVolumeTable::count(const box3i& in) const {
  const int x0 = std::max(in.lo.x, 0), y0 = std::max(in.lo.y, 0), z0 = std::max(in.lo.z, 0);
  const int x1 = std::min(in.hi.x, dims_.x), y1 = std::min(in.hi.y, dims_.y), z1 = std::min(in.hi.z, dims_.z);
  if (x1 <= x0 || y1 <= y0 || z1 <= z0) return 0;
  // Inclusion-exclusion over the 8 corners; unsigned wrap-around cancels exactly.
  uint32_t c = at(x1, y1, z1) - at(x0, y1, z1) - at(x1, y0, z1) - at(x1, y1, z0) + at(x0, y0, z1) +
               at(x0, y1, z0) + at(x1, y0, z0) - at(x0, y0, z0);
  return int64_t(c);
}

box3i SummedVolumeTable::shrink(const box3i& in) const {
  box3i b;
  for (int a = 0; a < 3; ++a) {
    b.lo[a] = std::max(in.lo[a], 0);
    b.hi[a] = std::min(in.hi[a], dims_[a]);
  }
  const int64_t total = count(b);
  if (total == 0) return box3i{b.lo, b.lo};
  box3i out = b;
  // Each axis independently against the full extent of the others: the tight box is the
  // product of the occupied bricks' extents per axis. count() is monotone in each face.
  for (int a = 0; a < 3; ++a) {
    // Largest lo with count([lo, hi)) == total.
    int l = b.lo[a], h = b.hi[a] - 1;
    while (l < h) {
      int m = l + (h - l + 1) / 2;
      box3i t = b;
      t.lo[a] = m;
      if (count(t) == total) l = m;
      else h = m - 1;
    }
    out.lo[a] = l;
    // Smallest hi with count([lo, hi)) == total.
    l = b.lo[a] + 1;
    h = b.hi[a];
    while (l < h) {
      int m = l + (h - l) / 2;
      box3i t = b;
      t.hi[a] = m;
      if (count(t) == total) h = m;
      else l = m + 1;
    }
    out.hi[a] = l;
  }
  return out;
}

}  // namespace spaceskip

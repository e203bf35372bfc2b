// Summed volume table: parallel construction (per-slice 2-D sums, then along z); the box queries
// are the shared SvtView's.
#include "spaceskip/SummedVolumeTable.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <stdexcept>

namespace spaceskip {

SummedVolumeTable::SummedVolumeTable(const OccupancyGrid& occ) {
  if (occ.size() >= (int64_t(1) << 32)) throw std::length_error("summed volume table: 2^32 or more bricks");
  const int nx = occ.dims.x, ny = occ.dims.y, nz = occ.dims.z;
  const size_t sx = size_t(nx) + 1, sxy = sx * (size_t(ny) + 1);
  // No serial zero fill: the zero borders are written by the parallel passes (first touch in
  // parallel too), every other entry by pass 1.
  sums_.reset(new uint32_t[sxy * (size_t(nz) + 1)]);  // default-initialised: no zero fill
  view_ = SvtView{occ.dims, occ.brick, occ.cellDims, sums_.get()};
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

box3i SummedVolumeTable::clip(const box3i& in) const {
  box3i b;
  for (int a = 0; a < 3; ++a) {
    b.lo[a] = std::max(in.lo[a], 0);
    b.hi[a] = std::min(in.hi[a], view_.dims[a]);
  }
  return b;
}

int64_t SummedVolumeTable::count(const box3i& in) const {
  const box3i b = clip(in);
  return b.empty() ? 0 : int64_t(view_.count(b.lo, b.hi));
}

box3i SummedVolumeTable::shrink(const box3i& in) const {
  box3i b = clip(in);
  if (b.empty() || view_.count(b.lo, b.hi) == 0) return box3i{b.lo, b.lo};
  view_.shrink(b.lo, b.hi);
  return b;
}

}  // namespace spaceskip

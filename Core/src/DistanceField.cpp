// The DistanceGrid's distance field on the CPU: three separable passes, oneTBB over lines.
#include "spaceskip/DistanceField.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace spaceskip {

std::vector<uint8_t> computeDistanceField(const OccupancyGrid& occ, int cap) {
  cap = std::max(1, std::min(cap, 255));
  const int64_t n = occ.size();
  std::vector<uint8_t> a(static_cast<size_t>(n)), b(static_cast<size_t>(n));
  for (int64_t i = 0; i < n; ++i) a[size_t(i)] = occ.occ[size_t(i)] ? 0 : uint8_t(cap);
  const vec3i d = occ.dims;
  const int64_t strides[3] = {1, int64_t(d.x), int64_t(d.x) * d.y};
  // Pass along `axis`, reading `in`, writing `out`: one task per range of z-slices.
  auto pass = [&](int axis, const std::vector<uint8_t>& in, std::vector<uint8_t>& out) {
    tbb::parallel_for(tbb::blocked_range<int>(0, d.z), [&](const tbb::blocked_range<int>& r) {
      for (int z = r.begin(); z != r.end(); ++z)
        for (int y = 0; y < d.y; ++y)
          for (int x = 0; x < d.x; ++x) {
            const int64_t i = x + strides[1] * y + strides[2] * z;
            const int pos = axis == 0 ? x : axis == 1 ? y : z;
            out[size_t(i)] = distancePass(in.data(), i, strides[axis], pos, d[axis], cap);
          }
    });
  };
  pass(0, a, b);
  pass(1, b, a);
  pass(2, a, b);
  return b;
}

}  // namespace spaceskip

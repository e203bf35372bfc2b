// The DistanceGrid's distance field on the CPU: three separable passes (distanceLine), oneTBB over lines.
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
  // Pass along `axis`, reading `in`, writing `out`: distanceLine over each line of that axis,
  // one task per range of lines (a line is numbered by its position on the other two axes).
  auto pass = [&](int axis, const std::vector<uint8_t>& in, std::vector<uint8_t>& out) {
    const int u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;  // the other two axes
    const int64_t lines = int64_t(d[u]) * d[w];
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, lines, 256), [&](const tbb::blocked_range<int64_t>& r) {
      std::vector<int> last(size_t(cap) + 1);
      for (int64_t l = r.begin(); l != r.end(); ++l) {
        const int64_t first = strides[u] * (l % d[u]) + strides[w] * (l / d[u]);
        distanceLine(in.data(), out.data(), first, strides[axis], d[axis], cap, last.data(), 1);
      }
    });
  };
  pass(0, a, b);
  pass(1, b, a);
  pass(2, a, b);
  return b;
}

}  // namespace spaceskip

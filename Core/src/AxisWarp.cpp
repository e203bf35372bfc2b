#include "spaceskip/AxisWarp.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace spaceskip {

std::shared_ptr<AxisWarp> AxisWarp::fromCoordinates(const double* const coords[3], const int64_t n[3]) {
  auto w = std::make_shared<AxisWarp>();
  for (int a = 0; a < 3; ++a) {
    const char axisName = char('x' + a);
    if (n[a] < 1 || n[a] > (int64_t(1) << 24))
      throw std::runtime_error(std::string("rectilinear grid: ") + axisName + " has " + std::to_string(n[a]) +
                               " coordinates (1 to 2^24 are drawn through the coordinates)");
    const double* x = coords[a];
    for (int64_t i = 0; i < n[a]; ++i)
      if (!std::isfinite(x[i]))
        throw std::runtime_error(std::string("rectilinear grid: ") + axisName + " coordinate " + std::to_string(i) +
                                 " is not finite");
    w->first[a] = x[0];
    w->last[a] = x[n[a] - 1];
    w->c[a].resize(size_t(n[a]));
    w->cell[a].resize(size_t(n[a]));
    if (n[a] == 1) {
      w->c[a][0] = 0.f;
      w->cell[a][0] = 0;
      continue;
    }
    const double sign = x[n[a] - 1] > x[0] ? 1.0 : -1.0;
    for (int64_t i = 1; i < n[a]; ++i)
      if (!(sign * (x[i] - x[i - 1]) > 0.0))
        throw std::runtime_error(std::string("rectilinear grid: ") + axisName + " coordinates are not strictly " +
                                 (sign > 0 ? "increasing" : "decreasing") + " at index " + std::to_string(i));
    // Virtual units: the first coordinate at 0, the last at n - 1 (exactly, whatever the rounding).
    const double scale = double(n[a] - 1) / (x[n[a] - 1] - x[0]);
    float prev = -1.f;
    for (int64_t i = 0; i < n[a]; ++i) {
      float ci = i == 0 ? 0.f : (i == n[a] - 1 ? float(n[a] - 1) : float((x[i] - x[0]) * scale));
      // Strictly increasing in float too (coordinates closer than float's resolution at this
      // index would make a cell of zero width): nudge up by one ulp, which moves a sample by
      // less than float rounding does anyway.
      if (!(ci > prev)) ci = std::nextafter(prev, 2.f * float(n[a]));
      w->c[a][size_t(i)] = ci;
      prev = ci;
    }
    if (!(w->c[a][size_t(n[a] - 2)] < w->c[a][size_t(n[a] - 1)]))
      throw std::runtime_error(std::string("rectilinear grid: ") + axisName +
                               " coordinates too close for float at the last cell");
    // cell[j]: the last i <= n - 2 with c[i] <= j.
    int64_t i = 0;
    for (int64_t j = 0; j < n[a]; ++j) {
      while (i + 1 <= n[a] - 2 && w->c[a][size_t(i + 1)] <= float(j)) ++i;
      w->cell[a][size_t(j)] = int32_t(i);
    }
  }
  return w;
}

double AxisWarp::spacing(int a) const {
  const int64_t n = points(a);
  return n > 1 ? std::abs(last[a] - first[a]) / double(n - 1) : 1.0;
}

void AxisWarp::cellSpan(int a, int64_t u0, int64_t u1, int64_t& i0, int64_t& i1) const {
  const int64_t n = points(a);
  const int64_t cells = std::max<int64_t>(n - 1, 1);
  auto cellAt = [&](int64_t u) { return int64_t(cell[a][size_t(std::clamp<int64_t>(u, 0, n - 1))]); };
  // Samples at u in [u0, u1] lie in grid cells cell[u0] (c[cell] <= u0) to the cell holding u1,
  // which is at most cell[ceil(u1)]: both found exactly from the table.
  i0 = std::max<int64_t>(cellAt(u0) - 1, 0);
  i1 = std::min<int64_t>(cellAt(u1) + 1, cells - 1);
}

AxisWarpView AxisWarp::view() const {
  AxisWarpView v;
  for (int a = 0; a < 3; ++a) {
    v.c[a] = c[a].data();
    v.cell[a] = cell[a].data();
    v.n[a] = int32_t(c[a].size());
  }
  return v;
}

}  // namespace spaceskip

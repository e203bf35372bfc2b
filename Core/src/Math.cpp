// 4x4 matrix helpers (host only).
#include "spaceskip/Math.h"

#include <cstring>

namespace spaceskip {

mat4 identity4() {
  mat4 r{};
  r.m[0] = r.m[5] = r.m[10] = r.m[15] = 1.0;
  return r;
}

mat4 multiply(const mat4& a, const mat4& b) {
  mat4 r{};
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a.m[k * 4 + row] * b.m[c * 4 + k];
      r.m[c * 4 + row] = s;
    }
  return r;
}

bool invert(const mat4& a, mat4& out) {
  // Gauss-Jordan with partial pivoting on a row-major copy.
  double m[4][8];
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) {
      m[r][c] = a.m[c * 4 + r];
      m[r][c + 4] = r == c ? 1.0 : 0.0;
    }
  for (int c = 0; c < 4; ++c) {
    int p = c;
    for (int r = c + 1; r < 4; ++r)
      if (std::fabs(m[r][c]) > std::fabs(m[p][c])) p = r;
    if (m[p][c] == 0.0 || !std::isfinite(m[p][c])) return false;
    if (p != c)
      for (int k = 0; k < 8; ++k) std::swap(m[p][k], m[c][k]);
    double d = 1.0 / m[c][c];
    for (int k = 0; k < 8; ++k) m[c][k] *= d;
    for (int r = 0; r < 4; ++r)
      if (r != c) {
        double f = m[r][c];
        for (int k = 0; k < 8; ++k) m[r][k] -= f * m[c][k];
      }
  }
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out.m[c * 4 + r] = m[r][c + 4];
  return true;
}

void transformPoint(const mat4& a, const double in[3], double out[3]) {
  double v[4];
  for (int r = 0; r < 4; ++r)
    v[r] = a.m[r] * in[0] + a.m[4 + r] * in[1] + a.m[8 + r] * in[2] + a.m[12 + r];
  for (int i = 0; i < 3; ++i) out[i] = v[i] / v[3];
}

}  // namespace spaceskip

// Small vector/box/matrix types shared by host and device code.
#pragma once
#include "Macros.h"

#include <cmath>
#include <cstdint>

namespace spaceskip {

struct vec3f {
  float x, y, z;
  SS_FUNC float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  SS_FUNC float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
};
struct vec4f {
  float x, y, z, w;
};
struct vec3i {
  int x, y, z;
  SS_FUNC int operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  SS_FUNC int& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
};
struct vec3l {
  int64_t x, y, z;
  SS_FUNC int64_t operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
};

/// v[i] = s for an axis i known at run time only, written as selects: no address is taken, so a
/// GPU keeps v in registers (a run-time index into an array, or a reference to a member chosen
/// at run time, puts the whole object in local memory).
SS_FUNC void setAxis(vec3f& v, int i, float s) {
  v.x = i == 0 ? s : v.x;
  v.y = i == 1 ? s : v.y;
  v.z = i == 2 ? s : v.z;
}
SS_FUNC void setAxis(vec3i& v, int i, int s) {
  v.x = i == 0 ? s : v.x;
  v.y = i == 1 ? s : v.y;
  v.z = i == 2 ? s : v.z;
}
/// v[i] by value (selects, as setAxis).
SS_FUNC float axisOf(const vec3f& v, int i) { return v[i]; }
SS_FUNC int axisOf(const vec3i& v, int i) { return v[i]; }

SS_FUNC vec3f operator+(vec3f a, vec3f b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
SS_FUNC vec3f operator-(vec3f a, vec3f b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
SS_FUNC vec3f operator*(vec3f a, float s) { return {a.x * s, a.y * s, a.z * s}; }
SS_FUNC vec3f operator*(float s, vec3f a) { return {a.x * s, a.y * s, a.z * s}; }
SS_FUNC float dot(vec3f a, vec3f b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
SS_FUNC vec3f cross(vec3f a, vec3f b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
SS_FUNC float length(vec3f a) { return sqrtf(dot(a, a)); }
SS_FUNC vec3f normalize(vec3f a) {
  float l = length(a);
  return l > 0.f ? a * (1.f / l) : a;
}
/// Leading zeros of a 64-bit word (64 for 0).
SS_FUNC int clz64(uint64_t v) {
#if defined(__CUDA_ARCH__)
  return __clzll(static_cast<long long>(v));
#else
  return v ? __builtin_clzll(v) : 64;
#endif
}
/// Trailing zeros of a non-zero 32-bit word.
SS_FUNC int ctz32(uint32_t v) {
#if defined(__CUDA_ARCH__)
  return __ffs(static_cast<int>(v)) - 1;
#else
  return __builtin_ctz(v);
#endif
}
/// Index of the highest set bit of a non-zero 32-bit word.
SS_FUNC int msb32(uint32_t v) {
#if defined(__CUDA_ARCH__)
  return 31 - __clz(static_cast<int>(v));
#else
  return 31 - __builtin_clz(v);
#endif
}
SS_FUNC float ss_min(float a, float b) { return a < b ? a : b; }
SS_FUNC float ss_max(float a, float b) { return a > b ? a : b; }
SS_FUNC int ss_mini(int a, int b) { return a < b ? a : b; }
SS_FUNC int ss_maxi(int a, int b) { return a > b ? a : b; }
SS_FUNC float ss_clamp(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }

/// Integer box in cell coordinates, half-open: [lo, hi).
struct box3i {
  vec3i lo, hi;
  SS_FUNC bool empty() const { return hi.x <= lo.x || hi.y <= lo.y || hi.z <= lo.z; }
  SS_FUNC int64_t volume() const {
    return empty() ? 0 : int64_t(hi.x - lo.x) * int64_t(hi.y - lo.y) * int64_t(hi.z - lo.z);
  }
};

/// Union of two boxes (the smallest box holding both; used by the LBVH's bottom-up pass and
/// KdTreeGPU's reductions, where the empty box is the one with lo = INT_MAX, hi = INT_MIN).
SS_FUNC box3i unite(const box3i& a, const box3i& b) {
  return box3i{vec3i{ss_mini(a.lo.x, b.lo.x), ss_mini(a.lo.y, b.lo.y), ss_mini(a.lo.z, b.lo.z)},
               vec3i{ss_maxi(a.hi.x, b.hi.x), ss_maxi(a.hi.y, b.hi.y), ss_maxi(a.hi.z, b.hi.z)}};
}

/// Cell-space box of the bricks [bricks.lo, bricks.hi) of `brick`^3 cells, clamped to `cellDims`.
/// Clamped to the voxel dims - 1 instead, [lo, hi] inclusive is the voxel range a trilinear sample
/// in those bricks touches (the +1 halo of RangeGrid).
SS_FUNC box3i brickCellBox(const box3i& bricks, int brick, vec3i cellDims) {
  return box3i{vec3i{bricks.lo.x * brick, bricks.lo.y * brick, bricks.lo.z * brick},
               vec3i{ss_mini(bricks.hi.x * brick, cellDims.x), ss_mini(bricks.hi.y * brick, cellDims.y),
                     ss_mini(bricks.hi.z * brick, cellDims.z)}};
}

/// Cell-space box of brick `b` (clamped to the volume, as OccupancyGrid::brickBox).
SS_FUNC box3i brickCellBox(vec3i b, int brick, vec3i cellDims) {
  return brickCellBox(box3i{b, vec3i{b.x + 1, b.y + 1, b.z + 1}}, brick, cellDims);
}

/// The bricks a cell region covers: [floor(lo / brick), ceil(hi / brick)) per axis.
SS_FUNC box3i cellBrickBox(const box3i& cells, int brick) {
  return box3i{vec3i{cells.lo.x / brick, cells.lo.y / brick, cells.lo.z / brick},
               vec3i{(cells.hi.x + brick - 1) / brick, (cells.hi.y + brick - 1) / brick,
                     (cells.hi.z + brick - 1) / brick}};
}

/// Ray in the volume's index space; t is shared with world space (the map is affine).
struct Ray {
  vec3f org, dir;
};

/// Slab test; returns the entry/exit parameters (tnear > tfar when missed).
/// Division by a zero direction component yields +-inf, which the min/max handle for
/// axis-parallel rays; the NaN of 0*inf (origin on a slab) is ignored by fminf/fmaxf.
SS_FUNC void intersectBox(const Ray& r, vec3f inv, vec3f lo, vec3f hi, float& tnear, float& tfar) {
  float t0x = (lo.x - r.org.x) * inv.x, t1x = (hi.x - r.org.x) * inv.x;
  float t0y = (lo.y - r.org.y) * inv.y, t1y = (hi.y - r.org.y) * inv.y;
  float t0z = (lo.z - r.org.z) * inv.z, t1z = (hi.z - r.org.z) * inv.z;
  tnear = fmaxf(fmaxf(fminf(t0x, t1x), fminf(t0y, t1y)), fminf(t0z, t1z));
  tfar = fminf(fminf(fmaxf(t0x, t1x), fmaxf(t0y, t1y)), fmaxf(t0z, t1z));
}

SS_FUNC vec3f safeInverse(vec3f d) {
  // A zero component gives +inf with the sign of the zero: slabs parallel to the ray then
  // contribute [-inf, inf] or an empty range, as the slab test expects.
  return {1.f / d.x, 1.f / d.y, 1.f / d.z};
}

/// Column-major 4x4 matrix (OpenGL/VTK-transposed convention: m[col*4+row]).
struct mat4 {
  double m[16];
};

mat4 identity4();
mat4 multiply(const mat4& a, const mat4& b);
bool invert(const mat4& a, mat4& out);
/// Transforms a point (w divide included).
void transformPoint(const mat4& a, const double in[3], double out[3]);

}  // namespace spaceskip

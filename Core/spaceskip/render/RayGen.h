// Ray generation: the primary ray of a pixel in the volume's index space, cut to the box, the
// window's depth, the clipping planes and the cropping regions. Written once for both executors.
#pragma once
#include "FrameShared.h"

#include <algorithm>
#include <cmath>

namespace spaceskip {

/// A pixel's ray in index space over [tEnter, tExit) (empty when !(tEnter < tExit)), with the
/// world-space entry frame that shading needs.
struct PrimaryRay {
  Ray r;
  vec3f inv;  ///< safeInverse(r.dir)
  vec3f nearW, dirW;
  float tEnter, tExit;
};

SS_FUNC uint32_t hashPixel(uint32_t x, uint32_t y, uint32_t seed) {
  uint32_t h = x * 0x8da6b343u ^ y * 0xd8163841u ^ seed * 0xcb1ab31fu;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}

SS_FUNC vec3f unproject(const float* m, float x, float y, float z) {
  float X = m[0] * x + m[4] * y + m[8] * z + m[12];
  float Y = m[1] * x + m[5] * y + m[9] * z + m[13];
  float Z = m[2] * x + m[6] * y + m[10] * z + m[14];
  float W = m[3] * x + m[7] * y + m[11] * z + m[15];
  return vec3f{X / W, Y / W, Z / W};
}

/// The ray through the centre of pixel (px, py) (row 0 at the bottom), entering the index-space box
/// [0, boxHi) no earlier than the near plane and leaving it no later than the window's depth.
SS_FUNC PrimaryRay primaryRay(const FrameView& f, int px, int py) {
  PrimaryRay p;
  const float nx = (float(px) + 0.5f) / float(f.width) * 2.f - 1.f;
  const float ny = (float(py) + 0.5f) / float(f.height) * 2.f - 1.f;
  p.nearW = unproject(f.invViewProj, nx, ny, -1.f);
  vec3f farW = unproject(f.invViewProj, nx, ny, 1.f);
  p.dirW = normalize(farW - p.nearW);
  float tLimit = INFINITY;
  if (f.depth) {
    float d = f.depth[int64_t(py) * f.width + px];
    if (d < 1.f) tLimit = dot(unproject(f.invViewProj, nx, ny, 2.f * d - 1.f) - p.nearW, p.dirW);
  }
  const float* M = f.worldToIndex;
  const vec3f nearW = p.nearW, dirW = p.dirW;
  p.r.org = vec3f{M[0] * nearW.x + M[1] * nearW.y + M[2] * nearW.z + M[3],
                  M[4] * nearW.x + M[5] * nearW.y + M[6] * nearW.z + M[7],
                  M[8] * nearW.x + M[9] * nearW.y + M[10] * nearW.z + M[11]};
  p.r.dir = vec3f{M[0] * dirW.x + M[1] * dirW.y + M[2] * dirW.z,
                  M[4] * dirW.x + M[5] * dirW.y + M[6] * dirW.z,
                  M[8] * dirW.x + M[9] * dirW.y + M[10] * dirW.z};
  p.inv = safeInverse(p.r.dir);
  intersectBox(p.r, p.inv, vec3f{0, 0, 0}, f.boxHi, p.tEnter, p.tExit);
  p.tEnter = ss_max(p.tEnter, 0.f);
  p.tExit = ss_min(p.tExit, tLimit);
  // A ray that is not finite (a camera or volume matrix out of float's range) draws nothing:
  // intersectBox's fminf/fmaxf drop a NaN axis, which would leave a long interval whose sample
  // positions are NaN. x - x is 0 for finite x only.
  const float all = p.r.org.x + p.r.org.y + p.r.org.z + p.r.dir.x + p.r.dir.y + p.r.dir.z + p.tExit;
  if (!(all - all == 0.f)) p.tEnter = p.tExit = 0.f;
  return p;
}

/// The pixels whose rays can meet the index-space box [0, boxHi] (host only): rect = {x0, y0,
/// x1, y1}, half-open, within the frame. A ray meets the box only where its pixel's centre lies
/// in the box's projection, the hull of its 8 projected corners: their NDC bounds, widened by 2
/// pixels against rounding. The whole frame when a matrix does not invert, a corner is not in
/// front of the eye (w <= 0) or not finite. Every pixel outside the rect renders (0, 0, 0, 0).
inline void boxPixelRect(const FrameView& f, int rect[4]) {
  rect[0] = rect[1] = 0;
  rect[2] = f.width;
  rect[3] = f.height;
  mat4 invVp{}, vp{}, w2i = identity4(), i2w{};
  for (int i = 0; i < 16; ++i) invVp.m[i] = f.invViewProj[i];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) w2i.m[c * 4 + r] = f.worldToIndex[r * 4 + c];  // row-major 3x4
  if (!invert(invVp, vp) || !invert(w2i, i2w)) return;
  const mat4 m = multiply(vp, i2w);  // index -> clip
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (int corner = 0; corner < 8; ++corner) {
    const double p[3] = {(corner & 1) ? double(f.boxHi.x) : 0.0, (corner & 2) ? double(f.boxHi.y) : 0.0,
                         (corner & 4) ? double(f.boxHi.z) : 0.0};
    double clip[4];
    for (int r = 0; r < 4; ++r) clip[r] = m.m[r] * p[0] + m.m[4 + r] * p[1] + m.m[8 + r] * p[2] + m.m[12 + r];
    if (!(clip[3] > 0.0) || !std::isfinite(clip[0] / clip[3]) || !std::isfinite(clip[1] / clip[3])) return;
    for (int a = 0; a < 2; ++a) {
      lo[a] = std::min(lo[a], clip[a] / clip[3]);
      hi[a] = std::max(hi[a], clip[a] / clip[3]);
    }
  }
  // Pixel p's centre is at NDC (p + 0.5) / n * 2 - 1 (primaryRay).
  const int n[2] = {f.width, f.height};
  for (int a = 0; a < 2; ++a) {
    const double first = std::floor((lo[a] + 1) * 0.5 * n[a] - 0.5) - 2;
    const double last = std::ceil((hi[a] + 1) * 0.5 * n[a] - 0.5) + 2;
    const int x0 = int(std::max(0.0, std::min(first, double(n[a]))));
    const int x1 = int(std::max(0.0, std::min(last + 1, double(n[a]))));
    rect[a] = x0;
    rect[2 + a] = std::max(x0, x1);
  }
}

// -- Rendering one piece of a larger volume (FrameView::lattice, MPI) -------------------------
// The ray, its box, the planes and the sample lattice t = t0 + k*dt are the whole volume's, the
// same on every rank as in the serial render; a piece draws the samples inside its owned cells.

/// The ray in the piece's own index space, where its voxels, grid and tree live: the same ray
/// moved by the piece's offset (t is shared). Serial: `r` itself.
SS_FUNC Ray pieceRay(const FrameView& f, const Ray& r) {
  return f.lattice.active ? Ray{r.org - f.lattice.pieceLo, r.dir} : r;
}

/// The part [a, b) of the ray inside the piece's owned cells; false when empty. Every rank
/// evaluates the same float expression for a face two pieces share, so their intervals meet at
/// the same t and each sample of the lattice is drawn by exactly one of them.
SS_FUNC bool ownedInterval(const FrameView& f, const Ray& r, vec3f inv, float& a, float& b) {
  intersectBox(r, inv, f.lattice.ownLo, f.lattice.ownHi, a, b);
  return a < b;
}

/// A piece's pixel as it goes to the compositor: where the ray goes on into another piece
/// behind this one (its owned part ends before the box's exit), the colour is raised by
/// followBias (VolumePiece::followBias: rounding for an 8-bit compositor that truncates).
SS_FUNC vec4f pieceResult(const FrameView& f, vec4f c, float ownB, float tExit) {
  if (f.lattice.followBias != 0.f && c.w > 0.f && ownB < tExit) {
    c.x += f.lattice.followBias;
    c.y += f.lattice.followBias;
    c.z += f.lattice.followBias;
  }
  return c;
}

/// Does the piece draw a sample at whole-volume position p lying outside the box (a ray's first
/// sample one step in, past where the ray leaves the box: the sampler clamps it to the box)?
/// The owner of the clamped position does; faces of the whole box belong to the piece there.
SS_FUNC bool ownsClampedSample(const FrameView& f, vec3f p) {
  const LatticeView& l = f.lattice;
  for (int a = 0; a < 3; ++a) {
    const float x = ss_clamp(p[a], 0.f, f.boxHi[a]);
    if (!(x >= l.ownLo[a] && (x < l.ownHi[a] || (x == f.boxHi[a] && l.ownHi[a] == f.boxHi[a])))) return false;
  }
  return true;
}

/// Clips [tmin, tmax] to the convex intersection of the clipping half-spaces; false if empty.
SS_FUNC bool clipToPlanes(const CropClip& cc, const Ray& r, float& tmin, float& tmax) {
  for (int i = 0; i < cc.numClipPlanes; ++i) {
    const float* c = cc.clip[i];
    const float num = c[0] * r.org.x + c[1] * r.org.y + c[2] * r.org.z + c[3];
    const float den = c[0] * r.dir.x + c[1] * r.dir.y + c[2] * r.dir.z;
    if (den == 0.f) {
      if (num < 0.f) return false;  // parallel to the plane, on the removed side
      continue;
    }
    const float t = -num / den;
    if (den > 0.f) tmin = ss_max(tmin, t);  // entering the kept side
    else tmax = ss_min(tmax, t);
  }
  return tmin < tmax;
}

/// Region index (0..2) of coordinate x between the planes lo and hi of one axis.
SS_FUNC int cropSlab(float x, float lo, float hi) { return x < lo ? 0 : (x < hi ? 1 : 2); }

/// Calls march(a, b) for each part of [tmin, tmax] that lies in a drawn cropping region, front
/// to back: the six planes split the ray into at most seven pieces, each inside one region.
template <class March>
SS_FUNC void forEachCroppedInterval(const CropClip& cc, const Ray& r, float tmin, float tmax, March&& march) {
  float ts[8];
  int n = 0;
  ts[n++] = tmin;
  for (int a = 0; a < 6; ++a) {
    const float o = a < 2 ? r.org.x : (a < 4 ? r.org.y : r.org.z);
    const float d = a < 2 ? r.dir.x : (a < 4 ? r.dir.y : r.dir.z);
    if (d == 0.f) continue;
    const float t = (cc.crop[a] - o) / d;
    if (t > tmin && t < tmax) ts[n++] = t;
  }
  ts[n++] = tmax;
  for (int i = 1; i < n; ++i)  // insertion sort: at most 8 values
    for (int j = i; j > 0 && ts[j] < ts[j - 1]; --j) {
      const float x = ts[j];
      ts[j] = ts[j - 1];
      ts[j - 1] = x;
    }
  for (int i = 0; i + 1 < n; ++i) {
    const float a = ts[i], b = ts[i + 1];
    if (!(a < b)) continue;
    const float tm = 0.5f * (a + b);
    const vec3f p = r.org + r.dir * tm;
    const int region = cropSlab(p.x, cc.crop[0], cc.crop[1]) + 3 * cropSlab(p.y, cc.crop[2], cc.crop[3]) +
                       9 * cropSlab(p.z, cc.crop[4], cc.crop[5]);
    if ((cc.cropFlags >> region) & 1)
      if (!march(a, b)) return;
  }
}

}  // namespace spaceskip

// Cropping (vtkVolumeMapper's 27 regions) and clipping planes in the volume's index space: the
// planes the integrator cuts samples at (FrameView) and the test that lets classification count
// bricks no drawn sample can reach as empty. Plain data; one rule for the host and the device.
#pragma once
#include "Math.h"
#include "Types.h"

#include <cstring>

namespace spaceskip {

/// What of the volume is drawn, in index space (the Engine builds it once per change and hands
/// the same values to the FrameView and to classification).
struct CropClip {
  int numClipPlanes = 0;         ///< half-spaces c.p + c[3] >= 0 are kept (convex)
  float clip[kMaxClipPlanes][4] = {};
  int cropping = 0;              ///< 1: only the regions of cropFlags are drawn
  int cropFlags = 0x7ffffff;     ///< bit i + 3j + 9k: region (i, j, k) of the 3x3x3 split is drawn
  float crop[6] = {};            ///< planes x0, x1, y0, y1, z0, z1

  SS_FUNC bool active() const { return numClipPlanes > 0 || cropping != 0; }
};

/// Bitwise (NaN-safe: the same planes compare equal, so they never re-classify).
inline bool operator==(const CropClip& a, const CropClip& b) {
  return a.numClipPlanes == b.numClipPlanes && a.cropping == b.cropping && a.cropFlags == b.cropFlags &&
         std::memcmp(a.clip, b.clip, sizeof a.clip) == 0 && std::memcmp(a.crop, b.crop, sizeof a.crop) == 0;
}
inline bool operator!=(const CropClip& a, const CropClip& b) { return !(a == b); }

/// Can a drawn sample lie in the cell box `cells` (a brick's box, brickCellBox: samples in it
/// read its voxels plus the +1 halo, which the value ranges already cover)? Conservative: the
/// box is widened by 1/16 voxel plus 2^-16 of its coordinates, more than the float error of
/// where a traversal's brick interval and the integrator's plane cuts put a sample; a brick is
/// undrawable only when the widened box meets no drawn cropping region or lies wholly on the
/// removed side of one clipping plane. NaN planes never make a brick empty.
SS_FUNC bool brickMayBeDrawn(const box3i& cells, const CropClip& cc) {
  float lo[3] = {float(cells.lo.x), float(cells.lo.y), float(cells.lo.z)};
  float hi[3] = {float(cells.hi.x), float(cells.hi.y), float(cells.hi.z)};
  for (int a = 0; a < 3; ++a) {
    const float m = ss_max(fabsf(lo[a]), fabsf(hi[a]));
    const float pad = 0.0625f + m * (1.f / 65536.f);
    lo[a] -= pad;
    hi[a] += pad;
  }
  for (int i = 0; i < cc.numClipPlanes; ++i) {
    const float* c = cc.clip[i];
    float best = c[3];  // the largest c.p + c[3] over the box's corners
    for (int a = 0; a < 3; ++a) best += c[a] > 0.f ? c[a] * hi[a] : c[a] * lo[a];
    if (best < 0.f) return false;  // wholly removed by this plane
  }
  if (!cc.cropping) return true;
  // The slabs (0: x < p0, 1: p0 <= x < p1, 2: x >= p1) the box meets on each axis, as bits.
  int slabs[3];
  for (int a = 0; a < 3; ++a) {
    const float p0 = cc.crop[2 * a], p1 = cc.crop[2 * a + 1];
    slabs[a] = (lo[a] < p0 ? 1 : 0) | (!(p1 <= lo[a]) && !(hi[a] < p0) ? 2 : 0) | (!(hi[a] < p1) ? 4 : 0);
  }
  for (int k = 0; k < 3; ++k) {
    if (!((slabs[2] >> k) & 1)) continue;
    for (int j = 0; j < 3; ++j) {
      if (!((slabs[1] >> j) & 1)) continue;
      for (int i = 0; i < 3; ++i)
        if (((slabs[0] >> i) & 1) && ((cc.cropFlags >> (i + 3 * j + 9 * k)) & 1)) return true;
    }
  }
  return false;
}

}  // namespace spaceskip

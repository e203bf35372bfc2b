// The k-d split decision shared by KdTreeGPU (host-driven, paper 3.2.2) and KdTreeGPUFast
// (level-parallel, on the device), so both build the same tree. Cost and halting follow the
// paper's code (deskvox virvo/spaceskip/cudakdtree.cu, node_splitting): candidate planes along
// the longest axis at multiples of len/bins, snapped down to the brick raster; cost = sum of the
// children's tight volumes; a split removing <= 1/1000 of the node volume is rejected. Halting:
// Shallow = node volume < 10% of the root's, Deep = node volume <= 8^3 cells. MLS (paper 4.3):
// a leaf longer than MLS cells along its longest axis is split in the middle of that axis.
#pragma once
#include "spaceskip/Math.h"

#include <cstdint>

namespace spaceskip::cuda {

struct KdSplitParams {
  int deep;         ///< 1: Deep halting, 0: Shallow
  int mls;          ///< 0: none, else max leaf edge in cells
  int bins;         ///< candidate planes = bins - 1
  int brick;        ///< raster the planes snap to (cells)
  int64_t rootVol;  ///< volume of the root's tight box (cells)
};

struct KdDecision {
  int split;  ///< 0: leaf
  box3i left, right;  ///< tight child boxes when split
};

SS_FUNC int longestAxis(const box3i& b) {
  int lx = b.hi.x - b.lo.x, ly = b.hi.y - b.lo.y, lz = b.hi.z - b.lo.z;
  return lx >= ly ? (lx >= lz ? 0 : 2) : (ly >= lz ? 1 : 2);
}

/// `box` is the node's tight box (cells); `tight(region)` returns the tight box of the
/// occupied bricks inside `region` (empty box when none).
#ifdef __CUDACC__
#pragma nv_exec_check_disable
#endif
template <class Tight>
SS_FUNC KdDecision decideKdSplit(const box3i& box, const KdSplitParams& p, Tight& tight) {
  KdDecision d;
  d.split = 0;
  d.left = d.right = box;
  const int64_t vol = box.volume();
  const int axis = longestAxis(box);
  const int lo = box.lo[axis], hi = box.hi[axis], len = hi - lo;
  const bool halt = p.deep ? vol <= 512 : vol < p.rootVol / 10;
  if (!halt) {
    const int dl = ss_maxi(len / p.bins, p.brick);
    int64_t best = INT64_MAX;
    for (int k = 1; k < p.bins; ++k) {
      int pos = lo + dl * k;
      pos = pos / p.brick * p.brick;
      if (pos <= lo || pos >= hi) continue;  // a plane on the border removes nothing
      box3i l = box, r = box;
      l.hi[axis] = pos;
      r.lo[axis] = pos;
      l = tight(l);
      r = tight(r);
      const int64_t c = l.volume() + r.volume();
      if (vol - c <= vol / 1000) continue;
      if (c < best) {
        best = c;
        d.split = 1;
        d.left = l;
        d.right = r;
      }
    }
    if (d.split) return d;
  }
  if (p.mls > 0 && len > p.mls) {
    int pos = (lo + len / 2) / p.brick * p.brick;
    if (pos <= lo) pos = lo + p.brick;
    if (pos < hi) {
      box3i l = box, r = box;
      l.hi[axis] = pos;
      r.lo[axis] = pos;
      d.split = 1;
      d.left = tight(l);
      d.right = tight(r);
    }
  }
  return d;
}

}  // namespace spaceskip::cuda

// The k-d split rule, written once for KdTreeCPU (oneTBB tasks, src/KdTreeBuilder.cpp), KdTreeGPU
// (host-driven, paper 3.2.2) and KdTreeGPUFast (level-parallel, cuda/KdTreeBuilder.cu), so all
// three build the same tree. Cost and halting follow the paper's code (deskvox
// virvo/spaceskip/cudakdtree.cu, node_splitting): candidate planes along the longest axis at
// multiples of len/bins, snapped down to the brick raster; cost = sum of the children's tight
// volumes; a split removing <= 1/1000 of the node volume is rejected. Halting: Shallow = node
// volume < 10% of the root's, Deep = node volume <= 8^3 cells. MLS (paper 4.3): a leaf longer
// than MLS cells along its longest axis is split in the middle of that axis.
//
// bins == 0 is the sweep (Vidal's plane sweep, every step-th brick boundary): KdTreeCPU always
// runs it, so a GPU tree with bins 0 is the KdTreeCPU tree of the same leaf criterion and MLS,
// node for node (the layout order aside). Header-only and host+device (SS_FUNC).
//
// Leaf criterion Empty (ours, the paper's open problem, 4.3/4.4): Deep's halting and cost, but a
// node the cost leaves as a leaf is not cut by size (MLS) but by what it holds: it stays a leaf,
// however large, when at most 1/kKdEmptyLeafDiv of its bricks are empty (homogeneous space, the
// Richtmyer-Meshkov case, is never over-split), else it is split at its empty/non-empty boundary:
// the brick-raster plane, over all three axes, with the largest between-class variance of the
// brick occupancy (Otsu: (oL nR - oR nL)^2 / (nL nR) for occupied bricks o and bricks n of the two
// sides), which escapes the greedy cost's local optimum (the Xmas-tree leaf). MLS is ignored.
// Needs `tight.count(lo, hi)`: occupied bricks in a brick box (SvtView has it).
#pragma once
#include "Math.h"

#include <cstdint>

namespace spaceskip::detail {

/// Leaf criterion Empty: a stalled node stays a leaf when empty bricks <= bricks / this.
constexpr int kKdEmptyLeafDiv = 8;

struct KdSplitParams {
  int deep;         ///< 1: Deep halting (Deep, Empty), 0: Shallow
  int mls;          ///< 0: none, else max leaf edge in cells
  int bins;         ///< candidate planes = bins - 1 (>= 2); 0: sweep (kdCandidateCount)
  int brick;        ///< raster the planes snap to (cells)
  int64_t rootVol;  ///< volume of the root's tight box (cells)
  int empty;        ///< 1: leaf criterion Empty (occupancy-driven leaves, MLS ignored), 0: MLS rule
};

struct KdDecision {
  int split;  ///< 0: leaf
  box3i left, right;  ///< tight child boxes when split
};

/// No split: `box` stays a leaf.
SS_FUNC KdDecision kdLeaf(const box3i& box) {
  KdDecision d;
  d.split = 0;
  d.left = d.right = box;
  return d;
}

/// The longest axis, the first one on ties.
SS_FUNC int longestAxis(const box3i& b) {
  int lx = b.hi.x - b.lo.x, ly = b.hi.y - b.lo.y, lz = b.hi.z - b.lo.z;
  return lx >= ly ? (lx >= lz ? 0 : 2) : (ly >= lz ? 1 : 2);
}

/// The sweep's step in bricks: every brick boundary for bricks of 8 cells or more, else every
/// ceil(8/brick) bricks (Vidal's raster of 8 voxels).
SS_FUNC int kdSweepStep(int brick) { return ss_maxi(1, (8 + brick - 1) / brick); }

SS_FUNC bool kdHalts(const box3i& box, const KdSplitParams& p) {
  const int64_t vol = box.volume();
  return p.deep ? vol <= 512 : vol < p.rootVol / 10;
}

/// Candidate planes of a node along `axis`: bins - 1, or for the sweep every step-th brick
/// boundary strictly inside the node (up to bricks/step - 1, e.g. 255 at 2048^3 with 8^3 bricks).
SS_FUNC int kdCandidateCount(const box3i& box, int axis, const KdSplitParams& p) {
  if (p.bins > 0) return p.bins - 1;
  // Bricks along the axis: the node's lo is on the raster, its hi may be clamped to the volume.
  const int nb = (box.hi[axis] - box.lo[axis] + p.brick - 1) / p.brick;
  return ss_maxi(0, nb / kdSweepStep(p.brick) - 1);
}

/// Position (cells) of candidate k, 1 <= k <= kdCandidateCount, in increasing order of k.
SS_FUNC int kdCandidatePlane(const box3i& box, int axis, int k, const KdSplitParams& p) {
  const int lo = box.lo[axis];
  if (p.bins == 0) return lo + k * kdSweepStep(p.brick) * p.brick;
  const int dl = ss_maxi((box.hi[axis] - lo) / p.bins, p.brick);
  return (lo + dl * k) / p.brick * p.brick;
}

/// The sweep both rules run over a node's candidate planes: candidate k = 1..count is scored by
/// `score(k)`; one whose score `beats(score, best)` (strictly better than `best` and every
/// earlier one) becomes `best` and is handed to `keep(k)`, so ties keep the first candidate.
/// Returns whether any did.
#ifdef __CUDACC__
#pragma nv_exec_check_disable
#endif
template <class T, class Score, class Beats, class Keep>
SS_FUNC bool kdSweep(int count, T& best, Score&& score, Beats&& beats, Keep&& keep) {
  bool found = false;
  for (int k = 1; k <= count; ++k) {
    const T v = score(k);
    if (beats(v, best)) {
      best = v;
      keep(k);
      found = true;
    }
  }
  return found;
}

/// Cost of splitting `box` at `pos` along `axis` (sum of the tight children's volumes) and the
/// children; INT64_MAX when the plane is rejected (on the border, or it removes <= 1/1000 of the
/// node volume as empty space).
#ifdef __CUDACC__
#pragma nv_exec_check_disable
#endif
template <class Tight>
SS_FUNC int64_t kdPlaneCost(const box3i& box, int axis, int pos, Tight& tight, box3i& l, box3i& r) {
  if (pos <= box.lo[axis] || pos >= box.hi[axis]) return INT64_MAX;  // a plane on the border removes nothing
  l = box;
  r = box;
  l.hi[axis] = pos;
  r.lo[axis] = pos;
  l = tight(l);
  r = tight(r);
  const int64_t vol = box.volume(), c = l.volume() + r.volume();
  return vol - c <= vol / 1000 ? INT64_MAX : c;
}

/// `box` split at `pos` on `axis`, the children's boxes tightened by `tight`.
#ifdef __CUDACC__
#pragma nv_exec_check_disable
#endif
template <class Tight>
SS_FUNC KdDecision kdSplitAt(const box3i& box, int axis, int pos, Tight& tight) {
  KdDecision d;
  box3i l = box, r = box;
  l.hi[axis] = pos;
  r.lo[axis] = pos;
  d.split = 1;
  d.left = tight(l);
  d.right = tight(r);
  return d;
}

/// The MLS split of a would-be leaf (d.split = 0 when MLS does not apply). Binned: the middle of
/// the axis snapped down to the raster, at least one brick in. Sweep: KdTreeCPU's middle brick
/// boundary, lo + (bricks / 2) bricks; the two differ only for a box clamped to the volume.
#ifdef __CUDACC__
#pragma nv_exec_check_disable
#endif
template <class Tight>
SS_FUNC KdDecision kdMlsSplit(const box3i& box, int axis, const KdSplitParams& p, Tight& tight) {
  KdDecision d = kdLeaf(box);
  const int lo = box.lo[axis], hi = box.hi[axis], len = hi - lo;
  if (p.mls <= 0 || len <= p.mls) return d;
  int pos;
  if (p.bins == 0) {
    pos = lo + (len + p.brick - 1) / p.brick / 2 * p.brick;  // a one-brick box gives pos == lo: no split
  } else {
    pos = (lo + len / 2) / p.brick * p.brick;
    if (pos <= lo) pos = lo + p.brick;
  }
  return pos > lo && pos < hi ? kdSplitAt(box, axis, pos, tight) : d;
}

/// Leaf criterion Empty: the split of a would-be leaf (d.split = 0: it stays a leaf). See the
/// header comment. Ties: the first axis (x, y, z), then the first plane in increasing order; when
/// every plane scores 0 (the occupancy looks the same on both sides everywhere) the middle of the
/// longest axis. Scores are compared in double from exact integers (no FMA can contract them),
/// so the CPU and the GPU choose alike.
#ifdef __CUDACC__
#pragma nv_exec_check_disable
#endif
template <class Tight>
SS_FUNC KdDecision kdEmptySplit(const box3i& box, const KdSplitParams& p, Tight& tight) {
  if (kdHalts(box, p)) return kdLeaf(box);  // Deep's halting holds
  KdDecision d = kdLeaf(box);
  const int B = p.brick;
  const vec3i lo{box.lo.x / B, box.lo.y / B, box.lo.z / B};
  const vec3i hi{(box.hi.x + B - 1) / B, (box.hi.y + B - 1) / B, (box.hi.z + B - 1) / B};
  const int64_t n = int64_t(hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z);
  const int64_t o = int64_t(tight.count(lo, hi));
  if (n <= 1 || (n - o) * kKdEmptyLeafDiv <= n) return d;  // (nearly) homogeneous: a leaf
  const int step = kdSweepStep(B);
  double best = 0;
  int bestAxis = -1, bestPos = 0;
  for (int a = 0; a < 3; ++a) {
    const int64_t slab = n / (hi[a] - lo[a]);  // bricks per unit slab along a
    // Candidate i: the brick plane lo + i step, strictly inside the node.
    kdSweep(
        (hi[a] - lo[a] - 1) / step, best,
        [&](int i) {
          const int k = lo[a] + i * step;
          vec3i h2 = hi;
          h2[a] = k;
          const int64_t nl = slab * (k - lo[a]), nr = n - nl;
          const int64_t ol = int64_t(tight.count(lo, h2)), orr = o - ol;
          const double diff = double(ol * nr - orr * nl);
          return diff * diff / (double(nl) * double(nr));
        },
        [](double v, double b) { return v > b; },
        [&](int i) {
          bestAxis = a;
          bestPos = lo[a] + i * step;
        });
  }
  if (bestAxis < 0) {  // no plane tells the two sides apart: halve the longest axis
    bestAxis = longestAxis(box);
    if (hi[bestAxis] - lo[bestAxis] < 2) return d;
    bestPos = lo[bestAxis] + (hi[bestAxis] - lo[bestAxis]) / 2;
  }
  return kdSplitAt(box, bestAxis, bestPos * B, tight);
}

/// The split of a node the cost function leaves as a leaf: Empty's rule or MLS's.
#ifdef __CUDACC__
#pragma nv_exec_check_disable
#endif
template <class Tight>
SS_FUNC KdDecision kdLeafSplit(const box3i& box, int axis, const KdSplitParams& p, Tight& tight) {
  return p.empty ? kdEmptySplit(box, p, tight) : kdMlsSplit(box, axis, p, tight);
}

/// `box` is the node's tight box (cells); `tight(region)` returns the tight box of the
/// occupied bricks inside `region` (empty box when none; SvtView in SummedVolumeTable.h). The
/// least cost wins; on ties the first plane in increasing order. KdTreeGPUFast evaluates the
/// sweep's candidates in parallel with the same pieces (cuda/KdTreeBuilder.cu,
/// levelDecideSweepKernel).
#ifdef __CUDACC__
#pragma nv_exec_check_disable
#endif
template <class Tight>
SS_FUNC KdDecision decideKdSplit(const box3i& box, const KdSplitParams& p, Tight& tight) {
  KdDecision d = kdLeaf(box);
  const int axis = longestAxis(box);
  if (!kdHalts(box, p)) {
    int64_t best = INT64_MAX;  // a rejected plane costs INT64_MAX: it never beats this
    box3i l, r;
    if (kdSweep(
            kdCandidateCount(box, axis, p), best,
            [&](int k) { return kdPlaneCost(box, axis, kdCandidatePlane(box, axis, k, p), tight, l, r); },
            [](int64_t c, int64_t b) { return c < b; },
            [&](int) {
              d.left = l;
              d.right = r;
            })) {
      d.split = 1;
      return d;
    }
  }
  return kdLeafSplit(box, axis, p, tight);
}

}  // namespace spaceskip::detail

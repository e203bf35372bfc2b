// DistanceGrid: the brick occupancy grid plus, per empty brick, its Chebyshev (L-infinity)
// distance in bricks to the nearest occupied brick ("proximity clouds", Cohen & Sheffer 1994).
// A brick at distance d is the centre of a cube of (2d-1)^3 empty bricks, so the grid DDA can
// leave that whole cube in one step instead of visiting its bricks one by one. The distance is
// a lower bound (capped at kMaxSkipDistance), so skipping with it is lossless.
#pragma once
#include "Classification.h"

#include <cstdint>
#include <vector>

namespace spaceskip {

/// Largest stored distance; a brick farther from every occupied brick stores this value.
/// The CUDA passes cut a line into segments that each start `cap` bricks early, so the cap is
/// their cost: on the H100 (docs/results/HISTORY.md, the distance cap) 32 instead of 64 built N-body 2048^3's
/// field in 0.37-0.38 ms instead of 0.47-0.49 (Richtmyer-Meshkov 0.35 vs 0.45), and the frame
/// rates of every builder using it on all 11 stand-ins stayed within 0.97-1.03x (two processes
/// each, alternated): leaps of 32 bricks (256 voxels) are already long.
constexpr int kMaxSkipDistance = 32;

/// One pass of the separable L-infinity distance transform along one axis of the brick grid:
/// out[i] = min(cap, min_j max(|j|, in[i + j*stride])) over the line through i (n bricks,
/// `pos` = i's position on it). Pass 1 reads 0 (occupied) / cap (empty); passes 2 and 3 read the
/// previous pass. This per-brick form costs O(distance) a brick (up to 2 * cap reads where the
/// data is sparse); the builds use distanceLine below, the same values in O(1) a brick, and the
/// tests check the two against each other.
SS_FUNC uint8_t distancePass(const uint8_t* in, int64_t i, int64_t stride, int pos, int n, int cap) {
  int best = in[i];
  for (int j = 1; j < best; ++j) {
    if (pos - j >= 0) {
      const int v = in[i - j * stride];
      const int c = v > j ? v : j;
      if (c < best) best = c;
    }
    if (pos + j < n) {
      const int v = in[i + j * stride];
      const int c = v > j ? v : j;
      if (c < best) best = c;
    }
    if (pos - j < 0 && pos + j >= n) break;
  }
  return uint8_t(best < cap ? best : cap);
}

/// One sweep of distanceLine: along `n` bricks from `first` in steps of `step` (+-stride),
/// L = min(cap, min over the bricks j already passed, this one included, of max(|i - j|, in[j]))
/// at each brick i, in O(1) a brick; written from the brick `skip` on (the ones before are only
/// passed); `combine`: out = min(out, L), else out = L.
/// The recurrence: from one brick to the next every passed term either stays or grows by one,
/// so L grows by one unless a passed brick j with in[j] <= L lies within L of the next brick;
/// `p` is the last passed brick with in[j] <= L, `last[v * lastStep]` the last with in[j] == v
/// (v <= cap) and feeds p when L grows. `Idx` holds positions on the sweep (int16_t where the
/// sweep is shorter than 32k bricks: half the scratch).
template <class Idx>
SS_FUNC void distanceSweep(const uint8_t* in, uint8_t* out, int64_t first, int64_t step, int n, int skip, int cap,
                           Idx* last, int lastStep, bool combine) {
  const int none = sizeof(Idx) == 2 ? -32768 : -(1 << 30);
  for (int v = 0; v <= cap; ++v) last[v * lastStep] = Idx(none);
  int L = cap + 1, p = none;  // nothing passed yet: "infinitely" far
  for (int i = 0; i < n; ++i) {
    const int64_t at = first + step * i;
    const int v = in[at] < cap ? in[at] : cap;
    const int c = p >= i - L ? L : L + 1;  // the passed bricks' best at brick i
    if (v <= c) {
      L = v;
      p = i;
    } else {
      const int lc = last[c * lastStep];
      if (c > L) p = p > lc ? p : lc;  // c < v <= cap
      L = c;
    }
    last[v * lastStep] = Idx(i);
    if (i >= skip) {
      const uint8_t d = uint8_t(L);
      out[at] = combine && out[at] < d ? out[at] : d;
    }
  }
}

/// distancePass over a whole line in O(n) (two sweeps): out[k] = distancePass(in, k, ...) for
/// every brick k of the line of `n` bricks starting at `first` (stride `stride`). `last`:
/// scratch of cap + 1 ints, `lastStep` apart.
SS_FUNC void distanceLine(const uint8_t* in, uint8_t* out, int64_t first, int64_t stride, int n, int cap, int* last,
                          int lastStep) {
  distanceSweep(in, out, first, stride, n, 0, cap, last, lastStep, false);
  distanceSweep(in, out, first + stride * (n - 1), -stride, n, 0, cap, last, lastStep, true);
}

/// distanceLine's values on the bricks [a, b) of the line only (0 <= a < b <= n), so that
/// several threads can share one line: each sweep starts `cap` bricks before its first written
/// brick, because a brick farther than cap cannot bring a value below the cap. The segments of
/// a line computed apart equal distanceLine of the whole line.
template <class Idx>
SS_FUNC void distanceSegment(const uint8_t* in, uint8_t* out, int64_t first, int64_t stride, int n, int a, int b,
                             int cap, Idx* last, int lastStep) {
  const int s0 = a - cap > 0 ? a - cap : 0;           // forward: from s0, written from a
  const int e0 = b + cap < n ? b + cap - 1 : n - 1;   // backward: from e0, written from b - 1
  distanceSweep(in, out, first + stride * s0, stride, b - s0, a - s0, cap, last, lastStep, false);
  distanceSweep(in, out, first + stride * e0, -stride, e0 - a + 1, e0 - b + 1, cap, last, lastStep, true);
}

/// The distance field of `occ` (0 for occupied bricks, >= 1 for empty ones), oneTBB.
std::vector<uint8_t> computeDistanceField(const OccupancyGrid& occ, int cap = kMaxSkipDistance);
/// The same field computed by the CUDA backend's kernels (for the tests); throws BackendError
/// without CUDA or a usable device.
std::vector<uint8_t> computeDistanceFieldCuda(const OccupancyGrid& occ, int cap = kMaxSkipDistance);

}  // namespace spaceskip

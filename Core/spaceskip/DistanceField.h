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
/// (The passes below cost O(cap) per brick, and the jumps it allows are already long.)
constexpr int kMaxSkipDistance = 64;

/// One pass of the separable L-infinity distance transform along one axis of the brick grid:
/// out[i] = min(cap, min_j max(|j|, in[i + j*stride])) over the line through i (n bricks,
/// `pos` = i's position on it). Pass 1 reads 0 (occupied) / cap (empty); passes 2 and 3 read the
/// previous pass. Shared by the oneTBB and CUDA builds so both produce the same field.
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

/// The distance field of `occ` (0 for occupied bricks, >= 1 for empty ones), oneTBB.
std::vector<uint8_t> computeDistanceField(const OccupancyGrid& occ, int cap = kMaxSkipDistance);

}  // namespace spaceskip

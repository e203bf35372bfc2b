// 3-D Morton (z-order) codes of brick coordinates, 21 bits per axis (LBVH keys on CPU and GPU,
// KdTreeGPU order): one host/device definition for both twins.
#pragma once
#include "Macros.h"

#include <cstdint>

namespace spaceskip {

/// Spreads the low 21 bits of v so that bit i moves to bit 3i.
SS_FUNC uint64_t spreadBits3(uint64_t v) {
  v &= 0x1fffffull;
  v = (v | v << 32) & 0x1f00000000ffffull;
  v = (v | v << 16) & 0x1f0000ff0000ffull;
  v = (v | v << 8) & 0x100f00f00f00f00full;
  v = (v | v << 4) & 0x10c30c30c30c30c3ull;
  v = (v | v << 2) & 0x1249249249249249ull;
  return v;
}

SS_FUNC uint32_t compactBits3(uint64_t v) {
  v &= 0x1249249249249249ull;
  v = (v ^ (v >> 2)) & 0x10c30c30c30c30c3ull;
  v = (v ^ (v >> 4)) & 0x100f00f00f00f00full;
  v = (v ^ (v >> 8)) & 0x1f0000ff0000ffull;
  v = (v ^ (v >> 16)) & 0x1f00000000ffffull;
  v = (v ^ (v >> 32)) & 0x1fffffull;
  return uint32_t(v);
}

SS_FUNC uint64_t mortonEncode3(uint32_t x, uint32_t y, uint32_t z) {
  return spreadBits3(x) | (spreadBits3(y) << 1) | (spreadBits3(z) << 2);
}

SS_FUNC void mortonDecode3(uint64_t m, uint32_t& x, uint32_t& y, uint32_t& z) {
  x = compactBits3(m);
  y = compactBits3(m >> 1);
  z = compactBits3(m >> 2);
}

/// Bits per axis needed for coordinates in [0, n).
inline int bitsFor(int n) {
  int b = 0;
  while ((1 << b) < n) ++b;
  return b;
}

}  // namespace spaceskip

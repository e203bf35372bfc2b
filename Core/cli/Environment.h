// The one place that reads SPACESKIP_* environment variables for the tools: the CLI (Options.cpp)
// and the window benchmark (VTKModule/Testing/Cxx/SpaceSkipWindowBench.cxx). The libraries read
// none of these; they take a spaceskip::Tuning (Tuning.h). docs/tuning.md lists every variable.
#pragma once
#include "spaceskip/Parse.h"
#include "spaceskip/Tuning.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace spaceskip::cli {

/// A variable's value, or nullptr when unset or empty.
inline const char* environmentValue(const char* name) {
  const char* v = std::getenv(name);
  return v && *v ? v : nullptr;
}

/// `t` with every field whose variable is set replaced by the variable's value (read once, when
/// called; malformed values are ignored, as the old library switches ignored them):
///   SPACESKIP_CUDA_BLOCK=WxH        blockX, blockY (32..256 threads)
///   SPACESKIP_CUDA_RESIDENT=N       resident (persistent launch, N blocks per SM; 0: plain)
///   SPACESKIP_RAY_SEGMENTS=N        raySegments (1..16; 0: automatic)
///   SPACESKIP_HEAVIEST_FIRST=0      heaviestFirst off (blocks in row-major order)
///   SPACESKIP_CUDA_PARTS_SHARE=X    partsShare
///   SPACESKIP_SUB_MASKS=0           subMasks off
///   SPACESKIP_DEFER_SHADOWS=0       deferShadows off
///   SPACESKIP_SUB_MASK_MAX=N        subMaskMaxSet (0..64)
///   SPACESKIP_PART_RANGES=0         partRanges off
///   SPACESKIP_DG_CAP=N              distanceCap (1..127)
///   SPACESKIP_DG_SEGMENTS=N         distanceSegments (1..8)
///   SPACESKIP_PIECE_BIAS=X          pieceBias (in 1/255)
///   SPACESKIP_CUDA_BLEND=0          cudaBlend off
///   SPACESKIP_COMPOSITE_FULL=1      compositeFull on
inline Tuning tuningFromEnvironment(Tuning t = Tuning{}) {
  if (const char* b = environmentValue("SPACESKIP_CUDA_BLOCK")) {
    unsigned w = 0, h = 0;
    if (std::sscanf(b, "%ux%u", &w, &h) == 2 && w * h >= 32 && w * h <= 256) {
      t.blockX = int(w);
      t.blockY = int(h);
    }
  }
  if (const char* r = environmentValue("SPACESKIP_CUDA_RESIDENT")) t.resident = std::max(0, std::atoi(r));
  if (const char* s = environmentValue("SPACESKIP_RAY_SEGMENTS")) t.raySegments = std::clamp(std::atoi(s), 0, 16);
  if (const char* s = environmentValue("SPACESKIP_HEAVIEST_FIRST")) t.heaviestFirst = s[0] != '0';
  if (const char* s = environmentValue("SPACESKIP_CUDA_PARTS_SHARE")) t.partsShare = std::atof(s);
  if (const char* s = environmentValue("SPACESKIP_SUB_MASKS")) t.subMasks = s[0] != '0';
  if (const char* s = environmentValue("SPACESKIP_DEFER_SHADOWS")) t.deferShadows = s[0] != '0';
  if (const char* s = environmentValue("SPACESKIP_SUB_MASK_MAX")) t.subMaskMaxSet = std::clamp(std::atoi(s), 0, 64);
  if (const char* s = environmentValue("SPACESKIP_PART_RANGES")) t.partRanges = s[0] != '0';
  if (const char* s = environmentValue("SPACESKIP_DG_CAP")) t.distanceCap = std::clamp(std::atoi(s), 1, 127);
  if (const char* s = environmentValue("SPACESKIP_DG_SEGMENTS")) t.distanceSegments = std::max(1, std::atoi(s));
  if (const char* s = environmentValue("SPACESKIP_PIECE_BIAS")) t.pieceBias = std::atof(s);
  if (const char* s = environmentValue("SPACESKIP_CUDA_BLEND")) t.cudaBlend = s[0] != '0';
  if (const char* s = environmentValue("SPACESKIP_COMPOSITE_FULL")) t.compositeFull = s[0] == '1';
  return t;
}

/// SPACESKIP_MAX_VOLUME_BYTES (bytes, or with a K/M/G/T suffix) when set, else `fallback`.
/// Throws std::runtime_error when it is set but not a positive byte count.
inline uint64_t maxVolumeBytesFromEnvironment(uint64_t fallback) {
  const char* env = environmentValue("SPACESKIP_MAX_VOLUME_BYTES");
  if (!env) return fallback;
  uint64_t v = 0;
  if (!parseByteCount(env, v) || v == 0)
    throw std::runtime_error(std::string("SPACESKIP_MAX_VOLUME_BYTES='") + env +
                             "' is not a positive byte count (e.g. 68719476736 or 64G)");
  return v;
}

}  // namespace spaceskip::cli

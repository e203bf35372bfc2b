#include "spaceskip/HostCopy.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstring>

namespace spaceskip {

void parallelCopy(void* dst, const void* src, size_t bytes) {
  // 1 MiB pieces: a 32 MiB staging chunk (HostStaging) is 32 of them, work for every thread of a
  // 16-core host.
  constexpr size_t kPiece = size_t(1) << 20;
  const size_t pieces = (bytes + kPiece - 1) / kPiece;
  if (pieces <= 1) {
    if (bytes) std::memcpy(dst, src, bytes);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pieces), [&](const tbb::blocked_range<size_t>& r) {
    const size_t b = r.begin() * kPiece, e = std::min(bytes, r.end() * kPiece);
    std::memcpy(static_cast<char*>(dst) + b, static_cast<const char*>(src) + b, e - b);
  });
}

}  // namespace spaceskip

// A large host-to-host copy spread over oneTBB's threads: the CUDA backend fills its pinned
// staging buffers with it (one thread's memcpy moves a fraction of what the host link can take).
#pragma once
#include <cstddef>

namespace spaceskip {

/// memcpy(dst, src, bytes) in pieces of 1 MiB on oneTBB's threads.
void parallelCopy(void* dst, const void* src, size_t bytes);

}  // namespace spaceskip

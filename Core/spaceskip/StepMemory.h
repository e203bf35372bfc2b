// Host memory for time steps that the CUDA backend uploads in one DMA (Engine::allocateStepMemory).
// Internal to Core.
#pragma once
#include <cstddef>
#include <memory>

namespace spaceskip {

/// Page-locked host memory of `bytes` (cudaMallocHost, freed by the pointer's deleter), or
/// nullptr where none can be had or this build has no CUDA.
std::shared_ptr<unsigned char> allocatePageLocked(size_t bytes);

}  // namespace spaceskip

// Host memory for time steps that the CUDA backend uploads in one DMA (Engine::allocateStepMemory).
// Used by the engine and by the VTK mapper's time-step arrays (NewTimeStepArray).
#pragma once
#include <cstddef>
#include <memory>

namespace spaceskip {

/// Page-locked host memory of `bytes` (cudaMallocHost, freed by the pointer's deleter), or
/// nullptr where none can be had or this build has no CUDA.
std::shared_ptr<unsigned char> allocatePageLocked(size_t bytes);

/// The same without an owner, for a container that releases its memory through a plain
/// function (vtkDataArray's free function): nullptr as above; release it with freePageLocked.
void* allocatePageLockedRaw(size_t bytes);
/// Releases what allocatePageLockedRaw returned (nothing for nullptr).
void freePageLocked(void* p);

}  // namespace spaceskip

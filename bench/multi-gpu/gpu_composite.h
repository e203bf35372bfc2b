// The multi-GPU driver's blend of the ranks' images, one function for the host path
// (mpi_pieces.cpp) and the GPU path's kernel (gpu_composite.cu); no CUDA types.
#pragma once
#include "spaceskip/PeerImages.h"

#include <cstddef>

namespace spaceskip::mpi {

/// Premultiplied front-to-back "over" (spaceskip::addBehind, the product's piece blend):
/// `back` added where `front` still lets light through.
SS_FUNC vec4f behind(vec4f front, vec4f back) {
  addBehind(front, back, 2.f);
  return front;
}

constexpr int kMaxRanks = 16;

/// The ranks' images (float4 premultiplied RGBA, device pointers mapped in this process) and the
/// visibility order to blend them in (front first).
struct BandSources {
  const void* src[kMaxRanks];
  int order[kMaxRanks];
};

/// Queues on `stream` (a cudaStream_t) the blend of pixels [first, first + count) of the `n`
/// images in `s.order` into the same pixels of `dst` (a float4 device pointer, possibly another
/// GPU's memory mapped through IPC). Returns the cudaError_t as an int (0: queued).
int launchBandBlend(const BandSources& s, int n, void* dst, size_t first, size_t count, void* stream);

}  // namespace spaceskip::mpi

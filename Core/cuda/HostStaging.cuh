// Host-to-device copies of large pageable buffers (the caller's voxels: a time step) through a
// ring of pinned chunks.
#pragma once
#include "CudaCommon.cuh"

namespace spaceskip::cuda {

/// The host fills one pinned chunk on oneTBB's threads (parallelCopy) while the copy engine moves
/// the ones before it, so the copy runs near the link's pinned rate where the driver's own staging
/// of pageable memory (one thread) does not (measured on the H200 host: 5-9 GB/s pageable, 55 GB/s
/// pinned; two 32 MiB chunks: 33 GB/s for 128 MiB, 47-52 GB/s for 0.5-4 GiB). Chunks of 8 MiB
/// (four) were slower, 22-29 GB/s: each chunk's wait and the threads' wake-up cost about as much
/// as its copy. Falls back to a plain cudaMemcpyAsync when no pinned memory can be had. A source
/// that is page-locked already (Engine::allocateStepMemory) goes in one cudaMemcpyAsync.
class HostStaging {
 public:
  static constexpr size_t kChunk = size_t(32) << 20;
  static constexpr int kChunks = 3;
  /// A page-locked source's DMA pieces.
  static constexpr size_t kPinnedPiece = size_t(8) << 20;
  HostStaging() = default;
  ~HostStaging();
  HostStaging(const HostStaging&) = delete;
  HostStaging& operator=(const HostStaging&) = delete;
  /// Copies `bytes` from host `src` to device `dst` in `stream`'s order. Returns when the host
  /// side is done; the device side finishes in `stream`. `src` may change on return where it
  /// is pageable, and once `stream` has finished the copy where it is page-locked.
  void copy(void* dst, const void* src, size_t bytes, cudaStream_t stream);
  /// Whether the driver knows `src` as page-locked host memory.
  static bool pageLocked(const void* src);

 private:
  PinnedBuffer chunk_[kChunks];
  cudaEvent_t done_[kChunks] = {};
};

}  // namespace spaceskip::cuda

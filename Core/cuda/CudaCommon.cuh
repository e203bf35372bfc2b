// Error checking and device buffers shared by the CUDA backend and the GPU builders.
// Every CUDA call goes through SS_CUDA_CHECK: a failure becomes a BackendError (the Engine falls
// back to the CPU backend), never an abort.
#pragma once
#include "spaceskip/Tuning.h"
#include "spaceskip/Types.h"

#include <cuda_runtime.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <utility>

namespace spaceskip::cuda {

[[noreturn]] inline void throwCuda(cudaError_t e, const char* what, const char* file, int line) {
  // Clear the sticky-free part of the error state so a later call is not poisoned by this one.
  (void)cudaGetLastError();
  std::string msg = std::string("CUDA error in ") + what + " (" + file + ":" + std::to_string(line) +
                    "): " + cudaGetErrorName(e) + ": " + cudaGetErrorString(e);
  if (e == cudaErrorMemoryAllocation) msg = "device out of memory: " + msg;
  throw BackendError(msg);
}

#define SS_CUDA_CHECK(call)                                                             \
  do {                                                                                  \
    cudaError_t ss_err_ = (call);                                                       \
    if (ss_err_ != cudaSuccess) ::spaceskip::cuda::throwCuda(ss_err_, #call, __FILE__, __LINE__); \
  } while (0)

/// After a kernel launch: catches bad launch configurations at once (errors raised while the
/// kernel runs surface at the next synchronizing call, which is checked too).
#define SS_CUDA_CHECK_LAUNCH(name) SS_CUDA_CHECK(cudaPeekAtLastError())

/// Device bytes currently held by SpaceSkip's allocations (every device allocation goes through
/// deviceMalloc/deviceMalloc3DArray; CUB's temporary storage too, via DeviceBuffer).
inline std::atomic<int64_t>& liveDeviceBytes() {
  static std::atomic<int64_t> bytes{0};
  return bytes;
}

/// Testing aid (spaceskip::testing::setDeviceMemoryLimit, Tuning.h): caps the device memory
/// SpaceSkip may hold; an allocation that would exceed it fails with cudaErrorMemoryAllocation,
/// exactly as a real out-of-memory does (so the "volume too large for the device" fallback can
/// be tested on any GPU). Negative: no cap.
inline int64_t deviceMemoryLimit() { return ::spaceskip::testing::deviceMemoryLimit(); }

/// Testing aid (spaceskip::testing::setFailRender, Tuning.h): every render launch reports
/// cudaErrorLaunchFailure, a CUDA error in the middle of a frame, so that the fallback to the CPU
/// backend's image can be tested on any GPU (TestCuda.cpp).
inline cudaError_t injectedRenderError() {
  return ::spaceskip::testing::failRender() ? cudaErrorLaunchFailure : cudaSuccess;
}

inline bool overDeviceMemoryLimit(size_t bytes) {
  const int64_t limit = deviceMemoryLimit();
  return limit >= 0 && (bytes > uint64_t(limit) || liveDeviceBytes().load() + int64_t(bytes) > limit);
}

/// cudaMalloc, counted and capped by the testing limit (deviceMemoryLimit).
inline cudaError_t deviceMalloc(void** p, size_t bytes) {
  *p = nullptr;
  if (overDeviceMemoryLimit(bytes)) return cudaErrorMemoryAllocation;
  const cudaError_t e = cudaMalloc(p, bytes);
  if (e == cudaSuccess) liveDeviceBytes() += int64_t(bytes);
  return e;
}
inline void deviceFree(void* p, size_t bytes) {
  if (!p) return;
  cudaFree(p);  // no check: called from destructors
  liveDeviceBytes() -= int64_t(bytes);
}

/// cudaMalloc3DArray, counted (width*height*depth elements of the channel size) and capped likewise.
inline cudaError_t deviceMalloc3DArray(cudaArray_t* a, const cudaChannelFormatDesc* desc, cudaExtent e,
                                       size_t& bytes) {
  *a = nullptr;
  bytes = e.width * e.height * e.depth * size_t((desc->x + desc->y + desc->z + desc->w) / 8);
  if (overDeviceMemoryLimit(bytes)) return cudaErrorMemoryAllocation;
  const cudaError_t r = cudaMalloc3DArray(a, desc, e);
  if (r == cudaSuccess) liveDeviceBytes() += int64_t(bytes);
  return r;
}
inline void deviceFreeArray(cudaArray_t a, size_t bytes) {
  if (!a) return;
  cudaFreeArray(a);
  liveDeviceBytes() -= int64_t(bytes);
}

/// A plain cudaMalloc'd array (no managed memory); grows only, never shrinks.
template <class T>
class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  explicit DeviceBuffer(size_t n) { reserve(n); }
  ~DeviceBuffer() { release(); }
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  DeviceBuffer(DeviceBuffer&& o) noexcept { swap(o); }
  DeviceBuffer& operator=(DeviceBuffer&& o) noexcept {
    swap(o);
    return *this;
  }

  /// Ensures room for n elements; old contents are not kept.
  void reserve(size_t n) {
    if (n <= cap_ && ptr_) return;
    release();
    if (n == 0) return;
    void* p = nullptr;
    SS_CUDA_CHECK(deviceMalloc(&p, n * sizeof(T)));
    ptr_ = static_cast<T*>(p);
    cap_ = n;
  }
  void release() {
    deviceFree(ptr_, cap_ * sizeof(T));
    ptr_ = nullptr;
    cap_ = 0;
  }
  T* get() const { return ptr_; }
  size_t capacity() const { return cap_; }
  void swap(DeviceBuffer& o) noexcept {
    std::swap(ptr_, o.ptr_);
    std::swap(cap_, o.cap_);
  }

 private:
  T* ptr_ = nullptr;
  size_t cap_ = 0;
};

/// Raw temporary storage for CUB algorithms (grown on demand).
struct TempStorage {
  DeviceBuffer<unsigned char> bytes;
  void* ensure(size_t n) {
    bytes.reserve(n < 1 ? 1 : n);
    return bytes.get();
  }
};

/// Owned handles: created by the constructor (SS_CUDA_CHECKed), destroyed unchecked.
class Stream {
 public:
  Stream() { SS_CUDA_CHECK(cudaStreamCreateWithFlags(&s_, cudaStreamNonBlocking)); }
  ~Stream() {
    if (s_) cudaStreamDestroy(s_);
  }
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;
  operator cudaStream_t() const { return s_; }

 private:
  cudaStream_t s_ = nullptr;
};

class Event {
 public:
  Event() { SS_CUDA_CHECK(cudaEventCreate(&e_)); }
  ~Event() {
    if (e_) cudaEventDestroy(e_);
  }
  Event(const Event&) = delete;
  Event& operator=(const Event&) = delete;
  operator cudaEvent_t() const { return e_; }

 private:
  cudaEvent_t e_ = nullptr;
};

/// Pinned host memory (cudaMallocHost): fast DMA to and from the device.
class PinnedBuffer {
 public:
  PinnedBuffer() = default;
  ~PinnedBuffer() { release(); }
  PinnedBuffer(const PinnedBuffer&) = delete;
  PinnedBuffer& operator=(const PinnedBuffer&) = delete;
  /// Ensures room for `bytes` (old contents are not kept); throws BackendError when it cannot.
  void reserve(size_t bytes) { SS_CUDA_CHECK(tryReserve(bytes)); }
  /// As reserve(), but reports a failure (cleared, the buffer left empty) instead of throwing.
  cudaError_t tryReserve(size_t bytes) {
    if (bytes_ >= bytes && p_) return cudaSuccess;
    release();
    const cudaError_t e = cudaMallocHost(&p_, bytes);
    if (e != cudaSuccess) {
      (void)cudaGetLastError();
      p_ = nullptr;
      return e;
    }
    bytes_ = bytes;
    return cudaSuccess;
  }
  void release() {
    if (p_) cudaFreeHost(p_);
    p_ = nullptr;
    bytes_ = 0;
  }
  void* get() const { return p_; }

 private:
  void* p_ = nullptr;
  size_t bytes_ = 0;
};

inline unsigned blocksFor(int64_t n, int threads) { return unsigned((n + threads - 1) / threads); }

}  // namespace spaceskip::cuda

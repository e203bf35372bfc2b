// Error checking and device buffers shared by the CUDA backend and the GPU builders.
// Every CUDA call goes through SS_CUDA_CHECK: a failure becomes a BackendError (the Engine falls
// back to the CPU backend), never an abort.
#pragma once
#include "spaceskip/Engine.h"

#include <cuda_runtime.h>

#include <cstddef>
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
    SS_CUDA_CHECK(cudaMalloc(&p, n * sizeof(T)));
    ptr_ = static_cast<T*>(p);
    cap_ = n;
  }
  void release() {
    if (ptr_) cudaFree(ptr_);  // no check: called from destructors
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

inline unsigned blocksFor(int64_t n, int threads) { return unsigned((n + threads - 1) / threads); }

}  // namespace spaceskip::cuda

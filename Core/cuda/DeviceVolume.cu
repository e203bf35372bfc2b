// Volume upload and the hardware-filtered texture made from the device copy.
#include "DeviceVolume.cuh"
#include "HostStaging.cuh"
#include "spaceskip/Backend.h"  // parallelCopy

#include <algorithm>

#include <limits>
#include <type_traits>

namespace spaceskip::cuda {

namespace {

constexpr int kThreads = 256;

// Launch shape: one thread per voxel, 256 per block. double -> float (textures have no double channel).
__global__ void toFloatKernel(const double* in, float* out, int64_t n) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n) out[i] = float(in[i]);
}

}  // namespace

void DeviceVolume::upload(const Volume& v, cudaStream_t stream) {
  destroyTexture();
  volume_ = v;
  volume_.storage.reset();  // the Engine keeps the voxels alive; we keep the device copy
  const size_t bytes = v.byteSize();
  // The allocation is kept when it fits (a time step of the same size: no free, no malloc).
  if (d_voxels_.capacity() < bytes || d_voxels_.capacity() > 2 * bytes) d_voxels_.release();
  d_voxels_.reserve(bytes);
  if (!staging_) staging_ = std::make_unique<HostStaging>();
  staging_->copy(d_voxels_.get(), v.data, bytes, stream);
}

void DeviceVolume::setWarp(const Volume& v, cudaStream_t stream) {
  warpView_ = AxisWarpView{};
  warpHost_ = v.warp;
  if (!v.warp) return;
  // One buffer: the three coordinate tables (float), then the three cell tables (int32).
  size_t n = 0;
  for (int a = 0; a < 3; ++a) n += v.warp->c[a].size();
  d_warp_.reserve(n * (sizeof(float) + sizeof(int32_t)));
  unsigned char* base = d_warp_.get();
  size_t off = 0;
  for (int a = 0; a < 3; ++a) {
    const size_t bytes = v.warp->c[a].size() * sizeof(float);
    SS_CUDA_CHECK(cudaMemcpyAsync(base + off, v.warp->c[a].data(), bytes, cudaMemcpyHostToDevice, stream));
    warpView_.c[a] = reinterpret_cast<const float*>(base + off);
    warpView_.n[a] = int32_t(v.warp->c[a].size());
    off += bytes;
  }
  for (int a = 0; a < 3; ++a) {
    const size_t bytes = v.warp->cell[a].size() * sizeof(int32_t);
    SS_CUDA_CHECK(cudaMemcpyAsync(base + off, v.warp->cell[a].data(), bytes, cudaMemcpyHostToDevice, stream));
    warpView_.cell[a] = reinterpret_cast<const int32_t*>(base + off);
    off += bytes;
  }
}

DeviceVolume::DeviceVolume() = default;
DeviceVolume::~DeviceVolume() { destroyTexture(); }

void HostStaging::copy(void* dst, const void* src, size_t bytes, cudaStream_t stream) {
  if (pageLocked(src)) {
    // DMAs straight from the caller's memory, in pieces: another stream's small host-to-device
    // copy (a classification's table) waits for the piece on the copy engine, not the whole step.
    for (size_t off = 0; off < bytes; off += kPinnedPiece)
      SS_CUDA_CHECK(cudaMemcpyAsync(static_cast<char*>(dst) + off, static_cast<const char*>(src) + off,
                                    std::min(kPinnedPiece, bytes - off), cudaMemcpyHostToDevice, stream));
    return;
  }
  if (bytes < 2 * kChunk) {  // small: the driver's own staging is as fast
    SS_CUDA_CHECK(cudaMemcpyAsync(dst, src, bytes, cudaMemcpyHostToDevice, stream));
    return;
  }
  for (int b = 0; b < kChunks; ++b) {
    if (chunk_[b].get() == nullptr && chunk_[b].tryReserve(kChunk) != cudaSuccess) {
      // No pinned memory to be had: the plain (pageable) copy.
      SS_CUDA_CHECK(cudaMemcpyAsync(dst, src, bytes, cudaMemcpyHostToDevice, stream));
      return;
    }
    if (!done_[b]) SS_CUDA_CHECK(cudaEventCreateWithFlags(&done_[b], cudaEventDisableTiming));
  }
  // The chunks in turn: a chunk is refilled once its last copy (of this call or the one before)
  // has finished (its event; an event never recorded is complete).
  size_t k = 0;
  for (size_t off = 0; off < bytes; off += kChunk, ++k) {
    const int b = int(k % kChunks);
    const size_t n = std::min(kChunk, bytes - off);
    SS_CUDA_CHECK(cudaEventSynchronize(done_[b]));
    parallelCopy(chunk_[b].get(), static_cast<const char*>(src) + off, n);
    SS_CUDA_CHECK(cudaMemcpyAsync(static_cast<char*>(dst) + off, chunk_[b].get(), n, cudaMemcpyHostToDevice, stream));
    SS_CUDA_CHECK(cudaEventRecord(done_[b], stream));
  }
}

bool HostStaging::pageLocked(const void* src) {
  cudaPointerAttributes a{};
  if (cudaPointerGetAttributes(&a, src) != cudaSuccess) {
    (void)cudaGetLastError();
    return false;
  }
  return a.type == cudaMemoryTypeHost;  // cudaMallocHost or cudaHostRegister (Engine::allocateStepMemory)
}

HostStaging::~HostStaging() {
  for (cudaEvent_t& e : done_)
    if (e) {
      cudaEventSynchronize(e);
      cudaEventDestroy(e);
    }
}

void DeviceVolume::describe(const Volume& v) {
  destroyTexture();
  volume_ = v;
  volume_.storage.reset();
  d_voxels_.release();
}

TextureSampler DeviceVolume::texture(cudaStream_t stream) {
  if (tex_) return TextureSampler{tex_, texScale_};
  destroyTexture();  // an array left by an earlier attempt that failed after allocating it
  cudaChannelFormatDesc desc{};
  cudaTextureReadMode mode = cudaReadModeNormalizedFloat;
  const void* src = d_voxels_.get();
  size_t elem = voxelSize(volume_.type);
  DeviceBuffer<float> converted;
  dispatchVoxelType(volume_.type, [&](auto t) {
    using T = decltype(t);
    if constexpr (std::is_integral_v<T>) {
      // Normalized reads, scaled back by the type's max (255, 127, 65535, 32767).
      desc = cudaCreateChannelDesc<T>();
      texScale_ = float(std::numeric_limits<T>::max());
    } else {
      desc = cudaCreateChannelDesc<float>();
      mode = cudaReadModeElementType;
      texScale_ = 1.f;
      if constexpr (std::is_same_v<T, double>) {
        const int64_t n = volume_.voxelCount();
        converted.reserve(size_t(n));
        toFloatKernel<<<blocksFor(n, kThreads), kThreads, 0, stream>>>(d_voxels<double>(), converted.get(), n);
        SS_CUDA_CHECK_LAUNCH(toFloatKernel);
        src = converted.get();
        elem = sizeof(float);
      }
    }
  });
  const cudaExtent extent = make_cudaExtent(size_t(volume_.dims.x), size_t(volume_.dims.y), size_t(volume_.dims.z));
  SS_CUDA_CHECK(deviceMalloc3DArray(&array_, &desc, extent, arrayBytes_));
  cudaMemcpy3DParms copy{};
  copy.srcPtr = make_cudaPitchedPtr(const_cast<void*>(src), size_t(volume_.dims.x) * elem, size_t(volume_.dims.x),
                                    size_t(volume_.dims.y));
  copy.dstArray = array_;
  copy.extent = extent;
  copy.kind = cudaMemcpyDeviceToDevice;
  SS_CUDA_CHECK(cudaMemcpy3DAsync(&copy, stream));
  SS_CUDA_CHECK(cudaStreamSynchronize(stream));
  cudaResourceDesc res{};
  res.resType = cudaResourceTypeArray;
  res.res.array.array = array_;
  cudaTextureDesc td{};
  td.addressMode[0] = td.addressMode[1] = td.addressMode[2] = cudaAddressModeClamp;
  td.filterMode = cudaFilterModeLinear;
  td.readMode = mode;
  td.normalizedCoords = 0;
  SS_CUDA_CHECK(cudaCreateTextureObject(&tex_, &res, &td, nullptr));
  return TextureSampler{tex_, texScale_};
}

void DeviceVolume::destroyTexture() {
  if (tex_) cudaDestroyTextureObject(tex_);
  deviceFreeArray(array_, arrayBytes_);
  tex_ = 0;
  array_ = nullptr;
  arrayBytes_ = 0;
}

}  // namespace spaceskip::cuda

// A volume in device memory: the voxels as uploaded (exact sampling reads them) and, made on first
// use, a 3-D texture with hardware trilinear filtering.
#pragma once
#include "CudaCommon.cuh"
#include "spaceskip/Volume.h"
#include "spaceskip/render/FrameShared.h"

#include <memory>

namespace spaceskip::cuda {

/// Hardware-filtered sampling: a 3-D texture with linear filtering. Integer types are read as
/// normalized floats and scaled back to raw values so the TF mapping is the same as in exact mode.
struct TextureSampler {
  /// Samples a march fetches per step (SamplerBatch, Integrator.h): one texture instruction a
  /// sample, so four in flight cost few registers.
  static constexpr int kBatch = kMaxSampleBatch;
  cudaTextureObject_t tex;
  float scale;
  __device__ float sample(vec3f p) const { return tex3D<float>(tex, p.x + 0.5f, p.y + 0.5f, p.z + 0.5f) * scale; }
};

class HostStaging;  // HostStaging.cuh

class DeviceVolume {
 public:
  DeviceVolume();
  ~DeviceVolume();
  DeviceVolume(const DeviceVolume&) = delete;
  DeviceVolume& operator=(const DeviceVolume&) = delete;

  /// Copies `v`'s voxels to the device, asynchronously on `stream`; drops the texture of the last
  /// volume. Keeps `v`'s description, not its host voxels (the caller keeps those alive).
  void upload(const Volume& v, cudaStream_t stream);
  /// Keeps `v`'s description only and frees the device voxels (sparse residency: DevicePool
  /// holds what is resident).
  void describe(const Volume& v);
  /// The description of the volume (its `data` is the caller's host pointer).
  const Volume& volume() const { return volume_; }
  /// The voxels on the device, as `T` (the C++ type of volume().type).
  template <class T>
  const T* d_voxels() const {
    return static_cast<const T*>(static_cast<const void*>(d_voxels_.get()));
  }
  /// The texture, made from the device copy on first use (synchronizes `stream` then).
  TextureSampler texture(cudaStream_t stream);
  /// Bytes of the texture's array (0 before texture()).
  size_t textureBytes() const { return arrayBytes_; }
  /// The device copy of `v`'s warp tables (a rectilinear grid, AxisWarp.h), queued on `stream`;
  /// none for an image.
  void setWarp(const Volume& v, cudaStream_t stream);
  /// The warp as the samplers read it on the device (off for an image).
  AxisWarpView warp() const { return warpView_; }

 private:
  void destroyTexture();

  Volume volume_;
  DeviceBuffer<unsigned char> d_voxels_;
  std::unique_ptr<HostStaging> staging_;  ///< made on the first upload
  cudaArray_t array_ = nullptr;
  size_t arrayBytes_ = 0;
  cudaTextureObject_t tex_ = 0;
  float texScale_ = 1.f;
  DeviceBuffer<unsigned char> d_warp_;
  AxisWarpView warpView_{};
  std::shared_ptr<const AxisWarp> warpHost_;  ///< the host tables, alive while their copy is queued
};

}  // namespace spaceskip::cuda

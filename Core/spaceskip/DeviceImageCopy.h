// CUDA-GL interop: the engine's device image (Engine::deviceImage) into a mapped GL texture.
// No CUDA types here: the VTK module includes it without nvcc.
#pragma once
#include <memory>

namespace spaceskip {

class DeviceImageCopy {
 public:
  DeviceImageCopy();
  ~DeviceImageCopy();  ///< waits for the copies still queued (it owns their scratch memory)
  DeviceImageCopy(const DeviceImageCopy&) = delete;
  DeviceImageCopy& operator=(const DeviceImageCopy&) = delete;

  /// Queues on `stream` (a cudaStream_t; Engine::deviceImageStream()) the copy of the pixels
  /// [x0, x0 + w) x [y0, y0 + h) of `image` (float4 premultiplied RGBA, `imageWidth` x
  /// `imageHeight` pixels, row 0 at the bottom) to the same pixels of `array` (a cudaArray_t: a mapped GL texture)
  /// of float4 texels, or with `eightBit` of RGBA8 texels rounded as the mapper's host path
  /// rounds (clamp to [0, 1], v * 255 + 0.5 truncated). Returns the cudaError_t as an int (0:
  /// queued); without CUDA, 1 (cudaErrorInvalidValue).
  int copy(const void* image, int imageWidth, int imageHeight, void* array, int x0, int y0, int w, int h,
           bool eightBit, void* stream);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace spaceskip

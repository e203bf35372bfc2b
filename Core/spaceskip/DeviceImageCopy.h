// CUDA-GL interop: the engine's device image (Engine::deviceImage) into a mapped GL texture, or
// blended straight into a mapped framebuffer texture.
// No CUDA types here: the VTK module includes it without nvcc.
#pragma once
#include "render/SegmentLayers.h"

#include <memory>

namespace spaceskip {

/// A frame's image in device memory (Engine::deviceImageView): the flat image (float4
/// premultiplied RGBA), or, while a segmented frame's layers are not yet composited into it,
/// those layers (`layers.layers` set; `image` then holds no valid pixels).
struct DeviceImageView {
  const void* image = nullptr;
  SegmentLayersView layers;
};

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

  /// Queues on `stream` the blend of the pixels [x0, x0 + w) x [y0, y0 + h) of `image` (as in
  /// copy()) over the pixels [x0 + dx, x0 + dx + w) x [y0 + dy, y0 + dy + h) of `array` (a
  /// cudaArray_t of RGBA8 texels, `arrayWidth` x `arrayHeight`, usable as a surface: a mapped GL
  /// framebuffer texture registered for surface load/store), as GL blends premultiplied colour
  /// with (ONE, ONE_MINUS_SRC_ALPHA) into an 8-bit normalized buffer: per channel
  /// d' = s + d (1 - s_alpha) rounded to the nearest 1/255, the source s rounded to 8 bits first
  /// with `eightBit` (what the GL path's RGBA8 texture holds), else clamped to [0, 1]; pixels of
  /// transparent black are left unwritten (d' = d). Returns the cudaError_t as an int (0: queued;
  /// without CUDA, 1).
  int blendOver(const void* image, int imageWidth, int imageHeight, void* array, int arrayWidth, int arrayHeight,
                int x0, int y0, int w, int h, int dx, int dy, bool eightBit, void* stream);
  /// The same from a view: with layers, each pixel composited from them as it is blended
  /// (compositeLayers: the same colour as the flat image), so the flat image is never written.
  int blendOver(const DeviceImageView& image, int imageWidth, int imageHeight, void* array, int arrayWidth,
                int arrayHeight, int x0, int y0, int w, int h, int dx, int dy, bool eightBit, void* stream);

  /// Forgets the surface blendOver() made for its last array (waiting for the blends still
  /// queued): call before that array's texture is unregistered or reallocated.
  void releaseSurface();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace spaceskip

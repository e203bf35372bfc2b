// Float images of several processes of one host, composited on the GPU: PeerImages shares this
// process's frame and maps the others' (CUDA IPC); PieceBlend blends pieces front to back into an
// image in device memory. The processes' float compositing under MPI (ParaView's ranks, one per
// GPU) then moves no pixels through host memory.
// No CUDA types here: the VTK module and the plugin include it without nvcc.
#pragma once
#include "spaceskip/Math.h"

#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace spaceskip {

/// Front-to-back premultiplied "over": `src` added behind `acc` unless `acc`'s ray has stopped
/// (its opacity reached `stopAt`, the early ray termination threshold; above 1: never). One
/// function for the pieces' blend on the host (the VTK module's piece compositing) and on the
/// device (PieceBlend).
SS_FUNC void addBehind(vec4f& acc, const vec4f& src, float stopAt) {
  if (acc.w >= stopAt) return;
  const float t = 1.f - acc.w;
  acc.x += t * src.x;
  acc.y += t * src.y;
  acc.z += t * src.z;
  acc.w += t * src.w;
}

/// A piece for PieceBlend: the rectangle [x, x + w) x [y, y + h) of the viewport, premultiplied
/// RGBA floats (float4), pixel (x + i, y + j) at pixels[j * rowPixels + i]. `pixels` lies in
/// device memory readable on the calling thread's device (this process's, or another process's
/// mapped by PeerImages::map) unless `host`; host pieces are uploaded first.
struct BlendSource {
  const void* pixels = nullptr;
  size_t rowPixels = 0;
  int x = 0, y = 0, w = 0, h = 0;
  bool host = false;
};

/// This process's frame shared with the other processes of the host (CUDA IPC), and theirs
/// mapped into it. Every call works on the calling thread's current CUDA device; each returns
/// false (nullptr) with `problem` set instead of throwing. Without CUDA every call fails.
class PeerImages {
 public:
  using Handle = std::array<char, 64>;  ///< a cudaIpcMemHandle_t's bytes
  PeerImages();
  ~PeerImages();  ///< unmaps the others' buffers, frees its own
  PeerImages(const PeerImages&) = delete;
  PeerImages& operator=(const PeerImages&) = delete;

  /// Copies `pixels` float4 of device memory (written on `stream`, a cudaStream_t) into this
  /// process's exchange buffer (allocated on the current device, grown as needed, never shrunk)
  /// and waits for the copy; `handle` then names the buffer to the other processes.
  bool share(const void* image, size_t pixels, void* stream, Handle& handle, std::string& problem);

  /// The buffer `handle` names (another process's share()), mapped for the current device, kept
  /// mapped under `slot` until a different handle comes for that slot; nullptr with `problem`.
  const void* map(int slot, const Handle& handle, std::string& problem);

  /// Copies `pixels` float4 from device memory (own or mapped) to `host`, and waits.
  static bool download(const void* device, size_t pixels, float* host, std::string& problem);

  /// Waits for the work queued on `stream` (a cudaStream_t).
  static bool wait(void* stream, std::string& problem);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Blends pieces front to back (addBehind, each pixel in the given order) into a `width` x
/// `height` float4 image in device memory on the current device; the result stays valid until
/// the next blend.
class PieceBlend {
 public:
  PieceBlend();
  ~PieceBlend();
  PieceBlend(const PieceBlend&) = delete;
  PieceBlend& operator=(const PieceBlend&) = delete;

  /// Queues on `stream` (a cudaStream_t) the upload of the host pieces and the blend of
  /// `frontToBack` (pieces outside the viewport are clipped to it); returns the image (row 0 at
  /// the bottom) or nullptr with `problem`.
  const void* blend(const std::vector<BlendSource>& frontToBack, int width, int height, float stopAt,
                    void* stream, std::string& problem);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace spaceskip

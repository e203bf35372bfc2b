// The CUDA executor of Core's shared renderPixel: one thread per pixel over tiles (plain or
// persistent launch), exact or hardware-filtered sampling, the frame's device buffers and the
// image's way back (a pinned staging copy, or left on the device for CUDA-GL interop).
#pragma once
#include "DeviceVolume.cuh"
#include "spaceskip/BrickPool.h"
#include "spaceskip/DeviceImageCopy.h"
#include "spaceskip/Tuning.h"
#include "spaceskip/Types.h"
#include "spaceskip/render/Integrator.h"

#include <vector>

namespace spaceskip::cuda {

/// Threads in a render block at most (Tuning::blockX x blockY; the kernels' launch bounds).
constexpr int kMaxRenderThreads = 256;

/// A plain launch's blocks in the order they start (Tuning::heaviestFirst): block b (linear
/// index, x fastest, then y, then the segment z) renders unit order[b] of the same grid; each
/// unit's SM clock cycles go to cost, indexed by its tile on the whole frame's tile grid
/// (originX/Y: the launch's first tile there; wholeX tiles a row), so that the next frame, whose
/// box may project onto other tiles, finds them. order and cost nullptr: row-major.
struct TileOrder {
  const unsigned* order = nullptr;
  unsigned* cost = nullptr;
  int originX = 0, originY = 0, wholeX = 0;

  /// Unit u of a launch of `grid`: its tile (tx, ty) in the launch and its segment.
  __host__ __device__ static void unit(unsigned u, dim3 grid, unsigned& tx, unsigned& ty, unsigned& segment) {
    const unsigned perSegment = grid.x * grid.y, r = u % perSegment;
    tx = r % grid.x;
    ty = r / grid.x;
    segment = u / perSegment;
  }
  /// Where the cycles of unit u of a launch of `grid` go: rows of wholeX tiles of the whole
  /// frame, the segments of a tile side by side (the index does not depend on the frame's height).
  __host__ __device__ size_t costIndex(unsigned u, dim3 grid) const {
    unsigned tx, ty, segment;
    unit(u, grid, tx, ty, segment);
    return wholeCostIndex(tx + unsigned(originX), ty + unsigned(originY), segment, grid.z);
  }
  /// Where the cycles of tile (x, y) of the whole frame and its segment go.
  __host__ __device__ size_t wholeCostIndex(unsigned x, unsigned y, unsigned segment, unsigned segments) const {
    return (size_t(y) * size_t(wholeX) + x) * segments + segment;
  }
};

class CudaExecutor {
 public:
  /// Reads the SM count.
  CudaExecutor();

  /// The launch knobs (blockX/Y, resident, raySegments) of the frames after this call.
  void setTuning(const Tuning& t) { tuning_ = t; }
  /// The (opacity-corrected) table the integrator samples, copied on `stream` through a pinned
  /// staging buffer (no host wait; the frames after it on `stream` read it).
  void setTransferTable(const std::vector<vec4f>& table, float lo, float scale, cudaStream_t stream);
  /// Renders `f` (grid and tree pointing at device memory; the table and depth filled here) from
  /// `vol` into `out`, or only sizes `out` and leaves the image in deviceImage() (setImageOnDevice).
  /// With a `pool` (sparse residency, device pointers) the voxels are read through it, exactly.
  void render(FrameView f, FilterMode filter, const float* depth, DeviceVolume& vol, const PoolView* pool,
              Image& out, cudaStream_t stream);

  bool setImageOnDevice(bool on) {
    imageOnDevice_ = on;
    deviceImageValid_ = false;
    return true;
  }
  /// The last frame's image in device memory (setImageOnDevice), or nullptr. A segmented frame's
  /// layers still pending are composited into it first (queued on the frame's stream).
  const void* deviceImage() const;
  /// The same frame as deviceImage(), but a segmented frame's layers are not composited: the
  /// view holds them instead (a reader that composites as it reads: DeviceImageCopy::blendOver).
  DeviceImageView deviceImageView() const;
  bool hasDeviceImage() const { return deviceImageValid_; }
  /// The last frame's kernel time (CUDA events). A frame left on the device is not waited for by
  /// render(): this waits for it, the first time it is asked.
  double lastFrameDeviceSeconds() const;
  /// Shadow rays the last frame queued (those its queue held), waiting for the frame.
  int64_t lastFrameQueuedShadowRays() const;
  /// The longest block of the frame before the last (the first of tileOrder's sorted keys: the
  /// most cycles among the last frame's units of this launch and their neighbours), by the SM
  /// clock, in seconds; -1 where the last frame had no order (heaviestFirst off, or no
  /// frame of its shape before). Waits for the frame.
  double lastFrameLongestBlockSeconds() const;

 private:
  /// Queues the composite of layers_ (a segmented frame's, when set) into d_image_ on stream_.
  void compositeLayers() const;
  template <class Sampler>
  void launch(const FrameView& f, const Sampler& s, dim3 grid, dim3 block, size_t textureBytes, cudaStream_t stream);
  /// The order of a plain launch of `grid` (z: segments) whose first tile is (originX, originY)
  /// of the whole frame's wholeX x wholeY tiles: the units by the most cycles they or their 8
  /// neighbouring tiles took in the last frame, longest first (a gather and a CUB radix sort on
  /// `stream`), and where this frame's cycles go. Without a last frame of this shape (or with
  /// Tuning::heaviestFirst off): no order.
  TileOrder tileOrder(dim3 grid, int originX, int originY, int wholeX, int wholeY, cudaStream_t stream);
  /// The frame's queued shadow rays (f.scatter.queue), marched into d_image_ after its kernel.
  template <class Sampler>
  void drainShadowQueue(const FrameView& f, const Sampler& s, cudaStream_t stream);
  /// A shaded frame with scattering (Tuning::deferShadows): the queue for its shadow rays, sized
  /// from the rays the last frame offered (read without waiting, when its copy is done);
  /// otherwise (or when it cannot be allocated) none, and its memory given back.
  void prepareShadowQueue(FrameView& f, size_t pixels, cudaStream_t stream);

  Event ev0_, ev1_;
  Tuning tuning_;
  int numSMs_ = 1;
  double clockHz_ = 0;  ///< the SM clock (cudaDevAttrClockRate), for lastFrameLongestBlockSeconds
  DeviceBuffer<vec4f> d_table_;
  PinnedBuffer h_table_;  ///< the table on its way to d_table_
  Event tableCopied_;     ///< h_table_ may be written again once this has passed
  bool tableCopyPending_ = false;
  TransferFunctionView table_{nullptr, 0, 0.f, 1.f};
  DeviceBuffer<float> d_depth_;
  DeviceBuffer<float> d_alphaIn_;
  DeviceBuffer<unsigned> d_counts_;
  DeviceBuffer<vec4f> d_image_;
  DeviceBuffer<ShadowRecord> d_shadowQueue_;  ///< scattering: queued shadow rays (prepareShadowQueue)
  DeviceBuffer<unsigned> d_shadowCount_;
  PinnedBuffer h_shadowCount_;                ///< the last frame's count, copied back without a wait
  Event shadowCounted_;
  bool shadowCountPending_ = false;
  size_t shadowNeed_ = 0;                     ///< rays the last counted frame offered
  unsigned lastQueueCapacity_ = 0;            ///< the last frame's queue (0: none)
  DeviceBuffer<unsigned> d_tileCounter_;
  DeviceBuffer<unsigned> d_tileCost_;     ///< cycles per unit of the whole frame's tiles (TileOrder)
  DeviceBuffer<unsigned> d_orderKeys_;    ///< tileOrder: the units' cost keys (orderKey), then sorted
  DeviceBuffer<unsigned> d_orderUnits_;   ///< tileOrder: the units, then in order
  TempStorage orderTemp_;
  PinnedBuffer h_longest_;                ///< tileOrder: the longest cost, copied back without a wait
  Event longestCopied_;
  bool longestPending_ = false;           ///< the last frame sorted: h_longest_ is its longest
  int costShape_[2] = {0, 0};             ///< wholeX, segments of d_tileCost_'s frames
  bool costKept_ = false;                 ///< d_tileCost_ holds a frame of costShape_
  DeviceBuffer<vec4f> d_layers_;  ///< a segmented frame's layers (raySegments)
  DeviceBuffer<unsigned char> d_layerFlags_;  ///< which layers a segment coloured (1) or left empty (0)
  mutable SegmentLayersView layers_;  ///< the last frame's layers while not yet composited into d_image_
  cudaStream_t stream_ = nullptr;     ///< the last frame's stream
  PinnedBuffer h_stage_;           ///< pinned copy of the last frame's image on its way to the caller
  bool imageOnDevice_ = false;     ///< setImageOnDevice(): leave the image in d_image_
  bool deviceImageValid_ = false;  ///< the last render() left its image in d_image_
  mutable double lastDeviceSeconds_ = -1;
  mutable bool timingPending_ = false;  ///< ev1_ of a frame not waited for: read on demand
};

}  // namespace spaceskip::cuda

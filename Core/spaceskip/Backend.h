// The executor interface behind Engine: a oneTBB backend and a CUDA backend implement it.
// Internal to Core (the VTK module only sees Engine).
#pragma once
#include "Classification.h"
#include "DeviceImageCopy.h"
#include "LabelMap.h"
#include "Tree.h"
#include "Tuning.h"
#include "Types.h"
#include "Volume.h"
#include "render/Integrator.h"

#include <functional>
#include <memory>
#include <string>

namespace spaceskip {

class Backend {
 public:
  virtual ~Backend() = default;
  virtual BackendKind kind() const = 0;
  virtual const char* name() const = 0;
  /// Takes the volume (uploads it on the GPU) and computes the per-brick value ranges.
  virtual void setVolume(const Volume& v, int brick) = 0;
  /// Starts moving `next` (the shape of the volume set, same brick) to where setVolume(next)
  /// will find it, without waiting; false when this backend does not (the CPU reads in place).
  virtual bool prefetchVolume(const Volume& /*next*/) { return false; }
  /// Whether the last setVolume() found its voxels prefetched (Counters::prefetchedSteps).
  virtual bool lastVolumePrefetched() const { return false; }
  /// The step after the one the next setVolume() takes (nullptr: none): a backend that found
  /// that one prefetched starts `next`'s prefetch as soon as it has swapped it in, before its
  /// value ranges (prefetchVolume(next) afterwards then returns true at once). Consumed by that
  /// setVolume(); `next` is copied, its voxels are the caller's (kept as for prefetchVolume).
  virtual void setNextVolume(const Volume* /*next*/) {}
  /// Re-classifies bricks against the TF opacity and what `cc` leaves drawn (bricks no drawn
  /// sample can reach are empty); returns true when the occupancy changed.
  virtual bool classify(const TransferFunction& tf, const CropClip& cc) = 0;
  /// A label map (LabelMap.h): re-classifies bricks over their label sets `s` (no voxel read):
  /// a brick is occupied when one of its labels is drawn (drawn[value - s.lo]) and `cc` leaves
  /// some of it drawn. No sub-brick masks. Returns true when the occupancy changed.
  virtual bool classifyLabels(const LabelSets& s, const std::vector<uint8_t>& drawn, const CropClip& cc) = 0;
  /// Whether the last classify() or classifyLabels() read voxels (the CPU backend's sub-brick
  /// masks): Counters::voxelPasses.
  virtual bool lastClassifyReadVoxels() const { return false; }
  /// True when the last classify() changed the occupancy only by emptying bricks (every brick
  /// occupied now was occupied before): a structure built before it still covers every
  /// occupied brick, so drawing with it stays lossless (it only visits bricks that are empty now).
  virtual bool lastClassifyOnlyEmptied() const { return false; }
  /// Of the last classify(), the seconds the host waited for the device (0 on the CPU).
  virtual double lastClassifyWaitSeconds() const { return 0; }
  /// The opacity-corrected table the integrator samples.
  virtual void setTransferTable(const std::vector<vec4f>& corrected, float lo, float scale) = 0;
  /// Builds the hierarchy `p.builder` asks for; throws BackendError when this backend cannot.
  virtual void build(const BuildParams& p, BuildStats& stats) = 0;
  /// `f` carries camera, box, sampling; the backend fills pointers and traversal kind.
  virtual void render(FrameView f, FilterMode filter, const float* depth, Image& out) = 0;
  /// Called on the caller's thread with the fraction of a frame drawn, where a frame takes long
  /// (the CPU backend's large frames); empty: none.
  virtual void setProgress(std::function<void(double)> /*progress*/) {}
  /// When `on` (and supported: returns whether it is), render() leaves the image in device memory
  /// (deviceImage()) and gives `out` only its size: for callers that draw it with CUDA-GL interop.
  virtual bool setImageOnDevice(bool /*on*/) { return false; }
  /// The last frame's premultiplied RGBA (one float4 per pixel, row 0 at the bottom) in device
  /// memory while setImageOnDevice(true) is in effect, else nullptr.
  virtual const void* deviceImage() const { return nullptr; }
  /// The same frame, a segmented frame's layers not composited (DeviceImageView).
  virtual DeviceImageView deviceImageView() const { return DeviceImageView{}; }
  /// The CUDA stream (a cudaStream_t) deviceImage() is written on, or nullptr. render() does not
  /// wait for a frame it leaves on the device: work the caller queues on this stream after
  /// render() sees the finished image, and the next render() overwrites it only after that work.
  virtual void* deviceImageStream() const { return nullptr; }
  /// The knobs of Tuning.h this backend reads (each backend keeps a copy).
  virtual void setTuning(const Tuning& /*t*/) {}
  /// Seconds the last render() spent in device work (CUDA events), -1 when not measured. For a
  /// frame left on the device (not waited for by render()) this waits for the frame.
  virtual double lastFrameDeviceSeconds() const { return -1; }
  /// Shadow rays the last render() queued for its second pass (FrameStats::queuedShadowRays);
  /// waits for the frame as lastFrameDeviceSeconds does.
  virtual int64_t lastFrameQueuedShadowRays() const { return 0; }
  /// The longest block of the frame before the last render() (FrameStats::longestBlockSeconds);
  /// waits for the frame.
  virtual double lastFrameLongestBlockSeconds() const { return -1; }
  /// Measures the host-to-device copy rates with buffers of `bytes` (best of 3 each); zeros
  /// without a device.
  virtual UploadRates measureUpload(size_t /*bytes*/) { return UploadRates{}; }
  /// The volume's value range from the brick ranges setVolume computed (the least brick minimum,
  /// the largest maximum; NaN skipped, +-Inf kept), without a pass over the voxels; false where
  /// the backend has none at hand.
  virtual bool brickValueRange(double& /*lo*/, double& /*hi*/) { return false; }
  /// The most memory the voxels may take (bytes; 0: the backend's default, for CUDA the free
  /// device memory less what the rest needs; the CPU backend holds the volume in host memory
  /// and ignores it unless set). A volume above it is kept sparse (BrickPool.h): only the
  /// bricks each frame needs are resident. Takes effect at the next setVolume().
  /// `poolBrick`: cells per pool brick edge (rounded to a multiple of the classification brick).
  virtual void setMemoryBudget(int64_t /*bytes*/, int /*poolBrick*/) {}
  /// Where the voxels live: in core, or sparse with the last frame's residency figures.
  virtual ResidencyStats residency() const { return ResidencyStats{}; }
  virtual const OccupancyGrid& occupancy() = 0;
  /// Fraction of occupied bricks after the last classify(), without a host copy of the grid.
  virtual double occupiedFraction() { return occupancy().occupancy(); }
  /// Set sub-brick parts over all parts of the occupied bricks after the last classify(); 1
  /// without masks.
  virtual double subMaskShare() const { return 1.0; }
  virtual Tree tree() = 0;
};

std::unique_ptr<Backend> makeCpuBackend();
/// memcpy split over oneTBB workers (the CUDA backend's pinned staging buffer -> the caller's image).
void parallelCopy(void* dst, const void* src, size_t bytes);
/// Throws BackendError when built without CUDA or when no usable device exists.
std::unique_ptr<Backend> makeCudaBackend();
/// True when this build has CUDA code and a device answers.
bool cudaAvailable(std::string* why = nullptr);
/// Device bytes held right now by all CUDA backends of this process (0 without CUDA). For tests:
/// after a backend is destroyed, nothing it allocated may remain.
int64_t cudaDeviceBytesInUse();

}  // namespace spaceskip

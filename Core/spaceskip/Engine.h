// The one interface the CLI, the VTK mapper and the tests drive, whatever the backend.
// It keeps what a scene needs and redoes only what a change requires:
//   volume -> value ranges (once) -> TF opacity edit -> classification -> rebuild only if the
//   occupancy changed; a colour-only edit updates the TF table alone.
#pragma once
#include "Camera.h"
#include "Classification.h"
#include "DeviceImageCopy.h"
#include "LabelMap.h"
#include "Tree.h"
#include "TransferFunction.h"
#include "Tuning.h"
#include "Types.h"
#include "Volume.h"
#include "VolumePiece.h"

#include <functional>
#include <memory>
#include <string>

namespace spaceskip {

/// The sample distance the engine renders with for `requested` world units (<= 0: half the
/// smallest spacing), after the bounds kMinStepsPerVoxel, kMaxSamplesPerCell, kMaxSamplesPerRay
/// and half the volume's diagonal (Types.h). When a bound applied, `note` (if given) says
/// what was clamped and why; otherwise it is left empty.
double effectiveSampleDistance(const Volume& v, double requested, std::string* note = nullptr);

class Backend;

class Engine {
 public:
  /// Auto picks CUDA when a usable device exists, else the oneTBB backend.
  explicit Engine(BackendKind backend = BackendKind::Auto);
  /// Same, with the logger installed before the backend is chosen (so a CUDA fallback message
  /// reaches it instead of stderr).
  Engine(BackendKind backend, std::function<void(const std::string&)> log);
  ~Engine();
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  BackendKind backendKind() const;
  const char* backendName() const;
  /// Messages (warnings, fallbacks) go here; default prints to stderr.
  void setLogger(std::function<void(const std::string&)> log);
  /// Called on the caller's thread as update() and render() go, with the fraction of the work
  /// done (0..1) and the step under way ("value ranges", "classification", "build",
  /// "measuring", "frame"): what a progress bar shows (the VTK mapper's progress events).
  /// The CPU backend also reports inside a large frame. Empty: none.
  void setProgress(std::function<void(double, const char*)> progress);

  /// The engine borrows `v.data` (or shares `v.storage`): keep it alive while rendering.
  void setVolume(const Volume& v);
  /// A time step's voxels before it is shown (playback): on the CUDA backend, when `next` has the
  /// shape of the volume shown and two steps fit the device, its upload starts on a second stream
  /// and a host thread while the current step is drawn, and setVolume(next) then finds it on the
  /// device. Keep `next`'s voxels unchanged and alive until setVolume(next) (or another prefetch).
  /// A step set before and not drawn yet is uploaded first (as update() would), so that
  /// setVolume(t); prefetchVolume(t + 1); render(t) overlaps step t + 1's upload with step t's
  /// classification, build and frame.
  /// Returns whether the upload started (false: setVolume uploads it as before).
  bool prefetchVolume(const Volume& next);
  /// A new table: compared with the one the engine has, an opacity change re-classifies (and
  /// rebuilds only when the occupied cells change), a colour-only change updates the table alone.
  /// A caller that knows a part is unchanged (the VTK mapper: that function was not edited) says
  /// so with `colorMayDiffer` / `opacityMayDiffer` false, and that part is not compared (it must
  /// then equal the engine's; Counters::colorCompares/opacityCompares count the compares).
  void setTransferFunction(TransferFunction tf, bool colorMayDiffer = true, bool opacityMayDiffer = true);
  /// Label maps (RenderParams::labelMap, LabelMap.h): each label's colour, opacity and
  /// visibility. Which labels are drawn (visible, opacity > 0) decides the occupancy: a change of
  /// that re-classifies bricks over their label sets (no voxel read; a rebuild only when the
  /// occupancy changes), an opacity or colour change re-makes the table alone.
  void setLabelTable(const LabelTable& t);
  const LabelTable& labelTable() const;
  /// Whether the last update() drew a label map (labelMap asked for, on 8- or 16-bit integers).
  bool labelMapActive() const;
  void setBuildParams(const BuildParams& p);
  void setRenderParams(const RenderParams& p);
  /// The volume is one piece of a larger one (MPI; VolumePiece.h): rays, planes and the sample
  /// lattice become the whole volume's and only the owned cells are drawn. A default
  /// VolumePiece (wholeDims 0) renders the volume as a whole. Checked against the volume at
  /// render time: a piece that does not fit it is said once and ignored.
  void setPiece(const VolumePiece& p);
  const BuildParams& buildParams() const;
  const RenderParams& renderParams() const;

  /// Brings ranges, classification and hierarchy up to date (render() calls it).
  void update();
  /// Renders `width` x `height` pixels; `depth` (optional) is the window depth of opaque
  /// geometry per pixel, in [0,1], row 0 at the bottom. `alphaIn` (optional, same layout): the
  /// opacity each ray brings from pieces in front of this one when pieces of one volume are
  /// composited front to back in float (composite and isosurface modes): the ray goes on from
  /// it (early ray termination stops where the whole volume's ray would) and the image holds
  /// this piece's share, to be added to what is in front.
  void render(const Camera& cam, int width, int height, Image& out, const float* depth = nullptr,
              const float* alphaIn = nullptr);

  /// CUDA: keep each frame's image in device memory (deviceImage()) instead of downloading it;
  /// render()'s Image then gets only its size. Returns false (and changes nothing) when the
  /// backend cannot; a fallback to the CPU backend turns it off.
  bool setImageOnDevice(bool on);
  /// The last frame's premultiplied RGBA, float4 per pixel, row 0 at the bottom, in device memory
  /// (valid until the next render), or nullptr when the image went to the host.
  const void* deviceImage() const;
  /// The same frame without compositing a segmented frame's layers into the flat image: the
  /// view holds the layers then (DeviceImageCopy::blendOver composites them as it blends).
  /// Empty (no image, no layers) when the image went to the host.
  DeviceImageView deviceImageView() const;
  /// The CUDA stream (a cudaStream_t) deviceImage() is written on, nullptr without a device
  /// image. render() does not wait for a frame it leaves on the device: work queued on this
  /// stream after render() sees the finished image (e.g. the CUDA-GL interop copy), and the next
  /// render() overwrites the image only after that work.
  void* deviceImageStream() const;
  /// The kernels', builders' and classification's knobs (Tuning.h; the defaults are the
  /// product's behaviour). A launch knob takes effect at the next frame, a classification knob
  /// at the next classification (partRanges at the next setVolume), a DistanceGrid knob at the
  /// next build; a backend made later (a fallback) gets them too.
  void setTuning(const Tuning& t);
  const Tuning& tuning() const;
  /// The most memory the voxels may take on the backend, in bytes (0, the default: CUDA takes
  /// the free device memory less what its other structures need; the CPU backend has no limit).
  /// A volume above it is kept sparse (BrickPool.h): each frame makes resident only the pool
  /// bricks it can need (bit-identical images), evicting the least recently needed ones; a
  /// view that needs more than the budget falls back to the CPU backend (CUDA) or samples
  /// the host's volume (CPU), said once. frameStats().residency reports it.
  /// `poolBrick`: cells per pool brick edge (a multiple of the classification brick; smaller
  /// bricks fit sparse data tighter, at (brick+1)^3/brick^3 voxels per slot and a larger table).
  void setMemoryBudget(int64_t bytes, int poolBrick = 16);

  const BuildStats& buildStats() const;
  /// Builder Auto: true while it measures its candidates (one to four frames each, Engine.cpp),
  /// at first or when it re-checks its choice at a new, still view.
  bool exploring() const;
  /// The last frame's statistics. A frame left on the device (setImageOnDevice) is not waited
  /// for by render(): its deviceSeconds is read here, which waits for the frame's device work;
  /// with `waitForDevice` false nothing waits and deviceSeconds is -1 until someone waits.
  const FrameStats& frameStats(bool waitForDevice = true) const;
  /// The host-to-device copy rates with buffers of `bytes` (Types.h UploadRates; zeros on the
  /// CPU backend): the bound a time step's upload can reach, beside the engine's own upload.
  UploadRates measureUpload(size_t bytes);
  /// Host memory for `bytes` of voxels that this engine's backend uploads at the link's full
  /// rate: page-locked on the CUDA backend (the upload is one DMA, no staging copy through the
  /// host's cores), plain memory on the CPU backend or where none can be locked. A reader that
  /// reads time steps into it and hands them over as Volume::data (kept alive while drawn)
  /// spares each step the pageable staging (measureUpload's staged rate against its pinned one).
  /// Throws std::bad_alloc when no memory can be had.
  std::shared_ptr<unsigned char> allocateStepMemory(size_t bytes);
  const Counters& counters() const;
  /// Host copies for tests and statistics (downloaded from the device if needed).
  const OccupancyGrid& occupancy();
  Tree tree();
  /// The sample distance rendered with, after effectiveSampleDistance's bounds.
  double sampleDistance() const;
  /// Floating-point volumes whose magnitudes lie outside [2^-60, 2^60] are sampled through an
  /// exact power-of-two rescale (a float copy); values are multiplied by 2^valueExponent()
  /// (0 when not rescaled). For one-component float32 volumes it is decided from the backend's
  /// brick ranges, i.e. known after update() (or the first render()).
  int valueExponent() const;
  /// The volume's value range (one component, 8/16-bit integers or float32; NaN and infinities
  /// aside) from the brick ranges the backend computes anyway where the voxels land (on the GPU
  /// right after the upload): uploads the volume set, if it is not yet, and reduces them. For a
  /// caller that needs the range before the first frame of a volume or time step (the VTK
  /// mapper's table range) without a pass of its own over the voxels. False, with nothing
  /// known, where the backend has no brick ranges at hand (sparse residency), for other
  /// volumes, for a rescaled float volume (valueExponent) or where a value is infinite: the
  /// caller's own pass is the fallback.
  bool valueRange(double& lo, double& hi);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace spaceskip

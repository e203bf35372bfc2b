// Per-brick value ranges and occupancy on the device: the twins of Core/src/Classification.cpp,
// sharing its rules (brickRange, OpacityRangeMaxView in spaceskip/Classification.h).
#pragma once
#include "DeviceVolume.cuh"
#include "spaceskip/Classification.h"
#include "spaceskip/GradientBound.h"
#include "spaceskip/LabelMap.h"

namespace spaceskip::cuda {

/// What classifyBricks counts, in device memory (zeroed by the caller).
struct ClassifyFlags {
  unsigned long long occupied;  ///< occupied bricks
  int changed;                  ///< 1 when some brick differs from the previous occupancy
  int grew;                     ///< 1 when some brick is occupied that was not before (or no previous)
  unsigned long long setParts[64];  ///< set sub-brick parts, summed over spread counters
  unsigned listCount;               ///< occupied bricks appended to the list (sub-brick masks)
};

/// d_vmin/d_vmax[i] = brickRange of brick i (x fastest) of the `bdims` bricks of `brick` cells
/// over the `type` voxels at d_voxels (of the opacity channel, the last of `components`
/// interleaved ones).
cudaError_t brickRanges(const void* d_voxels, VoxelType type, int components, vec3l dims, vec3i bdims, int brick,
                        float* d_vmin, float* d_vmax, cudaStream_t stream);

/// d_occ[i] = 1 when brick i of the `bdims` bricks of `brick` cells (of `cellDims`) is occupied
/// by brickOccupied: its range can have opacity > 0 (rmq.levels on the device) and `cc` leaves
/// some of it drawn; counts into d_flags and flags any difference from d_prev (nullptr:
/// everything changed). With d_state and d_list: the bricks' states (whole or empty) and the
/// occupied bricks' indices (d_flags->listCount of them). `rows` (height > 0, levels on the
/// device): a 2-D function's gradient rule too (GradientBound.h: gradientRowsAllow).
cudaError_t classifyBricks(const float* d_vmin, const float* d_vmax, vec3i bdims, int brick, vec3i cellDims,
                           const OpacityRangeMaxView& rmq, const CropClip& cc, const uint8_t* d_prev, uint8_t* d_occ,
                           ClassifyFlags* d_flags, cudaStream_t stream, uint8_t* d_state = nullptr,
                           uint32_t* d_list = nullptr, const GradientRowsView& rows = GradientRowsView{});

/// The brick grid of the current volume: value ranges (once per volume) and a double-buffered
/// occupancy (once per opacity edit), with a host copy of the occupancy made on demand.
class BrickClassification {
 public:
  BrickClassification() { h_flags_.reserve(sizeof(ClassifyFlags)); }

  /// Sizes the grid for `v` and launches the range kernel on `stream` (no synchronization).
  void setVolume(const DeviceVolume& v, int brick, cudaStream_t stream);
  /// The same from ranges computed on the host (sparse residency: the voxels are not on the
  /// device); copies them on `stream` (no synchronization: keep `r` alive until it is synchronized).
  void setRanges(const Volume& vol, const RangeGrid& r, cudaStream_t stream);
  /// Classifies against `tf`'s opacity and `cc`; true when the occupancy changed (or is the first).
  bool classify(const TransferFunction& tf, const CropClip& cc, cudaStream_t stream);
  /// A label map's occupancy (LabelMap.h: brickLabelsOccupied over the bricks' label sets, on
  /// the device; no sub-brick masks, no voxel read); true when it changed (or is the first).
  bool classifyLabels(const LabelSets& ls, const std::vector<uint8_t>& drawn, const CropClip& cc,
                      cudaStream_t stream);
  /// The occupancy on the host (downloaded once per classification).
  const OccupancyGrid& occupancy(cudaStream_t stream);

  int64_t numBricks() const { return int64_t(bdims.x) * bdims.y * bdims.z; }
  /// The least brick minimum and the largest brick maximum (NaN skipped, +-Inf kept): the
  /// volume's value range from the ranges setVolume computed, reduced on the device (no voxel
  /// read); waits for `stream`. False before any ranges.
  bool valueRange(double& lo, double& hi, cudaStream_t stream);

  // Plain state, read by the builders and the render launch.
  int brick = 8;
  vec3i cellDims{0, 0, 0}, bdims{0, 0, 0};
  DeviceBuffer<float> d_vmin, d_vmax;
  DeviceBuffer<float> d_range_;  ///< valueRange's two results
  TempStorage rangeTemp_;
  DeviceBuffer<uint8_t> d_occ[2];  ///< d_occ[cur]: the current occupancy
  /// The sub-brick masks of the current occupancy (Classification.h); null when there are none
  /// (brick size, several components, sparse residency, SPACESKIP_SUB_MASKS=0).
  /// Computed by refreshMasks(), not by classify(): the classification of an opacity edit
  /// stays as cheap as before, and the edit's frame marches whole bricks.
  const uint64_t* subMasks() const { return haveSub_ && masksReady_ ? d_sub_.get() : nullptr; }
  /// The brick states of the current occupancy (subBrickState), with the masks; else null.
  const uint8_t* brickStates() const { return haveSub_ && masksReady_ ? d_state_.get() : nullptr; }
  /// Whether this classification has masks to compute (refreshMasks).
  bool masksPending() const { return haveSub_ && !masksReady_; }
  /// Computes the masks and states of the last classification (one warp per occupied brick)
  /// and their set share; waits for them.
  void refreshMasks(cudaStream_t stream);
  /// Part ranges (sub-brick masks on the classification's path): after setVolume, the value
  /// range of every part of every brick whose parts' ranges differ from the brick's own, stored
  /// once (a warp per brick over the voxels, then a scan for the slots). With them the masks
  /// come from 128 stored bounds a brick instead of the brick's voxels (at N-body 2048^3 the
  /// voxel kernel took 0.59 ms, so it ran on the frame after the edit's and the edit's frame
  /// marched whole bricks), and classify() computes them itself where few bricks are occupied
  /// (editMaskShare), else the next frame does. Left out (masks on the next frame, from the
  /// voxels, as before) when they would take more than a quarter of the volume's bytes or the
  /// device has no room for them. Bytes held: partRangeBytes().
  size_t partRangeBytes() const { return partRangeBytes_; }
  /// classify() computes the masks from the part ranges when at most 1/editMaskShare of the
  /// bricks are occupied (sparse data, where the part walk pays); denser occupancies leave them
  /// to the next frame. On the H100 the range mask kernel took 3.4 ms at Richtmyer-Meshkov
  /// 2048^2x1920 (about 8 M occupied bricks) and about 0.05 ms at N-body 2048^3 (183 k).
  int64_t editMaskShare = 16;
  /// ... and only when the last masks had at most this share of their parts set (the frames
  /// walk parts then, CudaBackend's kPartsShare; else the edit's frame would not use them).
  double editMaskMaxShare = 0.2;
  /// Drops the part ranges and frees their buffers (the masks then come from the voxels,
  /// refreshMasks): sparse residency, no room on the device, and tests.
  void dropPartRanges() {
    d_partSlot_.release();
    d_partRanges_.release();
    d_partFlags_.release();
    partRangeBytes_ = 0;
    havePartRanges_ = false;
  }
  /// The masks and states of the last classification on the host (masks of bricks that are
  /// not occupied: 0), computing them first when pending. For tests.
  SubMasks downloadMasks(cudaStream_t stream);
  /// Marks DistanceGrid's field `d_dist` (one byte per brick) with markedDistance for the
  /// current states, or clears the marks when there are none (on `stream`, no synchronization).
  void markDistances(uint8_t* d_dist, cudaStream_t stream) const;
  /// The sub-brick mask knobs (subMasks, subMaskMaxSet: read at each classification;
  /// partRanges: at setVolume).
  Tuning tuning;
  int cur = 0;
  bool haveOcc = false;  ///< classify() ran for this volume
  int64_t occupied = 0;
  uint64_t generation = 0;  ///< counts classify() calls that changed the occupancy
  bool grew = true;         ///< the last classify() occupied a brick the previous one had empty
  /// Set parts over all parts of the occupied bricks (after refreshMasks): the share of an
  /// occupied brick's volume a part-walking frame still marches.
  double setFraction = 1.0;
  /// Of the last classify()'s host time, the seconds it waited for the device (its kernel, the
  /// flags' copy and whatever was queued before them on the stream).
  double waitSeconds = 0;

 private:
  DeviceBuffer<float> d_levels_;  ///< OpacityRangeMax's levels
  DeviceBuffer<float> d_rowLevels_;  ///< GradientRows' levels (a 2-D function over the gradient)
  PinnedBuffer h_rowLevels_;
  size_t levelBytes_ = 0, rowLevelBytes_ = 0;  ///< the bytes of h_levels_/h_rowLevels_ on the device (0: none)
  double spacing_[3] = {1, 1, 1};  ///< the volume's (the gradient rule's normalisation)
  /// Part ranges: per brick its slot in d_partRanges_ (kUniformBrick: every part's range is the
  /// brick's), and per slot 64 lower then 64 upper bounds (PartRangeStore of the voxel type).
  DeviceBuffer<uint32_t> d_partSlot_;
  DeviceBuffer<unsigned char> d_partRanges_;
  DeviceBuffer<uint32_t> d_partFlags_;  ///< computePartRanges' per-brick flags (kept: no free a step)
  TempStorage partScanTemp_;           ///< its scan's temporary storage (kept likewise)
  bool havePartRanges_ = false;        ///< d_partSlot_/d_partRanges_ hold this volume's part ranges
  size_t partRangeBytes_ = 0;
  void computePartRanges(cudaStream_t stream);
  void masksFromRanges(cudaStream_t stream, unsigned maxCount);
  /// The levels on their way to d_levels_: a pageable copy would wait for the whole stream and
  /// go through the driver's staging; classify() synchronizes before it returns, so the next
  /// classification may write it again.
  PinnedBuffer h_levels_;
  DeviceBuffer<uint64_t> d_sub_;
  DeviceBuffer<uint8_t> d_state_;
  DeviceBuffer<uint32_t> d_list_;  ///< the occupied bricks' indices (mask kernel's work list)
  bool masksReady_ = false;
  OpacityRangeMaxView rmq_{};  ///< the last classification's table (d_levels_ on the device)
  int numSMs_ = 0;
  bool haveSub_ = false;
  // The in-core voxels the masks read (setVolume; none after setRanges).
  const void* d_voxels_ = nullptr;
  VoxelType type_ = VoxelType::UInt8;
  vec3l dims_{0, 0, 0};
  int components_ = 1;
  DeviceBuffer<ClassifyFlags> d_flags_;
  const ClassifyFlags* finishClassification(cudaStream_t stream, bool& changed);
  // classifyLabels: the label sets (uploaded on the first classification after setVolume) and
  // the per-value flags.
  DeviceBuffer<int64_t> d_labelOffset_;
  DeviceBuffer<uint16_t> d_labels_;
  DeviceBuffer<uint8_t> d_drawn_;
  PinnedBuffer h_drawn_;
  bool labelSetsOnDevice_ = false;
  PinnedBuffer h_flags_;
  OccupancyGrid hostOcc_;
  bool hostOccValid_ = false;
};

}  // namespace spaceskip::cuda

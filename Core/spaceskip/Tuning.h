// Every knob of the kernels, the builders, the classification and the VTK compositor that a
// benchmark or a test may turn: plain data, set through Engine::setTuning (the backends get a
// copy) and vtkSpaceSkippingVolumeMapper::SetTuning. The library reads no environment for these:
// the CLI and the window benchmark fill a Tuning from SPACESKIP_* variables in one place
// (Core/cli/Environment.h; docs/tuning.md lists them). Each default is the product's behaviour.
#pragma once

#include <cstdint>

namespace spaceskip {

struct Tuning {
  // --- CUDA launch of the render kernels (the CPU backend ignores these) ---
  /// Threads per block, W x H with 32 <= W*H <= 256; 0: 16x8.
  int blockX = 0, blockY = 0;
  /// Persistent launch: N resident blocks per SM take tiles from a counter; 0: one block per tile
  /// (the plain launch); -1: automatic (persistent for hardware-filtered volumes above 2 GiB).
  int resident = -1;
  /// Rays cut into this many segments marched by separate threads (1..16; 1: whole rays); 0:
  /// automatic (up to 4, by the box's length in samples; 8 for long rays in frames of at most
  /// 3/4 of 1024^2 pixels; CudaExecutor.cu raySegments).
  int raySegments = 0;
  /// Plain launches start the blocks that took longest in the last frame first (their tiles and
  /// ray segments, by the SM clock, the most of the 3 x 3 tiles around; CudaExecutor::tileOrder):
  /// the frame no longer waits for its slowest tiles started last. Off: blocks in row-major
  /// order. The image is the same.
  bool heaviestFirst = true;
  /// Samples a hardware-filtered GPU march fetches before compositing the first (1..4; 0: 4,
  /// kMaxSampleBatch). 1 (one at a time) stays for the test that batches give the same image.
  int sampleBatch = 0;
  /// Grid and DistanceGrid frames walk the parts of sparse bricks only where the set parts are
  /// at most this share of the occupied bricks' parts (CudaBackend.cu; measured in
  /// docs/results/h100-sub-brick-masks).
  double partsShare = 0.2;
  /// Scattering: shadow rays are queued by the primary rays and marched by a second kernel
  /// (render/Scattering.h scatterShade); off: each is marched where its sample is.
  bool deferShadows = true;

  // --- classification (both backends) ---
  /// Sub-brick masks: without them an occupied brick is marched whole.
  bool subMasks = true;
  /// The oneTBB backend computes the masks and walks the parts too (with subMasks on). Off: it
  /// marches occupied bricks whole and an opacity edit reads no voxel. Off measured 0.96-1.10x
  /// the frame with it on (18 of 22 items faster) on the paper's 11 stand-ins at 1/4 scale, and
  /// an opacity edit that occupies bricks 1.6x faster to its first frame on N-body 512^3
  /// (docs/results/cpu-sub-brick-masks).
  bool cpuSubMasks = false;
  /// The most set parts (of 64) a brick may have to be walked part by part (subBrickState); 40
  /// measured best over 24 on the H100 and the oneTBB backend (docs/results/h100-tf-edit).
  int subMaskMaxSet = 40;
  /// CUDA: part ranges stored at setVolume, so that an edit's classification computes the masks
  /// from 128 bounds a brick (BrickClassification::partRangeBytes); off: from the voxels, on the
  /// frame after the edit's.
  bool partRanges = true;

  // --- DistanceGrid (CUDA) ---
  /// The distance field's cap in bricks (1..127; kMaxSkipDistance, DistanceField.h).
  int distanceCap = 32;
  /// The most threads a line of the field's staged kernel uses (1..8; DistanceField.cu).
  int distanceSegments = 8;

  // --- VTK mapper and compositor ---
  /// Under MPI, the colour a piece in front adds where its ray goes on into another piece, in
  /// 1/255 (VolumePiece::followBias: IceT's 8-bit blend truncates).
  double pieceBias = 0.5;
  /// CUDA: blend the frame straight into the window's colour texture when it can; off: the
  /// texture path (upload and GL draw).
  bool cudaBlend = true;
  /// Composite the whole viewport instead of the volume's projected rectangle.
  bool compositeFull = false;
};

/// Fault injection for tests (process-wide, off by default); the CUDA backend reads these at
/// each allocation and render launch, a relaxed atomic load each.
namespace testing {
/// Caps the device bytes SpaceSkip may hold: an allocation above it fails with
/// cudaErrorMemoryAllocation as a real out-of-memory does. Negative: no cap (the default).
void setDeviceMemoryLimit(int64_t bytes);
int64_t deviceMemoryLimit();
/// Every CUDA render launch reports cudaErrorLaunchFailure (a CUDA error in the middle of a
/// frame), so that the fallback to the CPU backend's image can be tested on any GPU.
void setFailRender(bool on);
bool failRender();
}  // namespace testing

}  // namespace spaceskip

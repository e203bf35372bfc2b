// Sparse residency on the device (BrickPool.h): the pool of resident bricks in device memory,
// its slot table, and the per-frame update that finds the needed pool bricks (one thread per
// pool brick, poolBrickNeeded) and uploads the missing ones through pinned staging buffers.
#pragma once
#include "CudaCommon.cuh"
#include "spaceskip/BrickPool.h"

namespace spaceskip::cuda {

class DevicePool {
 public:
  /// Lays out `v` (one component; the caller keeps its host voxels alive) in pool bricks of
  /// about `poolBrick` cells and allocates a pool of as many slots as `budgetBytes` holds (at
  /// most one per pool brick), allocated as views need them. Nothing is resident yet.
  void init(const Volume& v, int classBrick, int poolBrick, int64_t budgetBytes);
  void release();
  bool active() const { return active_; }

  /// Makes every pool brick `r` needs resident (classification bricks: d_occ/d_vmin/d_vmax of
  /// `cdims` bricks of `cbrick` cells; `generation` changes whenever d_occ does). Does nothing when
  /// neither changed since the last call. Grows the pool (grownCapacity) when the budget allows;
  /// throws BackendError when the needed bricks exceed the budget. Synchronizes `stream`.
  void update(const PoolNeedRule& r, const uint8_t* d_occ, uint64_t generation, const float* d_vmin,
              const float* d_vmax, vec3i cdims, int cbrick, cudaStream_t stream);

  /// The pool as the render kernels read it (device pointers).
  PoolView view() const { return PoolView{d_pool_.get(), d_table_.get(), vol_.dims, layout_.brick, layout_.bdims}; }
  const ResidencyStats& stats() const { return stats_; }

 private:
  bool active_ = false;
  Volume vol_;
  PoolLayout layout_;
  BrickResidency res_;
  DeviceBuffer<unsigned char> d_pool_;
  DeviceBuffer<int32_t> d_table_;
  DeviceBuffer<uint8_t> d_needed_;
  std::vector<uint8_t> needed_;
  PinnedBuffer stage_[2];
  int64_t maxCapacity_ = 0;  ///< slots the budget allows; the pool grows towards it
  PoolNeedRule rule_;
  uint64_t generation_ = ~uint64_t(0);
  bool valid_ = false;
  ResidencyStats stats_;
};

}  // namespace spaceskip::cuda

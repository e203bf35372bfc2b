// Sparse residency on the device: needed pool bricks, LRU bookkeeping (host) and uploads.
#include "DevicePool.cuh"
#include "spaceskip/PoolPlan.h"

#include <algorithm>
#include <chrono>
#include <string>

namespace spaceskip::cuda {

namespace {

constexpr int kThreads = 256;
/// Bytes of each of the two pinned staging buffers the uploads go through.
constexpr size_t kStageBytes = size_t(64) << 20;

// Launch shape: one thread per pool brick. needed[p] = poolBrickNeeded(p, ...).
__global__ void neededKernel(PoolLayout L, vec3i cdims, int cbrick, const uint8_t* occ, const float* vmin,
                             const float* vmax, PoolNeedRule r, uint8_t* needed) {
  const int64_t p = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (p < L.count()) needed[p] = poolBrickNeeded(p, L, cdims, cbrick, occ, vmin, vmax, r) ? 1 : 0;
}

}  // namespace

void DevicePool::init(const Volume& v, int classBrick, int poolBrick, int64_t budgetBytes) {
  release();
  if (v.components != 1)
    throw BackendError("sparse residency holds one-component volumes only (this one has " +
                       std::to_string(v.components) + ")");
  vol_ = v;
  vol_.storage.reset();  // the Engine keeps the voxels alive
  layout_ = makePoolLayout(v.dims, classBrick, poolBrick);
  maxCapacity_ = poolCapacity(v, layout_, budgetBytes);
  res_.reset(layout_.count(), 0);
  d_table_.reserve(size_t(layout_.count()));
  d_needed_.reserve(size_t(layout_.count()));
  needed_.assign(size_t(layout_.count()), 0);
  SS_CUDA_CHECK(cudaMemset(d_table_.get(), 0xff, size_t(layout_.count()) * sizeof(int32_t)));  // all -1
  stats_ = poolStats(v, layout_, maxCapacity_, budgetBytes);
  valid_ = false;
  active_ = true;
}

void DevicePool::release() {
  active_ = false;
  valid_ = false;
  d_pool_.release();
  d_table_.release();
  d_needed_.release();
  needed_.clear();
  stats_ = ResidencyStats{};
}

void DevicePool::update(const PoolNeedRule& r, const uint8_t* d_occ, uint64_t generation, const float* d_vmin,
                        const float* d_vmax, vec3i cdims, int cbrick, cudaStream_t stream) {
  if (!beginPoolUpdate(valid_, rule_, generation_, r, generation, stats_)) return;
  const auto t0 = std::chrono::steady_clock::now();
  const int64_t n = layout_.count();
  neededKernel<<<blocksFor(n, kThreads), kThreads, 0, stream>>>(layout_, cdims, cbrick, d_occ, d_vmin, d_vmax, r,
                                                                d_needed_.get());
  SS_CUDA_CHECK_LAUNCH(neededKernel);
  SS_CUDA_CHECK(cudaMemcpyAsync(needed_.data(), d_needed_.get(), size_t(n), cudaMemcpyDeviceToHost, stream));
  SS_CUDA_CHECK(cudaStreamSynchronize(stream));
  const int64_t slotBytes = layout_.slotVoxels() * int64_t(voxelSize(vol_.type));
  valid_ = false;  // until the uploads are done
  const BrickResidency::Plan plan = planPoolUpdate(
      res_, needed_.data(), maxCapacity_, vol_, layout_, stats_,
      [&](int64_t slots) {
        // A larger pool keeps the resident slots (one device copy). When the device cannot hold
        // both, the pool stays as it is and evicts instead (if the needed bricks fit it).
        DeviceBuffer<unsigned char> bigger;
        try {
          bigger.reserve(size_t(slots * slotBytes));
        } catch (const BackendError&) {
          return false;
        }
        if (res_.capacity() > 0)
          SS_CUDA_CHECK(cudaMemcpyAsync(bigger.get(), d_pool_.get(), size_t(res_.capacity() * slotBytes),
                                        cudaMemcpyDeviceToDevice, stream));
        SS_CUDA_CHECK(cudaStreamSynchronize(stream));
        d_pool_.swap(bigger);
        return true;
      },
      [](const std::string& m) { throw BackendError(m); });
  // Uploads: gather runs of bricks into one pinned buffer while the other one's copies run.
  const size_t perStage = std::max<size_t>(1, kStageBytes / size_t(slotBytes));
  if (!plan.bricks.empty()) {
    for (auto& s : stage_) s.reserve(perStage * size_t(slotBytes));
    Event done[2];
    bool pending[2] = {false, false};
    unsigned char* pool = d_pool_.get();
    for (size_t first = 0, chunk = 0; first < plan.bricks.size(); first += perStage, ++chunk) {
      const int b = int(chunk & 1);
      if (pending[b]) SS_CUDA_CHECK(cudaEventSynchronize(done[b]));
      const size_t count = std::min(perStage, plan.bricks.size() - first);
      unsigned char* stage = static_cast<unsigned char*>(stage_[b].get());
      gatherBricks(vol_, layout_, plan.bricks.data() + first, count, stage);
      // Runs of consecutive slots are one copy each (slots are in increasing order).
      for (size_t i = 0; i < count;) {
        size_t j = i + 1;
        while (j < count && plan.slots[first + j] == plan.slots[first + j - 1] + 1) ++j;
        SS_CUDA_CHECK(cudaMemcpyAsync(pool + int64_t(plan.slots[first + i]) * slotBytes, stage + i * size_t(slotBytes),
                                      (j - i) * size_t(slotBytes), cudaMemcpyHostToDevice, stream));
        i = j;
      }
      SS_CUDA_CHECK(cudaEventRecord(done[b], stream));
      pending[b] = true;
    }
  }
  SS_CUDA_CHECK(cudaMemcpyAsync(d_table_.get(), res_.table().data(), size_t(n) * sizeof(int32_t),
                                cudaMemcpyHostToDevice, stream));
  SS_CUDA_CHECK(cudaStreamSynchronize(stream));
  rule_ = r;
  generation_ = generation;
  valid_ = true;
  finishPoolUpdate(res_, plan, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), stats_);
}

}  // namespace spaceskip::cuda

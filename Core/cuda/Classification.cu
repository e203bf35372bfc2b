// Brick value ranges and classification against the TF on the device (thin drivers over the
// shared brickRange and OpacityRangeMaxView).
#include "Classification.cuh"
#include "spaceskip/Backend.h"

#include <algorithm>

#include <cub/device/device_reduce.cuh>
#include <cub/device/device_scan.cuh>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <type_traits>

namespace spaceskip::cuda {

namespace {

constexpr int kThreads = 256;

/// `levels` to `d` through the pinned `h`, queued on `stream` only when they differ from the ones
/// uploaded before (`uploaded`: their bytes, 0 for none). A time step classifies with the levels
/// of the step before: a host-to-device copy would queue behind a prefetched step's copy on the
/// copy engine.
void uploadLevelsIfChanged(const std::vector<float>& levels, DeviceBuffer<float>& d, PinnedBuffer& h,
                           size_t& uploaded, cudaStream_t stream) {
  const size_t bytes = levels.size() * sizeof(float);
  if (bytes == uploaded && d.get() && std::memcmp(h.get(), levels.data(), bytes) == 0) return;
  uploaded = 0;  // until the copy is queued
  d.reserve(levels.size());
  h.reserve(bytes);
  std::memcpy(h.get(), levels.data(), bytes);
  SS_CUDA_CHECK(cudaMemcpyAsync(d.get(), h.get(), bytes, cudaMemcpyHostToDevice, stream));
  uploaded = bytes;
}

// Launch shape: one thread per brick, 256 per block. brickRange over the brick's voxels.
template <class T, int NC>
__global__ void rangeKernel(const T* data, vec3l dims, vec3i bdims, int brick, float* vmin, float* vmax) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  const int64_t nb = int64_t(bdims.x) * bdims.y * bdims.z;
  if (i >= nb) return;
  const int64_t bx = i % bdims.x, by = (i / bdims.x) % bdims.y, bz = i / (int64_t(bdims.x) * bdims.y);
  float lo, hi;
  brickRange<T, NC>(data, dims, brick, bx, by, bz, lo, hi);
  vmin[i] = lo;
  vmax[i] = hi;
}

// Launch shape: one thread per brick, 256 per block. Occupancy against the TF and the cropping
// and clipping planes (brickOccupied, as on the CPU); counts occupied bricks (one atomic per
// block) and flags any difference from the previous occupancy.
// With `state` (sub-brick masks): every brick's state (kBrickWhole or kBrickEmpty; the mask
// kernel marks the sparse ones) and the occupied bricks' indices appended to `list` (one
// atomic a warp; any order).
__global__ void classifyKernel(const float* vmin, const float* vmax, vec3i bdims, int brick, vec3i cellDims,
                               OpacityRangeMaxView rmq, CropClip cc, const uint8_t* prev, uint8_t* occ,
                               unsigned long long* occupied, int* changed, int* grew, uint8_t* state,
                               uint32_t* list, unsigned* listCount, GradientRowsView rows) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  const int64_t n = int64_t(bdims.x) * bdims.y * bdims.z;
  int o = 0, diff = 0, more = 0;
  if (i < n) {
    o = brickOccupied(i, vmin[i], vmax[i], rmq, bdims, brick, cellDims, cc) &&
                gradientRowsAllow(i, vmin, vmax, bdims, rows)
            ? 1
            : 0;
    occ[i] = uint8_t(o);
    diff = prev ? (prev[i] != o) : 1;
    more = prev ? (o && !prev[i]) : 1;
    if (state) state[i] = o ? kBrickWhole : kBrickEmpty;
  }
  if (list) {
    const unsigned lane = threadIdx.x & 31, ballot = __ballot_sync(0xffffffffu, o != 0);
    if (ballot) {
      const int leader = __ffs(int(ballot)) - 1;
      unsigned base = 0;
      if (int(lane) == leader) base = atomicAdd(listCount, unsigned(__popc(int(ballot))));
      base = __shfl_sync(0xffffffffu, base, leader);
      if (o) list[base + unsigned(__popc(int(ballot & ((1u << lane) - 1u))))] = uint32_t(i);
    }
  }
  const int blockCount = __syncthreads_count(o);
  const int blockDiff = __syncthreads_or(diff);
  const int blockMore = __syncthreads_or(more);
  if (threadIdx.x == 0) {
    if (blockCount) atomicAdd(occupied, (unsigned long long)blockCount);
    if (blockDiff) atomicOr(changed, 1);
    if (blockMore) atomicOr(grew, 1);
  }
}

// A label map's occupancy over its bricks' label sets (LabelMap.h: brickLabelsOccupied, the
// CPU's rule), counted and compared with `prev` as classifyKernel does.
__global__ void labelClassifyKernel(const int64_t* offset, const uint16_t* labels, const uint8_t* drawn, vec3i bdims,
                                    int brick, vec3i cellDims, CropClip cc, const uint8_t* prev, uint8_t* occ,
                                    unsigned long long* occupied, int* changed, int* grew) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  const int64_t n = int64_t(bdims.x) * bdims.y * bdims.z;
  int o = 0, diff = 0, more = 0;
  if (i < n) {
    o = brickLabelsOccupied(i, offset, labels, drawn, bdims, brick, cellDims, cc) ? 1 : 0;
    occ[i] = uint8_t(o);
    diff = prev ? (prev[i] != o) : 1;
    more = prev ? (o && !prev[i]) : 1;
  }
  const int blockCount = __syncthreads_count(o);
  const int blockDiff = __syncthreads_or(diff);
  const int blockMore = __syncthreads_or(more);
  if (threadIdx.x == 0) {
    if (blockCount) atomicAdd(occupied, (unsigned long long)blockCount);
    if (blockDiff) atomicOr(changed, 1);
    if (blockMore) atomicOr(grew, 1);
  }
}

// Launch shape: a fixed grid (kMaskBlocksPerSM blocks of 256 threads per SM) whose warps take
// the occupied bricks of `list` in turn: one warp per brick, two of its 64 parts a lane
// (subPartSet), the mask by ballot; lane 0 writes the mask, marks the brick kBrickParts when
// sparse (subBrickState) and sums the set parts into one of kPartCounters counters. On the H100
// at N-body 2048^3 (183 k occupied bricks): 0.59 ms (one thread a brick: 8.4 ms; the warp
// copying the brick into shared memory first: 1.04 ms).
constexpr int kPartCounters = 64;
constexpr int kMaskBlocksPerSM = 8;
template <class T>
__global__ void subMaskKernel(const T* data, vec3l dims, vec3i cellDims, vec3i bdims, int brick,
                              OpacityRangeMaxView rmq, int maxSet, const uint32_t* list, const unsigned* listCount,
                              uint64_t* masks, uint8_t* state, unsigned long long* setParts) {
  const unsigned lane = threadIdx.x & 31;
  const unsigned warp = (blockIdx.x * blockDim.x + threadIdx.x) >> 5, warps = (gridDim.x * blockDim.x) >> 5;
  const unsigned count = *listCount;
  unsigned long long set = 0;
  for (unsigned w = warp; w < count; w += warps) {
    const int64_t i = list[w];
    const int64_t bx = i % bdims.x, by = (i / bdims.x) % bdims.y, bz = i / (int64_t(bdims.x) * bdims.y);
    const bool a = subPartSet(data, dims, cellDims, brick, bx, by, bz, int(lane), rmq);
    const bool b = subPartSet(data, dims, cellDims, brick, bx, by, bz, int(lane) + 32, rmq);
    const uint64_t m = uint64_t(__ballot_sync(0xffffffffu, a)) | (uint64_t(__ballot_sync(0xffffffffu, b)) << 32);
    if (lane == 0) {
      masks[i] = m;
      state[i] = subBrickState(true, m, maxSet);
      set += unsigned(popcount64(m));
    }
  }
  if (lane == 0 && set) atomicAdd(setParts + warp % kPartCounters, set);
}

// Part ranges. A brick is uniform when each of its parts (with a cell in the volume) has the
// brick's own range [vmin, vmax]: its mask needs no stored bounds. Integer bricks with
// vmin == vmax are uniform without reading them (every voxel has that value).
constexpr uint32_t kUniformBrick = 0xffffffffu;

// The share of set parts over all parts of `occupied` bricks, from the mask kernels' counters.
double setShare(const unsigned long long* setParts, int64_t occupied) {
  unsigned long long set = 0;
  for (int c = 0; c < kPartCounters; ++c) set += setParts[c];
  return occupied > 0 ? double(set) / (64.0 * double(occupied)) : 1.0;
}

// The current device's multiprocessors (1 when it cannot be asked): the fixed grids' size.
int multiprocessors() {
  int dev = 0, n = 0;
  if (cudaGetDevice(&dev) != cudaSuccess || cudaDeviceGetAttribute(&n, cudaDevAttrMultiProcessorCount, dev) != cudaSuccess ||
      n < 1) {
    (void)cudaGetLastError();
    return 1;
  }
  return n;
}
constexpr int kRangeBlocksPerSM = 8;
template <class T>
struct PartRangeStore {  // bounds stored exactly: the 8/16-bit types as themselves, else float
  using type = typename std::conditional<(sizeof(T) <= 2), T, float>::type;
};

// Launch shape: a fixed grid (kRangeBlocksPerSM blocks of 256 threads per SM); a warp per brick
// in turn, two of its 64 parts a lane (subPartRange). Pass 1 (out == nullptr): slot[i] = 1 for
// a brick that is not uniform, else 0. Pass 2: slot[i] holds the exclusive scan of pass 1's
// flags and `flag` pass 1's flag; a non-uniform brick's bounds go to its slot, and slot[i]
// becomes kUniformBrick for the others.
template <class T>
__global__ void partRangeKernel(const T* data, vec3l dims, vec3i cellDims, vec3i bdims, int brick, const float* vmin,
                                const float* vmax, const uint32_t* flag, uint32_t* slot,
                                typename PartRangeStore<T>::type* out) {
  using S = typename PartRangeStore<T>::type;
  const unsigned lane = threadIdx.x & 31;
  const int64_t warp = (int64_t(blockIdx.x) * blockDim.x + threadIdx.x) >> 5;
  const int64_t warps = (int64_t(gridDim.x) * blockDim.x) >> 5;
  const int64_t n = int64_t(bdims.x) * bdims.y * bdims.z;
  constexpr bool integral = std::numeric_limits<T>::is_integer;
  for (int64_t i = warp; i < n; i += warps) {
    if (out) {
      const uint32_t f = flag[i], s = slot[i];
      __syncwarp();
      if (!f) {
        if (lane == 0) slot[i] = kUniformBrick;
        continue;
      }
      const int64_t bx = i % bdims.x, by = (i / bdims.x) % bdims.y, bz = i / (int64_t(bdims.x) * bdims.y);
      S* o = out + int64_t(s) * 128;
      for (int k = int(lane); k < 64; k += 32) {
        float a, b;
        const bool in = subPartRange(data, dims, cellDims, brick, bx, by, bz, k, a, b);
        o[k] = in ? S(a) : S(0);  // a part outside the volume is never read (subPartInVolume)
        o[64 + k] = in ? S(b) : S(0);
      }
      continue;
    }
    const float lo = vmin[i], hi = vmax[i];
    if (integral && lo == hi) {
      if (lane == 0) slot[i] = 0;
      continue;
    }
    const int64_t bx = i % bdims.x, by = (i / bdims.x) % bdims.y, bz = i / (int64_t(bdims.x) * bdims.y);
    bool differs = false;
    for (int k = int(lane); k < 64; k += 32) {
      float a, b;
      if (subPartRange(data, dims, cellDims, brick, bx, by, bz, k, a, b) && !(a == lo && b == hi)) differs = true;
    }
    const bool any = __any_sync(0xffffffffu, differs);
    if (lane == 0) slot[i] = any ? 1u : 0u;
  }
}

// Launch shape: as subMaskKernel's grid; nothing when more than `maxCount` bricks are listed;
// else a half-warp per occupied brick of `list` (two bricks a warp in turn), four of its 64
// parts a lane (parts sub, sub + 16, sub + 32, sub + 48): twice the loads in flight of a warp
// per brick, the kernel being bound by the chain list -> slot -> bounds -> table. The mask from
// the stored bounds (or the brick's range for a uniform brick): the bits subPartSet gives from
// the voxels.
template <class S>
__global__ void rangeMaskKernel(const S* ranges, const uint32_t* slot, const float* vmin, const float* vmax,
                                vec3i cellDims, vec3i bdims, int brick, OpacityRangeMaxView rmq, int maxSet,
                                const uint32_t* list, const unsigned* listCount, unsigned maxCount, uint64_t* masks,
                                uint8_t* state, unsigned long long* setParts) {
  const unsigned lane = threadIdx.x & 31, half = lane >> 4, sub = lane & 15;
  const unsigned warp = (blockIdx.x * blockDim.x + threadIdx.x) >> 5, warps = (gridDim.x * blockDim.x) >> 5;
  const unsigned count = *listCount;
  if (count > maxCount) return;  // too many occupied bricks for the edit's path: a later frame's
  unsigned long long set = 0;
  for (unsigned base = 2 * warp; base < count; base += 2 * warps) {
    const unsigned w = base + half;
    const bool valid = w < count;
    int64_t i = 0, bx = 0, by = 0, bz = 0;
    bool bit[4] = {false, false, false, false};
    if (valid) {
      i = list[w];
      bx = i % bdims.x, by = (i / bdims.x) % bdims.y, bz = i / (int64_t(bdims.x) * bdims.y);
      const uint32_t s = slot[i];
      float lo[4], hi[4];
      if (s == kUniformBrick) {
        const float a = vmin[i], b = vmax[i];
        for (int j = 0; j < 4; ++j) lo[j] = a, hi[j] = b;
      } else {
        const S* r = ranges + int64_t(s) * 128;
        for (int j = 0; j < 4; ++j) {
          lo[j] = float(r[int(sub) + 16 * j]);
          hi[j] = float(r[64 + int(sub) + 16 * j]);
        }
      }
      for (int j = 0; j < 4; ++j)
        bit[j] = subPartInVolume(cellDims, brick, bx, by, bz, int(sub) + 16 * j) && rmq.query(lo[j], hi[j]) > 0.f;
    }
    uint64_t m = 0;
    for (int j = 0; j < 4; ++j)
      m |= uint64_t((__ballot_sync(0xffffffffu, bit[j]) >> (16 * half)) & 0xffffu) << (16 * j);
    if (valid && sub == 0) {
      masks[i] = m;
      state[i] = subBrickState(true, m, maxSet);
      set += unsigned(popcount64(m));
    }
  }
  if (set) atomicAdd(setParts + warp % kPartCounters, set);
}

// Launch shape: one thread per brick, 256 per block. markedDistance; without states (no masks)
// the marks are cleared.
__global__ void markKernel(uint8_t* dist, const uint8_t* state, int64_t n) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n) dist[i] = state ? markedDistance(dist[i], state[i]) : uint8_t(dist[i] & 0x7f);
}

}  // namespace

cudaError_t brickRanges(const void* d_voxels, VoxelType type, int components, vec3l dims, vec3i bdims, int brick,
                        float* d_vmin, float* d_vmax, cudaStream_t stream) {
  const int64_t nb = int64_t(bdims.x) * bdims.y * bdims.z;
  dispatchVoxelType(type, [&](auto t) {
    using T = decltype(t);
    dispatchComponents(components, [&](auto nc) {
      rangeKernel<T, decltype(nc)::value><<<blocksFor(nb, kThreads), kThreads, 0, stream>>>(
          static_cast<const T*>(d_voxels), dims, bdims, brick, d_vmin, d_vmax);
    });
  });
  return cudaPeekAtLastError();
}

cudaError_t classifyBricks(const float* d_vmin, const float* d_vmax, vec3i bdims, int brick, vec3i cellDims,
                           const OpacityRangeMaxView& rmq, const CropClip& cc, const uint8_t* d_prev, uint8_t* d_occ,
                           ClassifyFlags* d_flags, cudaStream_t stream, uint8_t* d_state, uint32_t* d_list,
                           const GradientRowsView& rows) {
  const int64_t n = int64_t(bdims.x) * bdims.y * bdims.z;
  classifyKernel<<<blocksFor(n, kThreads), kThreads, 0, stream>>>(d_vmin, d_vmax, bdims, brick, cellDims, rmq, cc,
                                                                  d_prev, d_occ, &d_flags->occupied,
                                                                  &d_flags->changed, &d_flags->grew, d_state, d_list,
                                                                  &d_flags->listCount, rows);
  return cudaPeekAtLastError();
}

void BrickClassification::setVolume(const DeviceVolume& v, int b, cudaStream_t stream) {
  const Volume& vol = v.volume();
  haveOcc = false;
  labelSetsOnDevice_ = false;
  setFraction = 1.0;
  brick = std::max(1, b);
  cellDims = vol.cellDims();
  d_voxels_ = v.d_voxels<unsigned char>();
  type_ = vol.type;
  dims_ = vol.dims;
  components_ = vol.components;
  std::copy(vol.spacing, vol.spacing + 3, spacing_);
  bdims = vec3i{(cellDims.x + brick - 1) / brick, (cellDims.y + brick - 1) / brick, (cellDims.z + brick - 1) / brick};
  const size_t nb = size_t(numBricks());
  d_vmin.reserve(nb);
  d_vmax.reserve(nb);
  d_occ[0].reserve(nb);
  d_occ[1].reserve(nb);
  SS_CUDA_CHECK(brickRanges(v.d_voxels<unsigned char>(), vol.type, vol.components, vol.dims, bdims, brick, d_vmin.get(), d_vmax.get(),
                            stream));
  computePartRanges(stream);
}

bool BrickClassification::valueRange(double& lo, double& hi, cudaStream_t stream) {
  const int64_t nb = numBricks();
  if (nb <= 0 || nb > int64_t(INT32_MAX) || !d_vmin.get() || !d_vmax.get()) return false;
  d_range_.reserve(2);
  size_t a = 0, b = 0;
  SS_CUDA_CHECK(cub::DeviceReduce::Min(nullptr, a, d_vmin.get(), d_range_.get(), int(nb), stream));
  SS_CUDA_CHECK(cub::DeviceReduce::Max(nullptr, b, d_vmax.get(), d_range_.get() + 1, int(nb), stream));
  const size_t bytes = std::max(a, b);
  void* temp = rangeTemp_.ensure(bytes);
  a = b = bytes;
  SS_CUDA_CHECK(cub::DeviceReduce::Min(temp, a, d_vmin.get(), d_range_.get(), int(nb), stream));
  SS_CUDA_CHECK(cub::DeviceReduce::Max(temp, b, d_vmax.get(), d_range_.get() + 1, int(nb), stream));
  float h[2] = {0, 0};
  SS_CUDA_CHECK(cudaMemcpyAsync(h, d_range_.get(), sizeof h, cudaMemcpyDeviceToHost, stream));
  SS_CUDA_CHECK(cudaStreamSynchronize(stream));
  lo = h[0];
  hi = h[1];
  return true;
}

void BrickClassification::computePartRanges(cudaStream_t stream) {
  // The buffers are kept from step to step (a time step's ranges land in them): a cudaFree
  // would wait for the whole device, the next step's copy on the prefetch stream included.
  havePartRanges_ = false;
  partRangeBytes_ = 0;
  if (!d_voxels_ || components_ != 1 || !usesSubMasks(brick)) return;
  // Tuning::partRanges off (read at setVolume): no bounds stored, the masks from the voxels on
  // the frame after an edit's.
  if (!tuning.partRanges) return;
  const int64_t nb = numBricks();
  if (nb <= 0 || nb >= int64_t(kUniformBrick)) return;
  if (numSMs_ == 0) numSMs_ = multiprocessors();
  const size_t volumeBytes = size_t(dims_.x) * size_t(dims_.y) * size_t(dims_.z) * voxelSize(type_);
  try {
    d_partFlags_.reserve(size_t(nb));
    uint32_t* flags = d_partFlags_.get();
    d_partSlot_.reserve(size_t(nb));
    dispatchVoxelType(type_, [&](auto t) {
      using T = decltype(t);
      using S = typename PartRangeStore<T>::type;
      const T* data = static_cast<const T*>(d_voxels_);
      partRangeKernel<T><<<numSMs_ * kRangeBlocksPerSM, kThreads, 0, stream>>>(
          data, dims_, cellDims, bdims, brick, d_vmin.get(), d_vmax.get(), nullptr, flags, nullptr);
      SS_CUDA_CHECK_LAUNCH(partRangeKernel);
      size_t tempBytes = 0;
      SS_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(nullptr, tempBytes, flags, d_partSlot_.get(), nb, stream));
      void* temp = partScanTemp_.ensure(tempBytes);
      SS_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(temp, tempBytes, flags, d_partSlot_.get(), nb, stream));
      uint32_t last[2] = {0, 0};
      SS_CUDA_CHECK(cudaMemcpyAsync(&last[0], d_partSlot_.get() + nb - 1, sizeof(uint32_t), cudaMemcpyDeviceToHost, stream));
      SS_CUDA_CHECK(cudaMemcpyAsync(&last[1], flags + nb - 1, sizeof(uint32_t), cudaMemcpyDeviceToHost, stream));
      SS_CUDA_CHECK(cudaStreamSynchronize(stream));
      const size_t slots = size_t(last[0]) + size_t(last[1]);
      const size_t bytes = slots * 128 * sizeof(S);
      if (bytes + size_t(nb) * sizeof(uint32_t) > volumeBytes / 4) {
        d_partRanges_.release();  // a no-op from the second such step on
        return;
      }
      if (d_partRanges_.capacity() > 2 * std::max<size_t>(bytes, 1)) d_partRanges_.release();  // only what is needed
      d_partRanges_.reserve(std::max<size_t>(bytes, 1));
      partRangeKernel<T><<<numSMs_ * kRangeBlocksPerSM, kThreads, 0, stream>>>(
          data, dims_, cellDims, bdims, brick, d_vmin.get(), d_vmax.get(), flags, d_partSlot_.get(),
          reinterpret_cast<S*>(d_partRanges_.get()));
      SS_CUDA_CHECK_LAUNCH(partRangeKernel);
      partRangeBytes_ = bytes + size_t(nb) * sizeof(uint32_t);
      havePartRanges_ = true;
    });
  } catch (const BackendError&) {
    // No room on the device: the masks come from the voxels on the frame after an edit.
    (void)cudaGetLastError();
    dropPartRanges();
  }
}

void BrickClassification::masksFromRanges(cudaStream_t stream, unsigned maxCount) {
  const int maxSet = subMaskMaxSet(tuning);
  dispatchVoxelType(type_, [&](auto t) {
    using S = typename PartRangeStore<decltype(t)>::type;
    rangeMaskKernel<S><<<numSMs_ * kMaskBlocksPerSM, kThreads, 0, stream>>>(
        reinterpret_cast<const S*>(d_partRanges_.get()), d_partSlot_.get(), d_vmin.get(), d_vmax.get(), cellDims, bdims,
        brick, rmq_, maxSet, d_list_.get(), &d_flags_.get()->listCount, maxCount, d_sub_.get(), d_state_.get(),
        d_flags_.get()->setParts);
  });
  SS_CUDA_CHECK_LAUNCH(rangeMaskKernel);
}

void BrickClassification::setRanges(const Volume& vol, const RangeGrid& r, cudaStream_t stream) {
  haveOcc = false;
  setFraction = 1.0;
  d_voxels_ = nullptr;  // sparse residency: no voxels on the device, no sub-brick masks
  dropPartRanges();
  brick = r.brick;
  cellDims = vol.cellDims();
  std::copy(vol.spacing, vol.spacing + 3, spacing_);
  bdims = r.dims;
  const size_t nb = size_t(numBricks());
  d_vmin.reserve(nb);
  d_vmax.reserve(nb);
  d_occ[0].reserve(nb);
  d_occ[1].reserve(nb);
  SS_CUDA_CHECK(cudaMemcpyAsync(d_vmin.get(), r.vmin.data(), nb * sizeof(float), cudaMemcpyHostToDevice, stream));
  SS_CUDA_CHECK(cudaMemcpyAsync(d_vmax.get(), r.vmax.data(), nb * sizeof(float), cudaMemcpyHostToDevice, stream));
}

// After a classification kernel wrote d_occ[1 - cur] and its flags: waits for the flags, makes
// the new occupancy current and takes its counts; `changed` as classify() returns it.
const ClassifyFlags* BrickClassification::finishClassification(cudaStream_t stream, bool& changed) {
  auto* flags = static_cast<ClassifyFlags*>(h_flags_.get());
  SS_CUDA_CHECK(cudaMemcpyAsync(flags, d_flags_.get(), sizeof(ClassifyFlags), cudaMemcpyDeviceToHost, stream));
  const auto waitStart = std::chrono::steady_clock::now();
  SS_CUDA_CHECK(cudaStreamSynchronize(stream));
  waitSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - waitStart).count();
  cur = 1 - cur;
  changed = !haveOcc || flags->changed != 0;
  grew = !haveOcc || flags->grew != 0;
  if (changed) ++generation;
  haveOcc = true;
  occupied = int64_t(flags->occupied);
  return flags;
}

bool BrickClassification::classify(const TransferFunction& tf, const CropClip& cc, cudaStream_t stream) {
  // The sparse table over the TF's (uncorrected) opacity, built as on the CPU, queried on the device.
  const OpacityRangeMax table(tf);
  uploadLevelsIfChanged(table.levels(), d_levels_, h_levels_, levelBytes_, stream);
  OpacityRangeMaxView rmq = table.view();
  rmq.levels = d_levels_.get();
  // A 2-D function over the gradient: its row-prefix tables, queried with each brick's
  // neighbourhood range (GradientBound.h), as on the CPU.
  const GradientRows gradRows(tf, spacing_);
  GradientRowsView rows = gradRows.view();
  if (!gradRows.empty()) {
    uploadLevelsIfChanged(gradRows.levels(), d_rowLevels_, h_rowLevels_, rowLevelBytes_, stream);
    rows.prefix.levels = d_rowLevels_.get();
  }

  const uint8_t* prev = haveOcc ? d_occ[cur].get() : nullptr;
  uint8_t* next = d_occ[1 - cur].get();
  d_flags_.reserve(1);
  SS_CUDA_CHECK(cudaMemsetAsync(d_flags_.get(), 0, sizeof(ClassifyFlags), stream));
  haveSub_ = d_voxels_ && components_ == 1 && usesSubMasks(brick) && tuning.subMasks;
  const int64_t nb = numBricks();
  if (haveSub_) {
    d_sub_.reserve(size_t(nb));
    d_state_.reserve(size_t(nb));
    d_list_.reserve(size_t(nb));
  }
  SS_CUDA_CHECK(classifyBricks(d_vmin.get(), d_vmax.get(), bdims, brick, cellDims, rmq, cc, prev, next, d_flags_.get(),
                               stream, haveSub_ ? d_state_.get() : nullptr, haveSub_ ? d_list_.get() : nullptr, rows));
  rmq_ = rmq;
  // The masks on the edit's path where the part walk can pay: at most 1/editMaskShare of the
  // bricks occupied (the kernel learns the count on the device and does nothing above it).
  const unsigned editMaxCount =
      unsigned(std::min<int64_t>(nb / std::max<int64_t>(editMaskShare, 1), int64_t(kUniformBrick)));
  const bool onPath = haveSub_ && havePartRanges_ && setFraction <= editMaskMaxShare;
  if (onPath) masksFromRanges(stream, editMaxCount);
  bool changed = false;
  const ClassifyFlags* flags = finishClassification(stream, changed);
  const bool masked = onPath && flags->listCount <= editMaxCount;
  if (masked) setFraction = setShare(flags->setParts, occupied);
  // Otherwise the masks follow on a later frame (refreshMasks): the edit's own frame marches
  // whole bricks.
  masksReady_ = masked;
  hostOccValid_ = false;
  return changed;
}

void BrickClassification::refreshMasks(cudaStream_t stream) {
  if (!masksPending()) return;
  if (numSMs_ == 0) numSMs_ = multiprocessors();
  const int maxSet = subMaskMaxSet(tuning);
  // setParts is zeroed by classify()'s memset (a range mask kernel over its limit added nothing);
  // the list and its count are classify()'s.
  if (havePartRanges_) {
    masksFromRanges(stream, kUniformBrick);
  } else {
    dispatchVoxelType(type_, [&](auto t) {
      using T = decltype(t);
      subMaskKernel<T><<<numSMs_ * kMaskBlocksPerSM, kThreads, 0, stream>>>(
          static_cast<const T*>(d_voxels_), dims_, cellDims, bdims, brick, rmq_, maxSet, d_list_.get(),
          &d_flags_.get()->listCount, d_sub_.get(), d_state_.get(), d_flags_.get()->setParts);
    });
    SS_CUDA_CHECK_LAUNCH(subMaskKernel);
  }
  auto* flags = static_cast<ClassifyFlags*>(h_flags_.get());
  SS_CUDA_CHECK(cudaMemcpyAsync(flags->setParts, d_flags_.get()->setParts, sizeof(flags->setParts),
                                cudaMemcpyDeviceToHost, stream));
  SS_CUDA_CHECK(cudaStreamSynchronize(stream));
  setFraction = setShare(flags->setParts, occupied);
  masksReady_ = true;
}

void BrickClassification::markDistances(uint8_t* d_dist, cudaStream_t stream) const {
  const int64_t n = numBricks();
  if (n <= 0) return;
  markKernel<<<blocksFor(n, kThreads), kThreads, 0, stream>>>(d_dist, brickStates(), n);
  SS_CUDA_CHECK_LAUNCH(markKernel);
}

SubMasks BrickClassification::downloadMasks(cudaStream_t stream) {
  SubMasks out;
  if (!haveSub_) return out;
  if (masksPending()) refreshMasks(stream);
  const size_t n = size_t(numBricks());
  out.mask.resize(n);
  out.state.resize(n);
  SS_CUDA_CHECK(cudaMemcpyAsync(out.mask.data(), d_sub_.get(), n * sizeof(uint64_t), cudaMemcpyDeviceToHost, stream));
  SS_CUDA_CHECK(cudaMemcpyAsync(out.state.data(), d_state_.get(), n, cudaMemcpyDeviceToHost, stream));
  SS_CUDA_CHECK(cudaStreamSynchronize(stream));
  for (size_t i = 0; i < n; ++i)
    if (out.state[i] == kBrickEmpty) out.mask[i] = 0;
  out.share = setFraction;
  return out;
}

bool BrickClassification::classifyLabels(const LabelSets& ls, const std::vector<uint8_t>& drawn, const CropClip& cc,
                                         cudaStream_t stream) {
  if (ls.size() != numBricks() || ls.brick != brick)
    throw BackendError("label classification: the label sets do not match the volume's bricks");
  // The sets go to the device once per volume and brick size (the engine computes them after
  // setVolume, which forgets the device copy), the per-value flags on every edit (a few KiB).
  if (!labelSetsOnDevice_) {
    d_labelOffset_.reserve(ls.offset.size());
    d_labels_.reserve(std::max<size_t>(ls.labels.size(), 1));
    SS_CUDA_CHECK(cudaMemcpyAsync(d_labelOffset_.get(), ls.offset.data(), ls.offset.size() * sizeof(int64_t),
                                  cudaMemcpyHostToDevice, stream));
    if (!ls.labels.empty())
      SS_CUDA_CHECK(cudaMemcpyAsync(d_labels_.get(), ls.labels.data(), ls.labels.size() * sizeof(uint16_t),
                                    cudaMemcpyHostToDevice, stream));
    SS_CUDA_CHECK(cudaStreamSynchronize(stream));  // the host vectors may go
    labelSetsOnDevice_ = true;
  }
  const size_t nd = std::max<size_t>(drawn.size(), 1);
  d_drawn_.reserve(nd);
  h_drawn_.reserve(nd);
  if (!drawn.empty()) std::memcpy(h_drawn_.get(), drawn.data(), drawn.size());
  SS_CUDA_CHECK(cudaMemcpyAsync(d_drawn_.get(), h_drawn_.get(), drawn.size(), cudaMemcpyHostToDevice, stream));
  const uint8_t* prev = haveOcc ? d_occ[cur].get() : nullptr;
  uint8_t* next = d_occ[1 - cur].get();
  d_flags_.reserve(1);
  SS_CUDA_CHECK(cudaMemsetAsync(d_flags_.get(), 0, sizeof(ClassifyFlags), stream));
  const int64_t n = numBricks();
  labelClassifyKernel<<<blocksFor(n, kThreads), kThreads, 0, stream>>>(
      d_labelOffset_.get(), d_labels_.get(), d_drawn_.get(), bdims, brick, cellDims, cc, prev, next,
      &d_flags_.get()->occupied, &d_flags_.get()->changed, &d_flags_.get()->grew);
  SS_CUDA_CHECK(cudaPeekAtLastError());
  bool changed = false;
  finishClassification(stream, changed);
  haveSub_ = false;  // no masks: a label edit reads no voxel
  masksReady_ = false;
  hostOccValid_ = false;
  return changed;
}

const OccupancyGrid& BrickClassification::occupancy(cudaStream_t stream) {
  if (!hostOccValid_) {
    hostOcc_ = OccupancyGrid{};
    hostOcc_.brick = brick;
    hostOcc_.cellDims = cellDims;
    hostOcc_.dims = bdims;
    if (haveOcc) {
      hostOcc_.occ.resize(size_t(numBricks()));
      SS_CUDA_CHECK(cudaMemcpyAsync(hostOcc_.occ.data(), d_occ[cur].get(), hostOcc_.occ.size(), cudaMemcpyDeviceToHost,
                                    stream));
      SS_CUDA_CHECK(cudaStreamSynchronize(stream));
      hostOcc_.occupied = occupied;
    }
    hostOccValid_ = true;
  }
  return hostOcc_;
}

}  // namespace spaceskip::cuda

namespace spaceskip {
SubMasks computeSubMasksCuda(const Volume& v, const TransferFunction& tf, int brick, int path, size_t* rangeBytes) {
  std::string why;
  if (!cudaAvailable(&why)) throw BackendError(why);
  cuda::DeviceVolume dv;
  cuda::BrickClassification cls;
  dv.upload(v, nullptr);
  cls.setVolume(dv, brick, nullptr);
  if (path == 0) cls.dropPartRanges();
  cls.editMaskShare = path == 1 ? 1 : int64_t(1) << 40;  // every brick may be listed, or none
  cls.editMaskMaxShare = path == 1 ? 2.0 : 0.0;
  if (rangeBytes) *rangeBytes = cls.partRangeBytes();
  cls.classify(tf, CropClip{}, nullptr);
  return cls.downloadMasks(nullptr);
}
}  // namespace spaceskip

// DistanceGrid's distance field on the device (see DistanceField.cuh).
#include "DistanceField.cuh"
#include "spaceskip/Backend.h"
#include "spaceskip/DistanceField.h"

#include <algorithm>
#include <cstdlib>
#include <string>

namespace spaceskip::cuda {

namespace {

constexpr int kThreads = 256;

__global__ void seedKernel(const uint8_t* occ, int64_t n, uint8_t cap, uint8_t* out) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n) out[i] = occ[i] ? 0 : cap;
}

// Launch shape: one thread per line of the brick grid along `axis` (lines numbered by their
// position on the other two axes, the first of them fastest), kLineThreads a block; each thread
// keeps distanceLine's cap + 1 ints of scratch in shared memory, interleaved across the block's
// threads (bank-conflict free). O(1) a brick, where the per-brick pass was O(distance).
constexpr int kLineThreads = 32;
__device__ int64_t lineStart(vec3i dims, int axis, int64_t l) {
  const int u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;
  auto stride = [&](int a) { return a == 0 ? int64_t(1) : a == 1 ? int64_t(dims.x) : int64_t(dims.x) * dims.y; };
  return stride(u) * (l % dims[u]) + stride(w) * (l / dims[u]);
}
__device__ int64_t axisStride(vec3i dims, int axis) {
  return axis == 0 ? int64_t(1) : axis == 1 ? int64_t(dims.x) : int64_t(dims.x) * dims.y;
}
__global__ void lineKernel(const uint8_t* in, vec3i dims, int axis, int cap, uint8_t* out) {
  extern __shared__ int lastScratch[];
  const int u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;
  const int64_t lines = int64_t(dims[u]) * dims[w];
  const int64_t l = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (l >= lines) return;
  distanceLine(in, out, lineStart(dims, axis, l), axisStride(dims, axis), dims[axis], cap, lastScratch + threadIdx.x,
               int(blockDim.x));
}

// Sixteen bricks, one 16-byte load or store.
union Bytes16 {
  uint4 v;
  uint8_t c[16];
};

// The block's lines move in 16-byte pieces when they are whole aligned pieces of the grid: a
// full block of 32 lines that are one run of bytes (axis 0: consecutive rows, n a multiple of
// 16) or 32 adjacent bytes at each position (the other axes: the lines' first bricks adjacent,
// the stride a multiple of 16), `in` and `out` aligned alike. Two loads a position instead of
// 32 single-byte ones (and no division a byte). On the H100 at N-body 2048^3 the three passes
// took 97 / 87 / 88 us instead of 161 / 129 / 130 (Nsight Compute), the field 0.23 instead of
// 0.34 ms (docs/results/h100-distance-field).
__device__ bool vectorStaging(const uint8_t* in, const uint8_t* out, const int64_t* starts, int nl, int n, int axis,
                              int64_t stride) {
  const int64_t step = axis == 0 ? n : 1;
  const auto aligned = [&](const uint8_t* p) { return (reinterpret_cast<uintptr_t>(p + starts[0]) & 15) == 0; };
  return nl == kLineThreads && starts[kLineThreads - 1] - starts[0] == (kLineThreads - 1) * step &&
         (axis == 0 ? n % 16 == 0 : stride % 16 == 0) && aligned(in) && aligned(out);
}

// The block's 32 lines staged in shared memory, `segs` threads a line (distanceSegment): the
// block first copies its lines in (for axis 0 the 32 lines are one run of bytes, read in order;
// for the other axes 32 consecutive lines are 32 consecutive bytes at each position), the
// threads sweep their segments there (each sweep's steps depend on one another: a line cut in
// `segs` segments shortens that chain from 2n to 2(n/segs + cap) steps, and gives the SM `segs`
// times as many warps to hide it behind), then the block writes the lines back the same way.
// Line k of the block at staged[i * kLineThreads + k]. Seed: `in` is the occupancy (0 / not 0)
// and the pass reads it as 0 (occupied) / cap (empty), which saves a pass over the grid.
template <bool Seed>
__global__ void stagedLineKernel(const uint8_t* in, vec3i dims, int axis, int cap, int segs, uint8_t* out) {
  extern __shared__ __align__(16) int shared[];
  __shared__ int64_t starts[kLineThreads];
  const int n = dims[axis];
  const int threads = int(blockDim.x);
  int16_t* last = reinterpret_cast<int16_t*>(shared);
  uint8_t* stagedIn = reinterpret_cast<uint8_t*>(last + (cap + 1) * threads);
  uint8_t* stagedOut = stagedIn + size_t(n) * kLineThreads;
  const int u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;
  const int64_t lines = int64_t(dims[u]) * dims[w];
  const int64_t l0 = int64_t(blockIdx.x) * kLineThreads;
  const int nl = lines - l0 < kLineThreads ? int(lines - l0) : kLineThreads;
  if (threadIdx.x < kLineThreads) starts[threadIdx.x] = int(threadIdx.x) < nl ? lineStart(dims, axis, l0 + threadIdx.x) : 0;
  __syncthreads();
  const int64_t stride = axisStride(dims, axis);
  const int total = n * kLineThreads;
  const bool vec = vectorStaging(in, out, starts, nl, n, axis, stride);
  const uint8_t capByte = uint8_t(cap);
  if (vec && axis == 0) {
    // 32 rows of n bricks, one run: piece p is line p % 32's bricks 16 (p / 32) .. + 15.
    for (int p = int(threadIdx.x); p < total / 16; p += threads) {
      const int k = p % kLineThreads, i0 = 16 * (p / kLineThreads);
      Bytes16 b;
      b.v = *reinterpret_cast<const uint4*>(in + starts[0] + int64_t(k) * n + i0);
#pragma unroll
      for (int j = 0; j < 16; ++j)
        stagedIn[(i0 + j) * kLineThreads + k] = Seed ? (b.c[j] ? uint8_t(0) : capByte) : b.c[j];
    }
  } else if (vec) {
    // At each position the 32 lines are 32 adjacent bytes: the staged row itself.
    for (int p = int(threadIdx.x); p < total / 16; p += threads) {
      const int i = p >> 1, h = 16 * (p & 1);
      Bytes16 b;
      b.v = *reinterpret_cast<const uint4*>(in + starts[0] + stride * i + h);
      if (Seed) {
#pragma unroll
        for (int j = 0; j < 16; ++j) b.c[j] = b.c[j] ? uint8_t(0) : capByte;
      }
      *reinterpret_cast<uint4*>(stagedIn + i * kLineThreads + h) = b.v;
    }
  } else {
    for (int o = int(threadIdx.x); o < total; o += threads) {
      const int k = axis == 0 ? o / n : o % kLineThreads, i = axis == 0 ? o % n : o / kLineThreads;
      if (k >= nl) continue;
      const uint8_t v = in[starts[k] + stride * i];
      stagedIn[i * kLineThreads + k] = Seed ? (v ? uint8_t(0) : capByte) : v;
    }
  }
  __syncthreads();
  const int k = int(threadIdx.x) % kLineThreads, s = int(threadIdx.x) / kLineThreads;
  const int segLen = (n + segs - 1) / segs;
  const int a = s * segLen, b = a + segLen < n ? a + segLen : n;
  if (k < nl && a < b) distanceSegment(stagedIn, stagedOut, k, kLineThreads, n, a, b, cap, last + threadIdx.x, threads);
  __syncthreads();
  if (vec && axis == 0) {
    for (int p = int(threadIdx.x); p < total / 16; p += threads) {
      const int kk = p % kLineThreads, i0 = 16 * (p / kLineThreads);
      Bytes16 b;
#pragma unroll
      for (int j = 0; j < 16; ++j) b.c[j] = stagedOut[(i0 + j) * kLineThreads + kk];
      *reinterpret_cast<uint4*>(out + starts[0] + int64_t(kk) * n + i0) = b.v;
    }
  } else if (vec) {
    for (int p = int(threadIdx.x); p < total / 16; p += threads) {
      const int i = p >> 1, h = 16 * (p & 1);
      *reinterpret_cast<uint4*>(out + starts[0] + stride * i + h) =
          *reinterpret_cast<const uint4*>(stagedOut + i * kLineThreads + h);
    }
  } else {
    for (int o = int(threadIdx.x); o < total; o += threads) {
      const int kk = axis == 0 ? o / n : o % kLineThreads, i = axis == 0 ? o % n : o / kLineThreads;
      if (kk < nl) out[starts[kk] + stride * i] = stagedOut[i * kLineThreads + kk];
    }
  }
}

/// Dynamic shared memory of stagedLineKernel: the scratch (cap + 1 int16 a thread) and the
/// block's lines, in and out.
size_t stagedBytes(int n, int cap, int segs) {
  return size_t(cap + 1) * kLineThreads * size_t(segs) * sizeof(int16_t) + 2 * size_t(n) * kLineThreads;
}
constexpr size_t kStagedMaxBytes = 96 * 1024;  // opted in (the default is 48 KiB)

/// Threads a line for lines of n bricks: up to 8, segments of at least 32 bricks, within
/// kStagedMaxBytes; `maxSegments` (Tuning::distanceSegments) caps it. 0: the unstaged
/// kernel, for lines shorter than 128 bricks or too long for shared memory. On the H100 the
/// staged kernel was slower than the unstaged one with one segment a line (N-body 2048^3: 0.73-1.17
/// vs 0.62 ms a build) and on lines of 64-104 bricks (two segments: 0.07-0.10 vs 0.05-0.08 ms),
/// faster with 4-8 segments on lines of 128-256 bricks (2048^3: 0.45 ms; 128 bricks: 0.09 vs
/// 0.12 ms) (docs/results/HISTORY.md, distance-field segments).
int segmentsFor(int n, int cap, int maxSegments) {
  if (n < 128) return 0;
  for (int segs = std::min(std::max(1, maxSegments), 8); segs >= 2; segs /= 2)
    if (n >= 32 * segs && stagedBytes(n, cap, segs) <= kStagedMaxBytes) return segs;
  return 0;
}

}  // namespace

const uint8_t* computeDistanceField(const uint8_t* occ, vec3i dims, int cap, DistanceWorkspace& ws,
                                    cudaStream_t stream, int maxSegments) {
  cap = cap < 1 ? 1 : cap > 255 ? 255 : cap;
  const int64_t n = int64_t(dims.x) * dims.y * dims.z;
  ws.a.reserve(size_t(n));
  ws.b.reserve(size_t(n));
  static const bool optedIn = [] {
    return cudaFuncSetAttribute(stagedLineKernel<true>, cudaFuncAttributeMaxDynamicSharedMemorySize,
                                int(kStagedMaxBytes)) == cudaSuccess &&
           cudaFuncSetAttribute(stagedLineKernel<false>, cudaFuncAttributeMaxDynamicSharedMemorySize,
                                int(kStagedMaxBytes)) == cudaSuccess;
  }();
  if (!optedIn) (void)cudaGetLastError();
  // The unstaged kernel's scratch: (cap + 1) * 32 ints, at most 32 KiB.
  const size_t shared = size_t(cap + 1) * kLineThreads * sizeof(int);
  // Passes: occupancy -> a (seeded), a -> b, b -> a.
  const uint8_t* src[3] = {occ, ws.a.get(), ws.b.get()};
  uint8_t* dst[3] = {ws.a.get(), ws.b.get(), ws.a.get()};
  for (int axis = 0; axis < 3; ++axis) {
    const int u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;
    const int64_t lines = int64_t(dims[u]) * dims[w];
    if (lines <= 0) continue;
    int segs = segmentsFor(dims[axis], cap, maxSegments);
    if (!optedIn && stagedBytes(dims[axis], cap, segs) > 48 * 1024) segs = 0;
    if (segs > 0) {
      const size_t bytes = stagedBytes(dims[axis], cap, segs);
      const int blocks = int((lines + kLineThreads - 1) / kLineThreads);
      if (axis == 0)
        stagedLineKernel<true><<<blocks, kLineThreads * segs, bytes, stream>>>(src[0], dims, 0, cap, segs, dst[0]);
      else
        stagedLineKernel<false><<<blocks, kLineThreads * segs, bytes, stream>>>(src[axis], dims, axis, cap, segs,
                                                                               dst[axis]);
      SS_CUDA_CHECK_LAUNCH(stagedLineKernel);
    } else {
      const uint8_t* from = src[axis];
      if (axis == 0) {  // seed into b (free until pass 2), then the pass reads it
        seedKernel<<<blocksFor(n, kThreads), kThreads, 0, stream>>>(occ, n, uint8_t(cap), ws.b.get());
        SS_CUDA_CHECK_LAUNCH(seedKernel);
        from = ws.b.get();
      }
      lineKernel<<<blocksFor(lines, kLineThreads), kLineThreads, shared, stream>>>(from, dims, axis, cap, dst[axis]);
      SS_CUDA_CHECK_LAUNCH(lineKernel);
    }
  }
  SS_CUDA_CHECK(cudaStreamSynchronize(stream));
  return ws.a.get();
}

std::vector<uint8_t> fieldOnDevice(const OccupancyGrid& occ, int cap) {
  const size_t n = occ.occ.size();
  DeviceBuffer<uint8_t> d_occ(std::max<size_t>(n, 1));
  DistanceWorkspace ws;
  SS_CUDA_CHECK(cudaMemcpy(d_occ.get(), occ.occ.data(), n, cudaMemcpyHostToDevice));
  const uint8_t* d = computeDistanceField(d_occ.get(), occ.dims, cap, ws, nullptr);
  std::vector<uint8_t> out(n);
  SS_CUDA_CHECK(cudaMemcpy(out.data(), d, n, cudaMemcpyDeviceToHost));
  return out;
}

}  // namespace spaceskip::cuda

namespace spaceskip {
std::vector<uint8_t> computeDistanceFieldCuda(const OccupancyGrid& occ, int cap) {
  std::string why;
  if (!cudaAvailable(&why)) throw BackendError(why);
  return cuda::fieldOnDevice(occ, cap);
}
}  // namespace spaceskip

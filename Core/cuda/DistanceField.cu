// DistanceGrid's distance field on the device (see DistanceField.cuh).
#include "DistanceField.cuh"
#include "spaceskip/Backend.h"
#include "spaceskip/DistanceField.h"

#include <algorithm>
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

// The same with the block's lines staged in shared memory: every thread first copies its line
// (independent loads the memory system overlaps), sweeps it there (the sweep's steps depend on
// one another: shared-memory latency instead of global), then writes it back. Line k of the
// block at staged[i * kLineThreads + k] (consecutive threads, consecutive bytes).
__global__ void stagedLineKernel(const uint8_t* in, vec3i dims, int axis, int cap, uint8_t* out) {
  extern __shared__ int shared[];
  const int n = dims[axis];
  int* last = shared;
  uint8_t* stagedIn = reinterpret_cast<uint8_t*>(shared + (cap + 1) * kLineThreads);
  uint8_t* stagedOut = stagedIn + size_t(n) * kLineThreads;
  const int u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;
  const int64_t lines = int64_t(dims[u]) * dims[w];
  const int64_t l = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (l >= lines) return;
  const int64_t first = lineStart(dims, axis, l), stride = axisStride(dims, axis);
  for (int i = 0; i < n; ++i) stagedIn[i * kLineThreads + threadIdx.x] = in[first + stride * i];
  distanceLine(stagedIn, stagedOut, threadIdx.x, kLineThreads, n, cap, last + threadIdx.x, kLineThreads);
  for (int i = 0; i < n; ++i) out[first + stride * i] = stagedOut[i * kLineThreads + threadIdx.x];
}

}  // namespace

const uint8_t* computeDistanceField(const uint8_t* occ, vec3i dims, int cap, DistanceWorkspace& ws,
                                    cudaStream_t stream) {
  cap = cap < 1 ? 1 : cap > 255 ? 255 : cap;
  const int64_t n = int64_t(dims.x) * dims.y * dims.z;
  ws.a.reserve(size_t(n));
  ws.b.reserve(size_t(n));
  seedKernel<<<blocksFor(n, kThreads), kThreads, 0, stream>>>(occ, n, uint8_t(cap), ws.a.get());
  SS_CUDA_CHECK_LAUNCH(seedKernel);
  // (cap + 1) * 32 ints: at most 32 KiB, under the default 48 KiB of dynamic shared memory; the
  // staged kernel adds two bytes per brick of the block's 32 lines while that stays under it.
  const size_t shared = size_t(cap + 1) * kLineThreads * sizeof(int);
  uint8_t* bufs[2] = {ws.a.get(), ws.b.get()};
  for (int axis = 0; axis < 3; ++axis) {
    const int u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;
    const int64_t lines = int64_t(dims[u]) * dims[w];
    const size_t staged = shared + 2 * size_t(dims[axis]) * kLineThreads;
    if (lines > 0 && staged <= 48 * 1024) {
      stagedLineKernel<<<blocksFor(lines, kLineThreads), kLineThreads, staged, stream>>>(bufs[axis % 2], dims, axis,
                                                                                       cap, bufs[1 - axis % 2]);
      SS_CUDA_CHECK_LAUNCH(stagedLineKernel);
    } else if (lines > 0) {
      lineKernel<<<blocksFor(lines, kLineThreads), kLineThreads, shared, stream>>>(bufs[axis % 2], dims, axis, cap,
                                                                                 bufs[1 - axis % 2]);
      SS_CUDA_CHECK_LAUNCH(lineKernel);
    }
  }
  SS_CUDA_CHECK(cudaStreamSynchronize(stream));
  return ws.b.get();  // passes a->b, b->a, a->b
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

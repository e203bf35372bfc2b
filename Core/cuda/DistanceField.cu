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
__global__ void lineKernel(const uint8_t* in, vec3i dims, int axis, int cap, uint8_t* out) {
  extern __shared__ int lastScratch[];
  const int u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;
  const int64_t lines = int64_t(dims[u]) * dims[w];
  const int64_t l = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (l >= lines) return;
  auto stride = [&](int a) { return a == 0 ? int64_t(1) : a == 1 ? int64_t(dims.x) : int64_t(dims.x) * dims.y; };
  const int64_t first = stride(u) * (l % dims[u]) + stride(w) * (l / dims[u]);
  distanceLine(in, out, first, stride(axis), dims[axis], cap, lastScratch + threadIdx.x, int(blockDim.x));
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
  // (cap + 1) * 32 ints: at most 32 KiB, under the default 48 KiB of dynamic shared memory.
  const size_t shared = size_t(cap + 1) * kLineThreads * sizeof(int);
  uint8_t* bufs[2] = {ws.a.get(), ws.b.get()};
  for (int axis = 0; axis < 3; ++axis) {
    const int u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;
    const int64_t lines = int64_t(dims[u]) * dims[w];
    if (lines > 0)
      lineKernel<<<blocksFor(lines, kLineThreads), kLineThreads, shared, stream>>>(bufs[axis % 2], dims, axis, cap,
                                                                                 bufs[1 - axis % 2]);
    SS_CUDA_CHECK_LAUNCH(lineKernel);
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

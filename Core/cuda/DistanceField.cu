// DistanceGrid's distance field on the device (see DistanceField.cuh).
#include "DistanceField.cuh"
#include "spaceskip/DistanceField.h"

namespace spaceskip::cuda {

namespace {

constexpr int kThreads = 256;

__global__ void seedKernel(const uint8_t* occ, int64_t n, uint8_t cap, uint8_t* out) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n) out[i] = occ[i] ? 0 : cap;
}

__global__ void passKernel(const uint8_t* in, vec3i dims, int axis, int cap, uint8_t* out) {
  const int64_t n = int64_t(dims.x) * dims.y * dims.z;
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const int64_t sx = 1, sy = dims.x, sz = int64_t(dims.x) * dims.y;
  const int x = int(i % dims.x), y = int((i / dims.x) % dims.y), z = int(i / sz);
  const int64_t stride = axis == 0 ? sx : axis == 1 ? sy : sz;
  const int pos = axis == 0 ? x : axis == 1 ? y : z;
  out[i] = distancePass(in, i, stride, pos, dims[axis], cap);
}

}  // namespace

const uint8_t* computeDistanceField(const uint8_t* occ, vec3i dims, int cap, DistanceWorkspace& ws,
                                    cudaStream_t stream) {
  cap = cap < 1 ? 1 : cap > 255 ? 255 : cap;
  const int64_t n = int64_t(dims.x) * dims.y * dims.z;
  ws.a.reserve(size_t(n));
  ws.b.reserve(size_t(n));
  const unsigned blocks = blocksFor(n, kThreads);
  seedKernel<<<blocks, kThreads, 0, stream>>>(occ, n, uint8_t(cap), ws.a.get());
  SS_CUDA_CHECK_LAUNCH(seedKernel);
  passKernel<<<blocks, kThreads, 0, stream>>>(ws.a.get(), dims, 0, cap, ws.b.get());
  SS_CUDA_CHECK_LAUNCH(passKernel);
  passKernel<<<blocks, kThreads, 0, stream>>>(ws.b.get(), dims, 1, cap, ws.a.get());
  SS_CUDA_CHECK_LAUNCH(passKernel);
  passKernel<<<blocks, kThreads, 0, stream>>>(ws.a.get(), dims, 2, cap, ws.b.get());
  SS_CUDA_CHECK_LAUNCH(passKernel);
  SS_CUDA_CHECK(cudaStreamSynchronize(stream));
  return ws.b.get();
}

}  // namespace spaceskip::cuda

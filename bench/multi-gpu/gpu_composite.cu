// The multi-GPU driver's compositing on the GPUs (mpi_pieces.cpp --composite gpu): every rank's
// float image lies in an exchange buffer that the other ranks of the host map through CUDA IPC;
// each rank blends its band of rows from all of them in visibility order (front to back,
// premultiplied "over") and writes the band straight into rank 0's final image. The images never
// leave the GPUs: the exchange is the blend kernel's reads over NVLink (or PCIe peer access).
#include "gpu_composite.h"

#include <cuda_runtime.h>

namespace spaceskip::mpi {

namespace {

/// Pixels [first, first + count) of dst = src[order[0]] over src[order[1]] over ...
__global__ void blendBand(BandSources s, int n, float4* dst, size_t first, size_t count) {
  const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= count) return;
  const size_t p = first + i;
  float4 acc = make_float4(0.f, 0.f, 0.f, 0.f);
  for (int k = 0; k < n; ++k) {
    const float4 b = static_cast<const float4*>(s.src[s.order[k]])[p];
    const float t = 1.f - acc.w;
    acc.x += t * b.x;
    acc.y += t * b.y;
    acc.z += t * b.z;
    acc.w += t * b.w;
  }
  dst[p] = acc;
}

}  // namespace

int launchBandBlend(const BandSources& s, int n, void* dst, size_t first, size_t count, void* stream) {
  if (count == 0) return 0;
  const int threads = 256;
  const unsigned blocks = unsigned((count + threads - 1) / threads);
  blendBand<<<blocks, threads, 0, static_cast<cudaStream_t>(stream)>>>(s, n, static_cast<float4*>(dst), first, count);
  return int(cudaGetLastError());
}

}  // namespace spaceskip::mpi

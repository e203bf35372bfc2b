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
__global__ void blendBand(BandSources s, int n, vec4f* dst, size_t first, size_t count) {
  const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= count) return;
  const size_t p = first + i;
  vec4f acc{0.f, 0.f, 0.f, 0.f};
  for (int k = 0; k < n; ++k) acc = behind(acc, static_cast<const vec4f*>(s.src[s.order[k]])[p]);
  dst[p] = acc;
}

}  // namespace

int launchBandBlend(const BandSources& s, int n, void* dst, size_t first, size_t count, void* stream) {
  if (count == 0) return 0;
  const int threads = 256;
  const unsigned blocks = unsigned((count + threads - 1) / threads);
  blendBand<<<blocks, threads, 0, static_cast<cudaStream_t>(stream)>>>(s, n, static_cast<vec4f*>(dst), first, count);
  return int(cudaGetLastError());
}

}  // namespace spaceskip::mpi

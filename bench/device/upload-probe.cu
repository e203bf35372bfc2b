// Host-to-device copy paths for a time step's voxels, measured side by side on one machine: what
// bounds HostStaging (Core/cuda/HostStaging.cuh) and whether pinning the caller's pages in place
// (cudaHostRegister) beats copying them through pinned chunks.
//
// Build and run on the GPU machine (nvcc and OpenMP there):
//   nvcc -O2 -Xcompiler -fopenmp -o /tmp/upload-probe bench/device/upload-probe.cu && /tmp/upload-probe [MiB ...]
//
// For each size, the best of 5 (seconds -> GB/s), the source a malloc'd pageable buffer at an
// offset of 64 bytes (as an array's memory is: not page aligned), its pages touched before:
//   pinned      cudaMemcpyAsync from a pinned buffer (the link's rate: the issue's upload bound)
//   pageable    cudaMemcpyAsync from the pageable buffer (the driver's own staging)
//   host copy   the pageable buffer copied into a pinned one on every core (1 MiB pieces), no DMA
//   host+dma    the same host copy while a pinned buffer's DMA runs (memory shared by both)
//   staged      32 MiB pinned chunks, three in a ring, filled on every core while the copy
//               engine moves the ones before (HostStaging's scheme)
//   ramped      the same ring, the chunks growing 4, 8, 16 MiB to 32 MiB at the start and shrinking
//               the same way at the end (a shorter fill before the first DMA and drain after the last)
//   registered  cudaHostRegister of the pageable buffer, its DMA, cudaHostUnregister, all timed;
//               the register and unregister parts printed apart
#include <cuda_runtime.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#define CK(x)                                                                                   \
  do {                                                                                          \
    cudaError_t e_ = (x);                                                                       \
    if (e_ != cudaSuccess) {                                                                    \
      std::fprintf(stderr, "%s:%d %s: %s\n", __FILE__, __LINE__, #x, cudaGetErrorString(e_)); \
      std::exit(1);                                                                             \
    }                                                                                           \
  } while (0)

using Clock = std::chrono::steady_clock;
static double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

static void hostCopy(char* dst, const char* src, size_t n) {
  const size_t piece = size_t(1) << 20, pieces = (n + piece - 1) / piece;
#pragma omp parallel for schedule(static)
  for (long i = 0; i < long(pieces); ++i) {
    const size_t off = size_t(i) * piece;
    std::memcpy(dst + off, src + off, std::min(piece, n - off));
  }
}

template <class F>
static double best(F&& f, int reps = 5) {
  double t = 1e30;
  for (int i = 0; i < reps; ++i) t = std::min(t, f());
  return t;
}

int main(int argc, char** argv) {
  std::vector<size_t> sizes;
  for (int i = 1; i < argc; ++i) sizes.push_back(size_t(std::atoll(argv[i])) << 20);
  if (sizes.empty()) sizes = {size_t(128) << 20, size_t(512) << 20, size_t(1024) << 20};
  cudaDeviceProp prop{};
  CK(cudaGetDeviceProperties(&prop, 0));
  std::printf("device %s, %d host threads\n", prop.name, omp_get_max_threads());
  cudaStream_t s, s2;
  CK(cudaStreamCreateWithFlags(&s, cudaStreamNonBlocking));
  CK(cudaStreamCreateWithFlags(&s2, cudaStreamNonBlocking));
  const size_t kChunk = size_t(32) << 20;
  char* chunk[3];
  cudaEvent_t done[3];
  for (int b = 0; b < 3; ++b) {
    CK(cudaMallocHost(&chunk[b], kChunk));
    CK(cudaEventCreateWithFlags(&done[b], cudaEventDisableTiming));
  }
  std::printf("| MiB | pinned | pageable | host copy | host copy beside a DMA | staged | ramped | registered (all) | "
              "register ms | DMA of registered | unregister ms |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (size_t bytes : sizes) {
    char* raw = static_cast<char*>(std::malloc(bytes + 128));
    char* src = raw + 64;
    for (size_t i = 0; i < bytes; ++i) src[i] = char(i * 2654435761u >> 13);
    char *pinned, *pinned2, *dst, *dst2;
    CK(cudaMallocHost(&pinned, bytes));
    CK(cudaMallocHost(&pinned2, bytes));
    std::memcpy(pinned, src, bytes);
    std::memcpy(pinned2, src, bytes);
    CK(cudaMalloc(&dst, bytes));
    CK(cudaMalloc(&dst2, bytes));
    auto dma = [&](const void* from) {
      const auto t = Clock::now();
      CK(cudaMemcpyAsync(dst, from, bytes, cudaMemcpyHostToDevice, s));
      CK(cudaStreamSynchronize(s));
      return since(t);
    };
    const double tPinned = best([&] { return dma(pinned); });
    const double tPageable = best([&] { return dma(src); });
    const double tHost = best([&] {
      const auto t = Clock::now();
      hostCopy(pinned, src, bytes);
      return since(t);
    });
    const double tHostDma = best([&] {
      CK(cudaMemcpyAsync(dst2, pinned2, bytes, cudaMemcpyHostToDevice, s2));
      const auto t = Clock::now();
      hostCopy(pinned, src, bytes);
      const double d = since(t);
      CK(cudaStreamSynchronize(s2));
      return d;
    });
    auto staged = [&](const std::vector<size_t>& plan) {
      const auto t = Clock::now();
      size_t off = 0;
      for (size_t k = 0; k < plan.size(); ++k) {
        const int b = int(k % 3);
        const size_t n = plan[k];
        CK(cudaEventSynchronize(done[b]));
        hostCopy(chunk[b], src + off, n);
        CK(cudaMemcpyAsync(dst + off, chunk[b], n, cudaMemcpyHostToDevice, s));
        CK(cudaEventRecord(done[b], s));
        off += n;
      }
      CK(cudaStreamSynchronize(s));
      return since(t);
    };
    std::vector<size_t> even, ramp, head, tail;
    for (size_t off = 0; off < bytes; off += kChunk) even.push_back(std::min(kChunk, bytes - off));
    size_t left = bytes;
    for (size_t c = size_t(4) << 20; c < kChunk && left >= 2 * c; c *= 2) {
      head.push_back(c);
      tail.push_back(c);
      left -= 2 * c;
    }
    ramp = head;
    for (; left > 0; left -= std::min(kChunk, left)) ramp.push_back(std::min(kChunk, left));
    ramp.insert(ramp.end(), tail.rbegin(), tail.rend());
    const double tStaged = best([&] { return staged(even); });
    const double tRamp = best([&] { return staged(ramp); });
    double reg = 1e30, regDma = 1e30, unreg = 1e30, regAll = 1e30;
    for (int i = 0; i < 5; ++i) {
      const auto t0 = Clock::now();
      CK(cudaHostRegister(src, bytes, cudaHostRegisterDefault));
      const double a = since(t0);
      const double d = dma(src);
      const auto t1 = Clock::now();
      CK(cudaHostUnregister(src));
      const double u = since(t1);
      reg = std::min(reg, a);
      regDma = std::min(regDma, d);
      unreg = std::min(unreg, u);
      regAll = std::min(regAll, since(t0));
    }
    const double gb = double(bytes) / 1e9;
    std::printf("| %zu | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.2f | %.1f | %.2f |\n", bytes >> 20,
                gb / tPinned, gb / tPageable, gb / tHost, gb / tHostDma, gb / tStaged, gb / tRamp, gb / regAll,
                1e3 * reg, gb / regDma, 1e3 * unreg);
    std::fflush(stdout);
    CK(cudaFree(dst));
    CK(cudaFree(dst2));
    CK(cudaFreeHost(pinned));
    CK(cudaFreeHost(pinned2));
    std::free(raw);
  }
  return 0;
}

// PeerImages (CUDA IPC exchange buffers of one host's processes) and PieceBlend (the pieces
// blended front to back on the GPU), spaceskip/PeerImages.h.
#include "CudaCommon.cuh"
#include "spaceskip/PeerImages.h"

#include <algorithm>
#include <cstring>
#include <map>

namespace spaceskip {

namespace {

std::string cudaProblem(cudaError_t e, const char* what) {
  (void)cudaGetLastError();
  return std::string(what) + ": " + cudaGetErrorName(e) + ": " + cudaGetErrorString(e);
}

/// Pieces blended in one launch (passed by value: 64 x 32 bytes of kernel parameters).
constexpr int kPiecesPerLaunch = 64;

struct LaunchPieces {
  BlendSource piece[kPiecesPerLaunch];
  int count;
};

/// One thread a pixel: out = (first launch ? nothing : out) with each piece added behind, in order.
__global__ void blendPiecesKernel(LaunchPieces s, int width, int height, float stopAt, bool first, vec4f* out) {
  const int x = int(blockIdx.x * blockDim.x + threadIdx.x), y = int(blockIdx.y * blockDim.y + threadIdx.y);
  if (x >= width || y >= height) return;
  const int64_t p = int64_t(y) * width + x;
  vec4f acc = first ? vec4f{0.f, 0.f, 0.f, 0.f} : out[p];
  for (int k = 0; k < s.count; ++k) {
    const BlendSource& b = s.piece[k];
    if (x < b.x || y < b.y || x >= b.x + b.w || y >= b.y + b.h) continue;
    const vec4f* px = static_cast<const vec4f*>(b.pixels);
    addBehind(acc, px[int64_t(y - b.y) * int64_t(b.rowPixels) + (x - b.x)], stopAt);
  }
  out[p] = acc;
}

}  // namespace

//------------------------------------------------------------------------------
struct PeerImages::Impl {
  void* own = nullptr;  // this process's exchange buffer (cudaMalloc: IPC needs it uncounted-free)
  size_t ownPixels = 0;
  Handle ownHandle{};
  struct Mapped {
    Handle handle{};
    void* ptr = nullptr;
  };
  std::map<int, Mapped> mapped;

  ~Impl() {
    for (auto& [slot, m] : mapped)
      if (m.ptr) cudaIpcCloseMemHandle(m.ptr);
    if (own) cudaFree(own);
  }
};

PeerImages::PeerImages() : impl_(new Impl) {}
PeerImages::~PeerImages() = default;

bool PeerImages::share(const void* image, size_t pixels, void* stream, Handle& handle, std::string& problem) {
  Impl& d = *impl_;
  cudaError_t e = cudaSuccess;
  if (pixels > d.ownPixels || !d.own) {
    if (d.own) cudaFree(d.own);
    d.own = nullptr;
    d.ownPixels = 0;
    // Plain cudaMalloc: CUDA IPC exports only such allocations.
    if ((e = cudaMalloc(&d.own, pixels * sizeof(vec4f))) != cudaSuccess) {
      d.own = nullptr;
      problem = cudaProblem(e, "cudaMalloc (the shared image)");
      return false;
    }
    d.ownPixels = pixels;
    cudaIpcMemHandle_t h{};
    if ((e = cudaIpcGetMemHandle(&h, d.own)) != cudaSuccess) {
      problem = cudaProblem(e, "cudaIpcGetMemHandle");
      return false;
    }
    static_assert(sizeof(h) == sizeof(Handle), "a cudaIpcMemHandle_t is 64 bytes");
    std::memcpy(d.ownHandle.data(), &h, sizeof h);
  }
  auto s = static_cast<cudaStream_t>(stream);
  if ((e = cudaMemcpyAsync(d.own, image, pixels * sizeof(vec4f), cudaMemcpyDeviceToDevice, s)) != cudaSuccess ||
      (e = cudaStreamSynchronize(s)) != cudaSuccess) {
    problem = cudaProblem(e, "copying the frame into the shared image");
    return false;
  }
  handle = d.ownHandle;
  return true;
}

const void* PeerImages::map(int slot, const Handle& handle, std::string& problem) {
  Impl::Mapped& m = impl_->mapped[slot];
  if (m.ptr && m.handle == handle) return m.ptr;
  if (m.ptr) cudaIpcCloseMemHandle(m.ptr);
  m.ptr = nullptr;
  cudaIpcMemHandle_t h{};
  std::memcpy(&h, handle.data(), sizeof h);
  const cudaError_t e = cudaIpcOpenMemHandle(&m.ptr, h, cudaIpcMemLazyEnablePeerAccess);
  if (e != cudaSuccess) {
    m.ptr = nullptr;
    problem = cudaProblem(e, "cudaIpcOpenMemHandle");
    return nullptr;
  }
  m.handle = handle;
  return m.ptr;
}

bool PeerImages::download(const void* device, size_t pixels, float* host, std::string& problem) {
  const cudaError_t e = cudaMemcpy(host, device, pixels * sizeof(vec4f), cudaMemcpyDeviceToHost);
  if (e != cudaSuccess) {
    problem = cudaProblem(e, "downloading a piece's image");
    return false;
  }
  return true;
}

bool PeerImages::wait(void* stream, std::string& problem) {
  const cudaError_t e = cudaStreamSynchronize(static_cast<cudaStream_t>(stream));
  if (e != cudaSuccess) {
    problem = cudaProblem(e, "waiting for the blend");
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
struct PieceBlend::Impl {
  cuda::DeviceBuffer<vec4f> out;
  cuda::DeviceBuffer<vec4f> uploads;  // the host pieces, one after another
};

PieceBlend::PieceBlend() : impl_(new Impl) {}
PieceBlend::~PieceBlend() = default;

const void* PieceBlend::blend(const std::vector<BlendSource>& frontToBack, int width, int height, float stopAt,
                              void* stream, std::string& problem) {
  if (width <= 0 || height <= 0) {
    problem = "an empty viewport";
    return nullptr;
  }
  Impl& d = *impl_;
  auto s = static_cast<cudaStream_t>(stream);
  try {
    d.out.reserve(size_t(width) * size_t(height));
    std::vector<BlendSource> pieces;
    size_t uploaded = 0;
    for (const BlendSource& b : frontToBack)
      if (b.host && b.w > 0 && b.h > 0) uploaded += size_t(b.w) * size_t(b.h);
    if (uploaded) {
      // The upload buffer is reused next frame: wait for the blend that still reads it.
      SS_CUDA_CHECK(cudaStreamSynchronize(s));
      d.uploads.reserve(uploaded);
    }
    size_t at = 0;
    for (BlendSource b : frontToBack) {
      if (b.w <= 0 || b.h <= 0 || !b.pixels) continue;
      if (b.host) {
        vec4f* dst = d.uploads.get() + at;
        SS_CUDA_CHECK(cudaMemcpy2DAsync(dst, size_t(b.w) * sizeof(vec4f), b.pixels, b.rowPixels * sizeof(vec4f),
                                        size_t(b.w) * sizeof(vec4f), size_t(b.h), cudaMemcpyHostToDevice, s));
        b.pixels = dst;
        b.rowPixels = size_t(b.w);
        b.host = false;
        at += size_t(b.w) * size_t(b.h);
      }
      pieces.push_back(b);
    }
    const dim3 threads(32, 8);
    const dim3 blocks(unsigned((width + 31) / 32), unsigned((height + 7) / 8));
    size_t k = 0;
    do {
      LaunchPieces lp{};
      lp.count = int(std::min<size_t>(kPiecesPerLaunch, pieces.size() - k));
      std::copy_n(pieces.begin() + ptrdiff_t(k), lp.count, lp.piece);
      blendPiecesKernel<<<blocks, threads, 0, s>>>(lp, width, height, stopAt, k == 0, d.out.get());
      SS_CUDA_CHECK_LAUNCH("blendPiecesKernel");
      k += size_t(lp.count);
    } while (k < pieces.size());
  } catch (const std::exception& e) {
    problem = e.what();
    return nullptr;
  }
  return d.out.get();
}

}  // namespace spaceskip

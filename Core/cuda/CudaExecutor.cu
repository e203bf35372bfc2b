// Render kernels (one per traversal and sampler), the tile scheduler, and the frame's way from
// FrameView to the caller's image.
#include "CudaExecutor.cuh"
#include "spaceskip/Backend.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <type_traits>

namespace spaceskip::cuda {

namespace {

// Launch shape: 2-D grid of 16x8 blocks (Tuning::blockX/Y override), one thread per pixel.
// One kernel per traversal: a kernel holding every traversal is allocated the registers of the
// tree traversal (64 per thread, half occupancy), which the naive and grid marches do not need.
// SPACESKIP_CUDA_HW_MIN_BLOCKS > 1 asks the hardware-filtered kernels to fit that many blocks of
// 256 threads per SM (a register cap). Measured on the H100: with one sample at a time, 6 (40
// registers) made every ESS kernel 4-11% slower than no cap; with batches of samples (102
// registers for the grid kernels), 3 (85 registers) made the hardware-filtered DistanceGrid
// 1.06-1.17x faster on five stand-ins (docs/results/HISTORY.md, the register cap), hence the default 3.
constexpr int kMaxRenderThreads = 256;
// Default launch of the hardware-filtered kernels: plain for volumes up to kLargeTextureBytes; a
// persistent launch with kLargeTextureResident blocks of 128 threads per SM above, for Naive
// only. Measured on the H100 (docs/results/HISTORY.md, persistent launch): naive:hw at 2048^3 (8 GiB) runs
// fastest with 6 blocks per SM (more warps in flight thrash the texture path), at 1024^3 (1 GiB)
// with all 16. The skipping kernels (traversals as iterators) run faster plain: DistanceGrid at
// N-body 2048^3 789 kernel fps plain vs 730 persistent, in one process
// (docs/results/h100-sub-brick-masks).
constexpr size_t kLargeTextureBytes = size_t(2) << 30;
constexpr int kLargeTextureResident = 6;
template <class Sampler>
struct RenderMinBlocks {
  static constexpr int value = 1;
};
#ifndef SPACESKIP_CUDA_HW_MIN_BLOCKS
#define SPACESKIP_CUDA_HW_MIN_BLOCKS 3  // CMake: SPACESKIP_CUDA_HW_MIN_BLOCKS (1 = no register cap)
#endif
template <>
struct RenderMinBlocks<TextureSampler> {
  static constexpr int value = SPACESKIP_CUDA_HW_MIN_BLOCKS;
};

// Tiles of blockDim pixels. Without `tileCounter` block (i, j) renders tile (i, j). With it the
// launch is persistent: a fixed number of resident blocks take tiles in row-major order from the
// counter until none are left, which bounds the warps in flight (the volume's cache working set)
// and balances blocks whose rays cost very different amounts.
// Segmented frames (gridDim.z > 1: segment blockIdx.z of every ray into its own layer of `out`)
// cover only the pixels of `rect` (x0, y0, x1, y1; boxPixelRect: the others render 0); with
// `flags` a segment writes its layer only where it coloured the pixel and says so in flags
// (SegmentLayers): most segments of a sparse volume colour nothing.
template <class Sampler, int Traversal, bool Plain>
__global__ void __launch_bounds__(kMaxRenderThreads, RenderMinBlocks<Sampler>::value)
    renderKernel(const __grid_constant__ FrameView f, const __grid_constant__ Sampler s, vec4f* out,
                 unsigned* tileCounter, int4 rect, unsigned char* flags) {
  const unsigned tilesX = (unsigned(rect.z - rect.x) + blockDim.x - 1) / blockDim.x;
  const int segment = int(blockIdx.z), segments = int(gridDim.z);
  auto tile = [&](unsigned tx, unsigned ty) {
    const int x = rect.x + int(tx * blockDim.x + threadIdx.x), y = rect.y + int(ty * blockDim.y + threadIdx.y);
    if (x < rect.z && y < rect.w) {
      const int64_t i = (int64_t(segment) * f.height + y) * f.width + x;
      const vec4f c = renderPixel<Sampler, Traversal, Plain>(f, s, x, y, segment, segments);
      if (!flags) {
        out[i] = c;
      } else {
        const bool coloured = c.x != 0.f || c.y != 0.f || c.z != 0.f || c.w != 0.f;
        flags[i] = coloured;
        if (coloured) out[i] = c;
      }
    }
  };
  if (!tileCounter) {
    tile(blockIdx.x, blockIdx.y);
    return;
  }
  const unsigned numTiles = tilesX * ((unsigned(rect.w - rect.y) + blockDim.y - 1) / blockDim.y);
  __shared__ unsigned next;
  for (;;) {
    if (threadIdx.x == 0 && threadIdx.y == 0) next = atomicAdd(tileCounter, 1u);
    __syncthreads();
    const unsigned t = next;
    __syncthreads();  // everyone has read `next` before thread 0 overwrites it
    if (t >= numTiles) return;
    tile(t % tilesX, t / tilesX);
  }
}

// The layers of a segmented frame composited front to back into the image (compositeLayers,
// SegmentLayers.h): one thread a pixel.
__global__ void compositeSegmentsKernel(const SegmentLayersView v, vec4f* out) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= int64_t(v.width) * v.height) return;
  out[i] = compositeLayers(v, int(i % v.width), int(i / v.width));
}

template <class Sampler>
struct IsPoolSampler : std::false_type {};
template <class T>
struct IsPoolSampler<PoolSampler<T>> : std::true_type {};

template <class Sampler>
using RenderKernelPtr = void (*)(const FrameView, const Sampler, vec4f*, unsigned*, int4, unsigned char*);

template <class Sampler, bool Plain>
RenderKernelPtr<Sampler> renderKernelFor(TraversalKind t) {
  switch (t) {
    case TraversalKind::Naive: return renderKernel<Sampler, int(TraversalKind::Naive), Plain>;
    case TraversalKind::Grid: return renderKernel<Sampler, int(TraversalKind::Grid), Plain>;
    case TraversalKind::Tree: return renderKernel<Sampler, int(TraversalKind::Tree), Plain>;
    case TraversalKind::Hybrid: return renderKernel<Sampler, int(TraversalKind::Hybrid), Plain>;
    case TraversalKind::GridParts:
      // Parts are walked in plain frames only (the speed that matters; other modes march whole
      // bricks: the same samples that can be drawn, fewer kernels to compile).
      if constexpr (Plain) return renderKernel<Sampler, int(TraversalKind::GridParts), Plain>;
      else return renderKernel<Sampler, int(TraversalKind::Grid), Plain>;
  }
  return renderKernel<Sampler, int(TraversalKind::Naive), Plain>;
}

/// The kernel for this frame: its traversal, and the composite-only build for plain frames.
template <class Sampler>
RenderKernelPtr<Sampler> renderKernelFor(const FrameView& f) {
  // Dependent components: one kernel reading the traversal from the frame (a rare mode: six
  // voxel types times four traversals more would double this file's compile time).
  if constexpr (IsChannelSampler<Sampler>::value || IsNearestSampler<Sampler>::value)
    return renderKernel<Sampler, -1, false>;
  // Sparse residency: the plain frames' kernels per traversal (the speed that matters), one
  // kernel reading the traversal from the frame for the other modes.
  else if constexpr (IsPoolSampler<Sampler>::value)
    return isPlainFrame(f) ? renderKernelFor<Sampler, true>(f.traversal) : renderKernel<Sampler, -1, false>;
  else
    return isPlainFrame(f) ? renderKernelFor<Sampler, true>(f.traversal)
                           : renderKernelFor<Sampler, false>(f.traversal);
}

/// Segments for a frame's rays: one per kSamplesPerSegment samples along the volume's diagonal
/// (its world length: the index box's corners through the inverse of worldToIndex, over dt), at
/// most kRaySegments; 1 (whole rays) below 2 x kSamplesPerSegment.
constexpr int kRaySegments = 4;
constexpr double kSamplesPerSegment = 512;
int raySegments(const FrameView& f) {
  mat4 w2i = identity4(), i2w;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) w2i.m[c * 4 + r] = f.worldToIndex[r * 4 + c];  // row-major 3x4
  if (!invert(w2i, i2w) || !(f.dt > 0)) return 1;
  const double lo[3] = {0, 0, 0}, hi[3] = {f.boxHi.x, f.boxHi.y, f.boxHi.z};
  double a[3], b[3];
  transformPoint(i2w, lo, a);
  transformPoint(i2w, hi, b);
  const double samples = std::sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) +
                                   (b[2] - a[2]) * (b[2] - a[2])) / double(f.dt);
  return int(std::max(1.0, std::min(double(kRaySegments), std::floor(samples / kSamplesPerSegment))));
}

bool validBlock(const Tuning& p) {
  return p.blockX > 0 && p.blockY > 0 && p.blockX * p.blockY >= 32 && p.blockX * p.blockY <= kMaxRenderThreads;
}

}  // namespace

CudaExecutor::CudaExecutor() {
  int dev = 0;
  if (cudaGetDevice(&dev) != cudaSuccess ||
      cudaDeviceGetAttribute(&numSMs_, cudaDevAttrMultiProcessorCount, dev) != cudaSuccess || numSMs_ < 1) {
    (void)cudaGetLastError();
    numSMs_ = 1;
  }
}

void CudaExecutor::setTransferTable(const std::vector<vec4f>& t, float lo, float scale, cudaStream_t stream) {
  // An opacity edit's path: a pageable copy would make the host wait for the whole stream (the
  // classification and the build queued before it); the pinned copy waits for nothing but the
  // previous table's copy (long done).
  const size_t bytes = t.size() * sizeof(vec4f);
  if (tableCopyPending_) SS_CUDA_CHECK(cudaEventSynchronize(tableCopied_));
  tableCopyPending_ = false;
  d_table_.reserve(t.size());
  h_table_.reserve(bytes);
  std::memcpy(h_table_.get(), t.data(), bytes);
  SS_CUDA_CHECK(cudaMemcpyAsync(d_table_.get(), h_table_.get(), bytes, cudaMemcpyHostToDevice, stream));
  SS_CUDA_CHECK(cudaEventRecord(tableCopied_, stream));
  tableCopyPending_ = true;
  table_ = TransferFunctionView{d_table_.get(), int(t.size()), lo, scale};
}

double CudaExecutor::lastFrameDeviceSeconds() const {
  if (timingPending_) {
    timingPending_ = false;
    float ms = 0;
    // A getter does not throw: an error of the frame surfaces at the next checked call.
    const bool ok = cudaEventSynchronize(ev1_) == cudaSuccess && cudaEventElapsedTime(&ms, ev0_, ev1_) == cudaSuccess;
    if (!ok) (void)cudaGetLastError();
    lastDeviceSeconds_ = ok ? double(ms) * 1e-3 : -1.0;
  }
  return lastDeviceSeconds_;
}

void CudaExecutor::render(FrameView f, FilterMode filter, const float* depth, DeviceVolume& vol,
                          const PoolView* pool, Image& out, cudaStream_t stream) {
  const size_t pixels = size_t(f.width) * size_t(f.height);
  timingPending_ = false;  // the last frame's time, if nobody asked for it, is not kept
  lastDeviceSeconds_ = -1;
  f.tf = table_;
  // Samples a GPU march fetches together (IntervalMarcher::takeBatch; batches against one sample
  // at a time: docs/results/HISTORY.md, batches of samples).
  f.sampleBatch = tuning_.sampleBatch > 0 ? std::min(tuning_.sampleBatch, kMaxSampleBatch) : kMaxSampleBatch;
  layers_ = SegmentLayersView{};  // launch() sets it for a segmented frame
  deviceImageValid_ = false;
  f.depth = nullptr;
  if (depth) {
    d_depth_.reserve(pixels);
    SS_CUDA_CHECK(cudaMemcpyAsync(d_depth_.get(), depth, pixels * sizeof(float), cudaMemcpyHostToDevice, stream));
    f.depth = d_depth_.get();
  }
  if (f.alphaIn) {
    d_alphaIn_.reserve(pixels);
    SS_CUDA_CHECK(cudaMemcpyAsync(d_alphaIn_.get(), f.alphaIn, pixels * sizeof(float), cudaMemcpyHostToDevice, stream));
    f.alphaIn = d_alphaIn_.get();
  }
  unsigned* hostCounts = f.sampleCount;
  f.sampleCount = nullptr;
  if (hostCounts) {
    d_counts_.reserve(pixels);
    f.sampleCount = d_counts_.get();
  }
  d_image_.reserve(pixels);
  const bool shaped = validBlock(tuning_);
  const unsigned bx = shaped ? unsigned(tuning_.blockX) : 16u, by = shaped ? unsigned(tuning_.blockY) : 8u;
  const dim3 block(bx, by);
  const dim3 grid(unsigned((f.width + bx - 1) / bx), unsigned((f.height + by - 1) / by));
  SS_CUDA_CHECK(cudaEventRecord(ev0_, stream));
  const Volume& v = vol.volume();
  if (pool) {  // sparse residency: the resident bricks, exact sampling
    dispatchVoxelType(v.type, [&](auto t) {
      using T = decltype(t);
      launch(f, pool->sampler<T>(), grid, block, 0, stream);
    });
  } else if (f.sampling != kSampleTrilinear && v.components == 1) {  // nearest, label maps (render/LabelSampler.h)
    dispatchVoxelType(v.type, [&](auto t) {
      using T = decltype(t);
      launch(f, NearestSampler<T>{vol.d_voxels<T>(), v.dims.x, v.dims.y, v.dims.z, f.sampling}, grid, block, 0,
             stream);
    });
  } else if (v.components > 1) {  // dependent components (render/Components.h): exact sampling only
    dispatchVoxelType(v.type, [&](auto t) {
      using T = decltype(t);
      launch(f, ChannelSampler<T>{vol.d_voxels<T>(), v.dims.x, v.dims.y, v.dims.z, v.components}, grid, block, 0,
             stream);
    });
  } else if (filter == FilterMode::Hardware) {
    const TextureSampler s = vol.texture(stream);
    launch(f, s, grid, block, vol.textureBytes(), stream);
  } else {
    dispatchVoxelType(v.type, [&](auto t) {
      using T = decltype(t);
      launch(f, ArraySampler<T>{vol.d_voxels<T>(), v.dims.x, v.dims.y, v.dims.z}, grid, block, 0, stream);
    });
  }
  SS_CUDA_CHECK_LAUNCH(renderKernel);
  SS_CUDA_CHECK(injectedRenderError());
  // A segmented frame's layers (launch) are composited into d_image_ here, or, when the image
  // stays on the device, when someone asks for d_image_ (deviceImage()): the CUDA blend into a
  // window reads the layers themselves (deviceImageView()), which spares writing and reading the
  // flat image.
  stream_ = stream;
  if (layers_.layers && !(imageOnDevice_ && !hostCounts)) compositeLayers();
  SS_CUDA_CHECK(cudaEventRecord(ev1_, stream));
  out.width = f.width;
  out.height = f.height;
  float ms = 0;
  if (imageOnDevice_ && !hostCounts) {
    // The caller draws d_image_ itself (CUDA-GL interop), queuing its copy on `stream`: no
    // download, and no wait here, so that the host's work for the frame overlaps the kernel.
    out.rgba.clear();
    timingPending_ = true;
    deviceImageValid_ = true;
    return;
  }
  deviceImageValid_ = false;
  out.rgba.resize(pixels);
  // Through a pinned staging buffer (DMA at full link speed, then a parallel host copy): about
  // twice as fast as a copy into the caller's pageable vector. Without pinned memory, direct.
  const size_t imageBytes = pixels * sizeof(vec4f);
  const bool staged = h_stage_.tryReserve(imageBytes) == cudaSuccess;
  SS_CUDA_CHECK(cudaMemcpyAsync(staged ? h_stage_.get() : static_cast<void*>(out.rgba.data()), d_image_.get(),
                                imageBytes, cudaMemcpyDeviceToHost, stream));
  if (hostCounts)
    SS_CUDA_CHECK(
        cudaMemcpyAsync(hostCounts, d_counts_.get(), pixels * sizeof(unsigned), cudaMemcpyDeviceToHost, stream));
  SS_CUDA_CHECK(cudaStreamSynchronize(stream));
  if (staged) parallelCopy(out.rgba.data(), h_stage_.get(), imageBytes);
  SS_CUDA_CHECK(cudaEventElapsedTime(&ms, ev0_, ev1_));
  lastDeviceSeconds_ = double(ms) * 1e-3;
}

void CudaExecutor::compositeLayers() const {
  if (!layers_.layers) return;
  const int64_t pixels = int64_t(layers_.width) * layers_.height;
  compositeSegmentsKernel<<<unsigned((pixels + 255) / 256), 256, 0, stream_>>>(layers_, d_image_.get());
  SS_CUDA_CHECK_LAUNCH(compositeSegmentsKernel);
  layers_ = SegmentLayersView{};
}

const void* CudaExecutor::deviceImage() const {
  if (!deviceImageValid_) return nullptr;
  compositeLayers();  // a segmented frame whose layers are still pending
  return d_image_.get();
}

DeviceImageView CudaExecutor::deviceImageView() const {
  DeviceImageView v;
  if (!deviceImageValid_) return v;
  v.image = d_image_.get();
  v.layers = layers_;
  return v;
}

template <class Sampler>
void CudaExecutor::launch(const FrameView& f, const Sampler& s, dim3 grid, dim3 block, size_t textureBytes,
                          cudaStream_t stream) {
  // Persistent launch with N blocks per SM taking tiles from a counter (0: one block per tile, the
  // plain launch): Tuning::resident, else automatic.
  int residentBlocks =
      std::is_same<Sampler, TextureSampler>::value && textureBytes > kLargeTextureBytes && f.traversal == TraversalKind::Naive
          ? std::max(1, kLargeTextureResident * 128 / int(block.x * block.y))
          : 0;
  if (tuning_.resident >= 0) residentBlocks = tuning_.resident;
  RenderKernelPtr<Sampler> k = renderKernelFor<Sampler>(f);
  if (residentBlocks <= 0) {
    // Rays cut into kRaySegments segments marched by separate threads, composited front to back
    // (segmentableFrame: composite plain frames without early ray termination). A frame takes as
    // long as its slowest tiles, and at N-body 2048^3 those are tiles whose rays cross dense
    // clusters: 0.6-0.9 ms while the median tile takes 1.3 us. Measured on the H100
    // (docs/results/HISTORY.md, segmented rays): 4 segments 1.07-1.18x kernel fps on five stand-ins
    // (DistanceGrid, DistanceGrid:hw, Auto), 8 less; short rays lose (N-body 128^3 in a 1024^2
    // window: kernel 0.30 -> 0.35 ms), hence raySegments. Tuning::raySegments forces a count
    // (1..16; 1: whole rays).
    const int forced = std::max(0, std::min(16, tuning_.raySegments));
    const int segments = forced > 0 ? forced : raySegments(f);
    if (segments > 1 && segmentableFrame(f)) {
      // The layers cover the pixels whose rays can meet the box (boxPixelRect), and a segment
      // writes its layer only where it coloured the pixel (flags): at N-body 2048^3 in a 1024^2
      // window about half the pixels miss the box and most segments colour nothing, which spared
      // the layers' traffic (4 x 16 MB written and read a frame).
      const int64_t pixels = int64_t(f.width) * f.height;
      int rect[4] = {0, 0, f.width, f.height};
      boxPixelRect(f, rect);
      // Whole tiles of the full frame's launch: the same pixels share a block as without the
      // rect (measured: a rect cutting tiles made Menger's frame 1 % slower).
      rect[0] -= rect[0] % int(block.x);
      rect[1] -= rect[1] % int(block.y);
      const int4 r = make_int4(rect[0], rect[1], rect[2], rect[3]);
      d_layers_.reserve(size_t(pixels) * size_t(segments));
      d_layerFlags_.reserve(size_t(pixels) * size_t(segments));
      unsigned char* flags = d_layerFlags_.get();
      if (r.z > r.x && r.w > r.y) {
        const dim3 rectGrid(unsigned((r.z - r.x + int(block.x) - 1) / int(block.x)),
                            unsigned((r.w - r.y + int(block.y) - 1) / int(block.y)), unsigned(segments));
        k<<<rectGrid, block, 0, stream>>>(f, s, d_layers_.get(), nullptr, r, flags);
      }
      layers_.layers = d_layers_.get();
      layers_.flags = flags;
      layers_.segments = segments;
      layers_.width = f.width;
      layers_.height = f.height;
      std::copy(rect, rect + 4, layers_.rect);
      return;
    }
    k<<<grid, block, 0, stream>>>(f, s, d_image_.get(), nullptr, make_int4(0, 0, f.width, f.height), nullptr);
    return;
  }
  d_tileCounter_.reserve(1);
  SS_CUDA_CHECK(cudaMemsetAsync(d_tileCounter_.get(), 0, sizeof(unsigned), stream));
  const unsigned tiles = grid.x * grid.y;
  const unsigned blocks = std::min(tiles, unsigned(residentBlocks) * unsigned(numSMs_));
  k<<<blocks, block, 0, stream>>>(f, s, d_image_.get(), d_tileCounter_.get(), make_int4(0, 0, f.width, f.height),
                                  nullptr);
}

}  // namespace spaceskip::cuda

// The render kernels (one per sampler, traversal and plain/general frame) and
// CudaExecutor::launch, which picks one and launches it. The kernels are many (six voxel types,
// five traversals, four sampler families) and cost most of the CUDA build, so launch<Sampler> is
// instantiated in several translation units, one per sampler family (CudaRender*.cu): they
// compile in parallel. CudaExecutor.cu sees only launch's declaration.
#pragma once
#include "CudaExecutor.cuh"
#include "spaceskip/Backend.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>

namespace spaceskip::cuda {

/// Segments for a frame's rays (CudaExecutor.cu).
int raySegments(const FrameView& f);

namespace {

// One kernel per traversal: a kernel holding every traversal is allocated the registers of the
// tree traversal (64 per thread, half occupancy), which the naive and grid marches do not need.
// SPACESKIP_CUDA_HW_MIN_BLOCKS > 1 asks the hardware-filtered kernels to fit that many blocks of
// 256 threads per SM (a register cap). Measured on the H100: with one sample at a time, 6 (40
// registers) made every ESS kernel 4-11% slower than no cap; with batches of samples (102
// registers for the grid kernels), 3 (85 registers) made the hardware-filtered DistanceGrid
// 1.06-1.17x faster on five stand-ins (docs/results/HISTORY.md, the register cap), hence the default 3.
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
// The exact-sampling kernels (ArraySampler: FilterMode::Exact, the default) held up to 130
// registers uncapped: 3 blocks of 128 threads an SM (Nsight Compute, N-body 2048^3, DistanceGrid).
// 3 (blocks of 256 threads) leaves 76-80 registers and 6 blocks of 128. Measured on H200s, builds
// alternated in one hold (docs/results/multi-gpu, register cap): against no cap, N-body 2048^3 on
// one GPU 1.22x at 1024^2 and 1.37x at 2048^2, N-body 512^3 1.09x, the dense Richtmyer-Meshkov
// 1024^3 1.11x. 2 (128 registers) gained less; 4 (64 registers) ran the dense one at 0.63x.
#ifndef SPACESKIP_CUDA_EXACT_MIN_BLOCKS
#define SPACESKIP_CUDA_EXACT_MIN_BLOCKS 3  // CMake: SPACESKIP_CUDA_EXACT_MIN_BLOCKS (1 = no register cap)
#endif
template <class T>
struct RenderMinBlocks<ArraySampler<T>> {
  static constexpr int value = SPACESKIP_CUDA_EXACT_MIN_BLOCKS;
};

// Tiles of blockDim pixels. Without `tileCounter` block (i, j) renders tile (i, j). With it the
// launch is persistent: a fixed number of resident blocks take tiles in row-major order from the
// counter until none are left, which bounds the warps in flight (the volume's cache working set)
// and balances blocks whose rays cost very different amounts.
// Segmented frames (gridDim.z > 1: segment blockIdx.z of every ray into its own layer of `out`)
// cover only the pixels of `rect` (x0, y0, x1, y1; boxPixelRect: the others render 0); with
// `flags` a segment writes its layer only where it coloured the pixel and says so in flags
// (SegmentLayers): most segments of a sparse volume colour nothing.
// `order` (plain launches, Tuning::heaviestFirst): block b renders unit order.order[b] and
// writes its cycles to order.cost (TileOrder).
template <class Sampler, int Traversal, bool Plain>
__global__ void __launch_bounds__(kMaxRenderThreads, RenderMinBlocks<Sampler>::value)
    renderKernel(const __grid_constant__ FrameView f, const __grid_constant__ Sampler s, vec4f* out,
                 unsigned* tileCounter, int4 rect, unsigned char* flags, const __grid_constant__ TileOrder order) {
  const unsigned tilesX = (unsigned(rect.z - rect.x) + blockDim.x - 1) / blockDim.x;
  int segment = int(blockIdx.z);
  const int segments = int(gridDim.z);
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
  if (!tileCounter && order.cost) {
    const unsigned b = blockIdx.x + gridDim.x * (blockIdx.y + gridDim.y * blockIdx.z);
    const unsigned u = order.order ? order.order[b] : b;
    unsigned tx, ty, seg;
    TileOrder::unit(u, gridDim, tx, ty, seg);
    segment = int(seg);
    const long long t0 = clock64();
    tile(tx, ty);
    __syncthreads();  // the block's time is its slowest ray's
    if (threadIdx.x == 0 && threadIdx.y == 0) {
      const long long dt = clock64() - t0;
      order.cost[order.costIndex(u, gridDim)] = unsigned(dt < 0 ? 0 : dt > 0xffffffffll ? 0xffffffffll : dt);
    }
    return;
  }
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

// The second pass of a frame with queued shadow rays (ScatterView::queue, render/Scattering.h
// scatterShade): each thread marches queued rays, grid-stride, and adds what each lets through
// to its pixel. The queue's count is on the device, hence a fixed grid.
template <class Sampler>
__global__ void shadowQueueKernel(const __grid_constant__ FrameView f, const __grid_constant__ Sampler s, vec4f* out) {
  const unsigned count = *f.scatter.queueCount, n = count < f.scatter.queueCapacity ? count : f.scatter.queueCapacity;
  for (unsigned i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += gridDim.x * blockDim.x) {
    const ShadowRecord r = f.scatter.queue[i];
    const vec3f c = queuedShadowColour(f, s, r);
    vec4f* px = out + r.pixel;
    if (c.x != 0.f) atomicAdd(&px->x, c.x);
    if (c.y != 0.f) atomicAdd(&px->y, c.y);
    if (c.z != 0.f) atomicAdd(&px->z, c.z);
  }
}

template <class Sampler>
struct IsPoolSampler : std::false_type {};
template <class T>
struct IsPoolSampler<PoolSampler<T>> : std::true_type {};

template <class Sampler>
using RenderKernelPtr = void (*)(const FrameView, const Sampler, vec4f*, unsigned*, int4, unsigned char*, const TileOrder);

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

}  // namespace

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
        const TileOrder order = tileOrder(rectGrid, r.x / int(block.x), r.y / int(block.y),
                                          int((unsigned(f.width) + block.x - 1) / block.x),
                                          int((unsigned(f.height) + block.y - 1) / block.y), stream);
        k<<<rectGrid, block, 0, stream>>>(f, s, d_layers_.get(), nullptr, r, flags, order);
      }
      layers_.layers = d_layers_.get();
      layers_.flags = flags;
      layers_.segments = segments;
      layers_.width = f.width;
      layers_.height = f.height;
      std::copy(rect, rect + 4, layers_.rect);
      return;
    }
    const TileOrder order = tileOrder(grid, 0, 0, int(grid.x), int(grid.y), stream);
    k<<<grid, block, 0, stream>>>(f, s, d_image_.get(), nullptr, make_int4(0, 0, f.width, f.height), nullptr, order);
    drainShadowQueue(f, s, stream);
    return;
  }
  d_tileCounter_.reserve(1);
  SS_CUDA_CHECK(cudaMemsetAsync(d_tileCounter_.get(), 0, sizeof(unsigned), stream));
  const unsigned tiles = grid.x * grid.y;
  const unsigned blocks = std::min(tiles, unsigned(residentBlocks) * unsigned(numSMs_));
  k<<<blocks, block, 0, stream>>>(f, s, d_image_.get(), d_tileCounter_.get(), make_int4(0, 0, f.width, f.height),
                                  nullptr, TileOrder{});
  drainShadowQueue(f, s, stream);
}

template <class Sampler>
void CudaExecutor::drainShadowQueue(const FrameView& f, const Sampler& s, cudaStream_t stream) {
  if (!f.scatter.queue) return;
  shadowQueueKernel<Sampler><<<unsigned(numSMs_) * 8u, 256, 0, stream>>>(f, s, d_image_.get());
}


// Instantiates launch for one sampler type (in one of the CudaRender*.cu files).
#define SPACESKIP_INSTANTIATE_LAUNCH(Sampler)                                                          \
  template void CudaExecutor::launch<Sampler>(const FrameView&, const Sampler&, dim3, dim3, size_t, \
                                              cudaStream_t);

}  // namespace spaceskip::cuda

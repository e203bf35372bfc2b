// The frame's way from FrameView to the caller's image: the sampler for the volume, the launch
// (CudaRenderLaunch.cuh, instantiated per sampler family in CudaRender*.cu), the segments'
// composite and the image's copy.
#include "CudaExecutor.cuh"
#include "spaceskip/Backend.h"
#include "spaceskip/Math.h"

#include <cub/device/device_radix_sort.cuh>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace spaceskip::cuda {

namespace {

// The layers of a segmented frame composited front to back into the image (compositeLayers,
// SegmentLayers.h): one thread a pixel.
__global__ void compositeSegmentsKernel(const SegmentLayersView v, vec4f* out) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= int64_t(v.width) * v.height) return;
  out[i] = compositeLayers(v, int(i % v.width), int(i / v.width));
}

// The sort key of a unit's cycles: 16 bits that keep their order, the position of the leading
// one (5 bits) and the 11 bits after it (a float's exponent and mantissa; 1/2048 apart at most).
// Sorting 16 bits takes two of the radix sort's passes instead of four. Measured on H200s: with
// 32-bit keys the gather and the sort took 57 us a frame at N-body 2048^3, 1024^2, beside a
// 1.07 ms render kernel (Nsight Compute, bench/device/ncu-ray-scaling.sh); with 16-bit keys the
// frame ran 1.024x faster on one GPU and 1.021x on two (docs/results/multi-gpu, ray scaling).
constexpr int kOrderKeyBits = 16;
SS_FUNC unsigned orderKey(unsigned cycles) {
  if (cycles == 0) return 0;
  const int lead = 63 - clz64(cycles);  // the leading one's position, 0..31
  if (lead == 31) return 0xffffu;  // a second and more at once: the top key
  const unsigned mantissa = lead >= 11 ? (cycles >> (lead - 11)) & 0x7ffu : (cycles << (11 - lead)) & 0x7ffu;
  return (unsigned(lead + 1) << 11) | mantissa;  // lead + 1: a key of 0 is "no cycles" alone
}
/// The cycles of a key (the 11 bits after the leading one; the rest 0).
double orderKeyCycles(unsigned key) {
  if (key == 0) return 0;
  const int lead = int(key >> 11) - 1;
  return std::ldexp(double(2048 + (key & 0x7ffu)), lead - 11);
}

// tileOrder: each unit of a launch of `grid` (x fastest, then y, then the segment) with the
// key of the most cycles that its segment took in the last frame on its tile or one of the 8
// around it (0 where none was drawn), on the whole frame's wholeX x wholeY tiles. A tile that a
// dense cluster moves onto as the view turns starts early. Traced block by block
// (bench/device/block-trace.patch) at N-body 2048^3, 1024^2, 6 degrees a frame, the block that
// ended the frame had taken 1/9 of its cycles on its own tile the frame before, so it started
// late. Against the tile's own cycles, on 2 x H200 (docs/results/multi-gpu, the slowest block):
// N-body 2048^3 1.02-1.07x on one GPU, 1.02x on two; the dense Richtmyer-Meshkov 1024^3 1.01x.
__global__ void gatherTileCostKernel(const TileOrder o, dim3 grid, int wholeY, unsigned* keys, unsigned* units) {
  const unsigned n = grid.x * grid.y * grid.z;
  const unsigned u = blockIdx.x * blockDim.x + threadIdx.x;
  if (u >= n) return;
  unsigned tx, ty, segment;
  TileOrder::unit(u, grid, tx, ty, segment);
  const int wx = int(tx) + o.originX, wy = int(ty) + o.originY;
  unsigned c = 0;
  for (int y = wy - 1; y <= wy + 1; ++y)
    for (int x = wx - 1; x <= wx + 1; ++x)
      if (x >= 0 && y >= 0 && x < o.wholeX && y < wholeY) {
        const unsigned v = o.cost[o.wholeCostIndex(unsigned(x), unsigned(y), segment, grid.z)];
        c = v > c ? v : c;
      }
  keys[u] = orderKey(c);
  units[u] = u;
}

// Launch shape: 2-D grid of 16x8 blocks (Tuning::blockX/Y override), one thread per pixel.
bool validBlock(const Tuning& p) {
  return p.blockX > 0 && p.blockY > 0 && p.blockX * p.blockY >= 32 && p.blockX * p.blockY <= kMaxRenderThreads;
}

}  // namespace

/// Segments for a frame's rays: one per kSamplesPerSegment samples along the volume's diagonal
/// (its world length: the index box's corners through the inverse of worldToIndex, over dt), at
/// most kRaySegments; 1 (whole rays) below 2 x kSamplesPerSegment. A frame of long rays and at
/// most kFewRaysPixels pixels (a small window, one GPU's band of an image) takes
/// kRaySegmentsFewRays: with few tiles its slowest ray segments are the frame (traced block by
/// block: at N-body 2048^3 in 724^2 one 0.52 ms block was the whole kernel). The frame's size,
/// not the box's pixels: those change as the view turns, and each change of the count starts the
/// launch order again (tileOrder), which cost 0.97x at 1024^2. Measured on H200s
/// (docs/results/multi-gpu, ray segments), 8 against 4 segments: N-body 2048^3 1.13x on 2 GPUs'
/// bands of 1024^2, 1.17x at 512^2, 1.01x at 724^2, 1.04x at 1000 x 700; N-body 512^3 1.00x /
/// 1.05x / 0.99x / 1.00x; the dense Richtmyer-Meshkov 1024^3 1.00x / 1.02x / 1.00x / 1.00x. At
/// 1024^2 on one GPU 8 lost: 0.87-0.98x.
namespace {
constexpr int kRaySegments = 4;
constexpr int kRaySegmentsFewRays = 8;
constexpr double kSamplesPerSegment = 512;
constexpr int64_t kFewRaysPixels = (int64_t(3) << 20) / 4;  // 3/4 of 1024^2: layers of 96 MiB at most
}  // namespace
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
  const int n = int(std::max(1.0, std::min(double(kRaySegments), std::floor(samples / kSamplesPerSegment))));
  return n == kRaySegments && int64_t(f.width) * f.height <= kFewRaysPixels ? kRaySegmentsFewRays : n;
}
CudaExecutor::CudaExecutor() {
  int dev = 0;
  if (cudaGetDevice(&dev) != cudaSuccess ||
      cudaDeviceGetAttribute(&numSMs_, cudaDevAttrMultiProcessorCount, dev) != cudaSuccess || numSMs_ < 1) {
    (void)cudaGetLastError();
    numSMs_ = 1;
  }
  int kHz = 0;
  if (cudaDeviceGetAttribute(&kHz, cudaDevAttrClockRate, dev) == cudaSuccess) clockHz_ = 1e3 * double(kHz);
  else (void)cudaGetLastError();
}

TileOrder CudaExecutor::tileOrder(dim3 grid, int originX, int originY, int wholeX, int wholeY, cudaStream_t stream) {
  if (!tuning_.heaviestFirst) return TileOrder{};
  TileOrder o;
  o.originX = originX;
  o.originY = originY;
  o.wholeX = wholeX;
  const int segments = int(grid.z);
  const size_t whole = size_t(wholeX) * size_t(wholeY) * size_t(segments);
  if (costShape_[0] != wholeX || costShape_[1] != segments || whole > d_tileCost_.capacity()) {
    // A new width in tiles or segment count, or more rows than kept: no last frame to go by;
    // this one measures. A frame of fewer or more rows within the room (an image band whose
    // height follows the load) keeps its rows' costs: the layout's stride is the width.
    const size_t room = whole > d_tileCost_.capacity() ? whole + whole / 4 : d_tileCost_.capacity();
    d_tileCost_.reserve(room);
    SS_CUDA_CHECK(cudaMemsetAsync(d_tileCost_.get(), 0, room * sizeof(unsigned), stream));
    costShape_[0] = wholeX;
    costShape_[1] = segments;
    costKept_ = false;
  }
  o.cost = d_tileCost_.get();
  const unsigned n = grid.x * grid.y * grid.z;
  if (!costKept_ || n < 2) {
    costKept_ = true;  // this frame's launch writes them
    return o;
  }
  d_orderKeys_.reserve(size_t(n) * 2);
  d_orderUnits_.reserve(size_t(n) * 2);
  unsigned *keys = d_orderKeys_.get(), *units = d_orderUnits_.get();
  gatherTileCostKernel<<<(n + 255) / 256, 256, 0, stream>>>(o, grid, wholeY, keys, units);
  SS_CUDA_CHECK_LAUNCH(gatherTileCostKernel);
  // Longest first; the sort is stable, so equal costs (a first frame's zeros) stay in row-major
  // order. Measured on 2 x H200 (docs/results/multi-gpu, heaviest first): N-body 2048^3 at
  // 1024^2 1.06x on one GPU, 1.03x on two; N-body 512^3 / 1024^3 1.11x / 1.06x; the dense
  // Richtmyer-Meshkov 1024^3 0.985x and N-body at 2048^2 0.98x (their bulk of similar tiles
  // loses row-major order's neighbours running together). Only the heavy units first (a stable
  // sort on "at least 1/8 of the slowest", the rest in row-major order) was worse: 0.94x.
  size_t bytes = 0;
  SS_CUDA_CHECK(cub::DeviceRadixSort::SortPairsDescending(nullptr, bytes, keys, keys + n, units, units + n, int(n), 0,
                                                          kOrderKeyBits, stream));
  void* temp = orderTemp_.ensure(bytes);
  SS_CUDA_CHECK(cub::DeviceRadixSort::SortPairsDescending(temp, bytes, keys, keys + n, units, units + n, int(n), 0,
                                                          kOrderKeyBits, stream));
  o.order = units + n;
  // The longest block, for the frame's statistics (FrameStats::longestBlockSeconds). Measured
  // on 2 x H200, N-body 2048^3 at 1024^2: 0.068 ms in a 0.99 ms kernel on one GPU and a 0.64 ms
  // kernel on two (docs/results/multi-gpu): no slow block bounds the scaling.
  if (!h_longest_.get()) h_longest_.reserve(sizeof(unsigned));
  SS_CUDA_CHECK(cudaMemcpyAsync(h_longest_.get(), keys + n, sizeof(unsigned), cudaMemcpyDeviceToHost, stream));
  SS_CUDA_CHECK(cudaEventRecord(longestCopied_, stream));
  longestPending_ = true;
  return o;
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

int64_t CudaExecutor::lastFrameQueuedShadowRays() const {
  if (!lastQueueCapacity_) return 0;
  SS_CUDA_CHECK(cudaEventSynchronize(shadowCounted_));
  return std::min<int64_t>(*static_cast<const unsigned*>(h_shadowCount_.get()), lastQueueCapacity_);
}

double CudaExecutor::lastFrameLongestBlockSeconds() const {
  if (!longestPending_ || !(clockHz_ > 0)) return -1;
  SS_CUDA_CHECK(cudaEventSynchronize(longestCopied_));
  return orderKeyCycles(*static_cast<const unsigned*>(h_longest_.get())) / clockHz_;
}

void CudaExecutor::prepareShadowQueue(FrameView& f, size_t pixels, cudaStream_t stream) {
  lastQueueCapacity_ = 0;
  f.scatter.queue = nullptr;
  f.scatter.queueCount = nullptr;
  f.scatter.queueCapacity = 0;
  if (shadowCountPending_ && cudaEventQuery(shadowCounted_) == cudaSuccess) {  // not ready: keep the size
    shadowNeed_ = *static_cast<const unsigned*>(h_shadowCount_.get());
    shadowCountPending_ = false;
  }
  if (!f.scatter.on || !tuning_.deferShadows) {
    d_shadowQueue_.release();  // only what a frame needs
    return;
  }
  // One ray a pixel at first; then room for what the last frame offered and a quarter more, at
  // most 16 a pixel and 512 MiB. A full queue costs no correctness: the rays beyond it are
  // marched where their samples are.
  const size_t most = std::min(pixels * 16, (size_t(512) << 20) / sizeof(ShadowRecord));
  size_t want = d_shadowQueue_.capacity() ? d_shadowQueue_.capacity() : pixels;
  if (shadowNeed_ > want || shadowNeed_ * 4 < want) want = std::max(pixels / 4, shadowNeed_ + shadowNeed_ / 4);
  want = std::max<size_t>(1, std::min(want, most));
  try {
    if (want != d_shadowQueue_.capacity()) {
      d_shadowQueue_.release();
      d_shadowQueue_.reserve(want);
    }
    d_shadowCount_.reserve(1);
    if (!h_shadowCount_.get()) h_shadowCount_.reserve(sizeof(unsigned));
  } catch (const std::exception&) {  // no room: the shadow rays are marched in place
    (void)cudaGetLastError();
    d_shadowQueue_.release();
    return;
  }
  SS_CUDA_CHECK(cudaMemsetAsync(d_shadowCount_.get(), 0, sizeof(unsigned), stream));
  f.scatter.queue = d_shadowQueue_.get();
  f.scatter.queueCount = d_shadowCount_.get();
  f.scatter.queueCapacity = unsigned(d_shadowQueue_.capacity());
  lastQueueCapacity_ = f.scatter.queueCapacity;
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
  longestPending_ = false;        // tileOrder() sets it for a frame in order
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
  prepareShadowQueue(f, pixels, stream);
  SS_CUDA_CHECK(cudaEventRecord(ev0_, stream));
  const Volume& v = vol.volume();
  const AxisWarpView warp = vol.warp();
  if (warp.on() && (pool || f.sampling != kSampleTrilinear))
    throw BackendError("a rectilinear grid is drawn through its coordinates in core, with trilinear sampling only");
  if (warp.on()) {  // a rectilinear grid through its coordinates (AxisWarp.h): exact sampling
    launch(f, WarpedSampler{vol.d_voxels<unsigned char>(), v.type, v.dims.x, v.dims.y, v.dims.z, warp}, grid, block, 0,
           stream);
  } else if (pool) {  // sparse residency: the resident bricks, exact sampling
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
  if (f.scatter.queue) {  // how many rays the frame offered, for the next frame's queue
    SS_CUDA_CHECK(cudaMemcpyAsync(h_shadowCount_.get(), d_shadowCount_.get(), sizeof(unsigned), cudaMemcpyDeviceToHost,
                                  stream));
    SS_CUDA_CHECK(cudaEventRecord(shadowCounted_, stream));
    shadowCountPending_ = true;
  }
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

}  // namespace spaceskip::cuda

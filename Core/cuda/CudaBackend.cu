// The CUDA backend: volume upload, range grid and classification kernels, GPU builders, and a
// one-thread-per-pixel executor of Core's shared renderPixel (exact or hardware trilinear).
#include "BuildContext.cuh"
#include "CudaCommon.cuh"
#include "DistanceField.cuh"
#include "KdTreeBuilder.cuh"
#include "LbvhBuilder.cuh"
#include "spaceskip/Backend.h"
#include "spaceskip/Builders.h"
#include "spaceskip/DistanceField.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <type_traits>
#include <vector>

namespace spaceskip {

namespace {

using cuda::DeviceBuffer;
using cuda::blocksFor;

constexpr int kThreads = 256;
constexpr int kMaxSparseLevels = 32;

/// Max-opacity range queries over the TF table (the device twin of OpacityRangeMax: the same
/// sparse table and the same index arithmetic, so GPU and CPU classification agree exactly).
struct SparseTableView {
  const float* levels;  ///< level k at offset[k], size - 2^k + 1 entries
  int offset[kMaxSparseLevels];
  int size;
  double lo, scale;

  __device__ float query(double vmin, double vmax) const {
    if (!(vmin <= vmax)) return 0.f;
    double x0 = (vmin - lo) * scale, x1 = (vmax - lo) * scale;
    x0 = fmin(fmax(x0, 0.0), double(size - 1));
    x1 = fmin(fmax(x1, 0.0), double(size - 1));
    int i0 = int(floor(x0)) - 1, i1 = int(ceil(x1)) + 1;
    i0 = min(max(i0, 0), size - 1);
    i1 = min(max(i1, i0), size - 1);
    const int len = i1 - i0 + 1;
    int k = 0;
    while ((2 << k) <= len) ++k;
    const float* L = levels + offset[k];
    return fmaxf(L[i0], L[i1 - (1 << k) + 1]);
  }
};

// One thread per brick: min/max of the voxels [b*B, (b+1)*B] (the +1 halo), NaN skipped.
template <class T>
__global__ void rangeKernel(const T* data, vec3l dims, vec3i bdims, int brick, float* vmin, float* vmax) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  const int64_t nb = int64_t(bdims.x) * bdims.y * bdims.z;
  if (i >= nb) return;
  const int64_t bx = i % bdims.x, by = (i / bdims.x) % bdims.y, bz = i / (int64_t(bdims.x) * bdims.y);
  const int64_t x0 = bx * brick, x1 = min(x0 + brick, dims.x - 1);
  const int64_t y0 = by * brick, y1 = min(y0 + brick, dims.y - 1);
  const int64_t z0 = bz * brick, z1 = min(z0 + brick, dims.z - 1);
  float lo = INFINITY, hi = -INFINITY;
  for (int64_t z = z0; z <= z1; ++z)
    for (int64_t y = y0; y <= y1; ++y) {
      const T* line = data + dims.x * (y + dims.y * z);
      for (int64_t x = x0; x <= x1; ++x) {
        const float v = float(line[x]);
        if (v != v) continue;
        lo = v < lo ? v : lo;
        hi = v > hi ? v : hi;
      }
    }
  vmin[i] = lo;
  vmax[i] = hi;
}

// One thread per brick: occupancy against the TF; counts occupied bricks (one atomic per block)
// and flags any difference from the previous occupancy.
__global__ void classifyKernel(const float* vmin, const float* vmax, int64_t n, SparseTableView rmq,
                               const uint8_t* prev, uint8_t* occ, unsigned long long* occupied, int* changed) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  int o = 0, diff = 0;
  if (i < n) {
    o = rmq.query(double(vmin[i]), double(vmax[i])) > 0.f ? 1 : 0;
    occ[i] = uint8_t(o);
    diff = prev ? (prev[i] != o) : 1;
  }
  const int blockCount = __syncthreads_count(o);
  const int blockDiff = __syncthreads_or(diff);
  if (threadIdx.x == 0) {
    if (blockCount) atomicAdd(occupied, (unsigned long long)blockCount);
    if (blockDiff) atomicOr(changed, 1);
  }
}

// Hardware-filtered sampling: a 3-D texture with linear filtering. Integer types are read as
// normalized floats and scaled back to raw values so the TF mapping is the same as in exact mode.
struct TextureSampler {
  cudaTextureObject_t tex;
  float scale;
  __device__ float sample(vec3f p) const { return tex3D<float>(tex, p.x + 0.5f, p.y + 0.5f, p.z + 0.5f) * scale; }
};

// Launch shape: 2-D grid of 16x8 blocks (SPACESKIP_CUDA_BLOCK overrides), one thread per pixel.
// One kernel per traversal: a kernel holding every traversal is allocated the registers of the
// tree traversal (64 per thread, half occupancy), which the naive and grid marches do not need.
// SPACESKIP_CUDA_HW_MIN_BLOCKS > 1 asks the hardware-filtered kernels to fit that many blocks of
// 256 threads per SM (a register cap). Measured on the H100 (round 3): 6 (40 registers) made
// every ESS kernel 4-11% slower than no cap, so the default is 1 (no cap).
constexpr int kMaxRenderThreads = 256;
// Default launch of the hardware-filtered kernels: plain for volumes up to kLargeTextureBytes; a
// persistent launch with kLargeTextureResident blocks of 128 threads per SM above. Measured on
// the H100 (docs/results/cuda-h100-round3): naive:hw at 2048^3 (8 GiB) runs fastest with 6
// blocks per SM (more warps in flight thrash the texture path), at 1024^3 (1 GiB) with all 16;
// the skipping kernels do not care either way.
constexpr size_t kLargeTextureBytes = size_t(2) << 30;
constexpr int kLargeTextureResident = 6;
template <class Sampler>
struct RenderMinBlocks {
  static constexpr int value = 1;
};
#ifndef SPACESKIP_CUDA_HW_MIN_BLOCKS
#define SPACESKIP_CUDA_HW_MIN_BLOCKS 1  // CMake: SPACESKIP_CUDA_HW_MIN_BLOCKS (1 = no register cap)
#endif
template <>
struct RenderMinBlocks<TextureSampler> {
  static constexpr int value = SPACESKIP_CUDA_HW_MIN_BLOCKS;
};

// Tiles of blockDim pixels. Without `tileCounter` block (i, j) renders tile (i, j). With it the
// launch is persistent: a fixed number of resident blocks take tiles in row-major order from the
// counter until none are left, which bounds the warps in flight (the volume's cache working set)
// and balances blocks whose rays cost very different amounts.
template <class Sampler, int Traversal>
__global__ void __launch_bounds__(kMaxRenderThreads, RenderMinBlocks<Sampler>::value)
    renderKernel(const __grid_constant__ FrameView f, const __grid_constant__ Sampler s, vec4f* out,
                 unsigned* tileCounter) {
  const unsigned tilesX = (unsigned(f.width) + blockDim.x - 1) / blockDim.x;
  auto tile = [&](unsigned tx, unsigned ty) {
    const int x = int(tx * blockDim.x + threadIdx.x), y = int(ty * blockDim.y + threadIdx.y);
    if (x < f.width && y < f.height) out[int64_t(y) * f.width + x] = renderPixel<Sampler, Traversal>(f, s, x, y);
  };
  if (!tileCounter) {
    tile(blockIdx.x, blockIdx.y);
    return;
  }
  const unsigned numTiles = tilesX * ((unsigned(f.height) + blockDim.y - 1) / blockDim.y);
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

template <class Sampler>
using RenderKernelPtr = void (*)(const FrameView, const Sampler, vec4f*, unsigned*);

template <class Sampler>
RenderKernelPtr<Sampler> renderKernelFor(TraversalKind t) {
  switch (t) {
    case TraversalKind::Naive: return renderKernel<Sampler, int(TraversalKind::Naive)>;
    case TraversalKind::Grid: return renderKernel<Sampler, int(TraversalKind::Grid)>;
    case TraversalKind::Tree: return renderKernel<Sampler, int(TraversalKind::Tree)>;
    case TraversalKind::Hybrid: return renderKernel<Sampler, int(TraversalKind::Hybrid)>;
  }
  return renderKernel<Sampler, int(TraversalKind::Naive)>;
}

// One thread per voxel: double -> float (textures have no double channel).
__global__ void toFloatKernel(const double* in, float* out, int64_t n) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n) out[i] = float(in[i]);
}

class CudaBackend final : public Backend {
 public:
  CudaBackend() {
    try {
      SS_CUDA_CHECK(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking));
      SS_CUDA_CHECK(cudaEventCreate(&ev0_));
      SS_CUDA_CHECK(cudaEventCreate(&ev1_));
      SS_CUDA_CHECK(cudaMallocHost(&h_flags_, sizeof(Flags)));
    } catch (...) {
      releaseHandles();  // no destructor runs for a half-built object
      throw;
    }
    // Tuning knob for measurements: SPACESKIP_CUDA_BLOCK=WxH (threads per block, default 16x8, at most 256).
    if (const char* b = std::getenv("SPACESKIP_CUDA_BLOCK")) {
      unsigned w = 0, h = 0;
      if (std::sscanf(b, "%ux%u", &w, &h) == 2 && w * h >= 32 && w * h <= unsigned(kMaxRenderThreads)) {
        blockX_ = w;
        blockY_ = h;
      }
    }
    int dev = 0;
    if (cudaGetDevice(&dev) != cudaSuccess ||
        cudaDeviceGetAttribute(&numSMs_, cudaDevAttrMultiProcessorCount, dev) != cudaSuccess || numSMs_ < 1) {
      (void)cudaGetLastError();
      numSMs_ = 1;
    }
    // Tuning knob for measurements: SPACESKIP_CUDA_CARVEOUT=0..100 (percent of the unified L1 /
    // shared memory given to shared memory for the render kernels; 0 = largest L1).
    if (const char* c = std::getenv("SPACESKIP_CUDA_CARVEOUT")) {
      const int v = std::atoi(c);
      if (v >= 0 && v <= 100) carveout_ = v;
    }
  }
  ~CudaBackend() override {
    destroyTexture();
    releaseHandles();
  }

  BackendKind kind() const override { return BackendKind::CUDA; }
  const char* name() const override { return "cuda"; }

  void setVolume(const Volume& v, int brick) override {
    validate(v);
    destroyTexture();
    volume_ = v;
    volume_.storage.reset();  // the Engine keeps the voxels alive; we keep the device copy
    tree_ = cuda::DeviceTree{};
    hostTree_ = Tree{};
    traversal_ = TraversalKind::Naive;
    d_distField_ = nullptr;
    haveOcc_ = false;
    const size_t bytes = v.byteSize();
    d_volume_.release();
    d_volume_.reserve(bytes);
    SS_CUDA_CHECK(cudaMemcpyAsync(d_volume_.get(), v.data, bytes, cudaMemcpyHostToDevice, stream_));
    brick_ = std::max(1, brick);
    cellDims_ = v.cellDims();
    bdims_ = vec3i{(cellDims_.x + brick_ - 1) / brick_, (cellDims_.y + brick_ - 1) / brick_,
                   (cellDims_.z + brick_ - 1) / brick_};
    const int64_t nb = numBricks();
    d_vmin_.reserve(size_t(nb));
    d_vmax_.reserve(size_t(nb));
    d_occ_[0].reserve(size_t(nb));
    d_occ_[1].reserve(size_t(nb));
    switch (v.type) {
      case VoxelType::UInt8: ranges<uint8_t>(); break;
      case VoxelType::Int8: ranges<int8_t>(); break;
      case VoxelType::UInt16: ranges<uint16_t>(); break;
      case VoxelType::Int16: ranges<int16_t>(); break;
      case VoxelType::Float32: ranges<float>(); break;
      case VoxelType::Float64: ranges<double>(); break;
    }
    SS_CUDA_CHECK(cudaStreamSynchronize(stream_));
  }

  bool classify(const TransferFunction& tf) override {
    if (tf.table.empty()) throw std::invalid_argument("empty transfer-function table");
    // The sparse table over the TF's (uncorrected) opacity, as OpacityRangeMax builds it.
    const int size = int(tf.table.size());
    SparseTableView rmq{};
    std::vector<float> flat;
    std::vector<float> level(static_cast<size_t>(size));
    for (int i = 0; i < size; ++i) level[size_t(i)] = tf.table[size_t(i)].w;
    int k = 0;
    rmq.offset[k++] = 0;
    flat.insert(flat.end(), level.begin(), level.end());
    for (int len = 2; len <= size; len *= 2) {
      if (k >= kMaxSparseLevels) throw BackendError("transfer-function table too large");
      std::vector<float> cur(size_t(size - len + 1));
      for (int i = 0; i + len <= size; ++i) cur[size_t(i)] = std::max(level[size_t(i)], level[size_t(i + len / 2)]);
      rmq.offset[k++] = int(flat.size());
      flat.insert(flat.end(), cur.begin(), cur.end());
      level = std::move(cur);
    }
    d_sparse_.reserve(flat.size());
    SS_CUDA_CHECK(cudaMemcpyAsync(d_sparse_.get(), flat.data(), flat.size() * sizeof(float), cudaMemcpyHostToDevice,
                                  stream_));
    rmq.levels = d_sparse_.get();
    rmq.size = size;
    rmq.lo = tf.rangeMin;
    rmq.scale = tf.rangeMax > tf.rangeMin ? double(size - 1) / (tf.rangeMax - tf.rangeMin) : 0.0;

    const int64_t nb = numBricks();
    const uint8_t* prev = haveOcc_ ? d_occ_[cur_].get() : nullptr;
    uint8_t* next = d_occ_[1 - cur_].get();
    d_flags_.reserve(1);
    SS_CUDA_CHECK(cudaMemsetAsync(d_flags_.get(), 0, sizeof(Flags), stream_));
    classifyKernel<<<blocksFor(nb, kThreads), kThreads, 0, stream_>>>(
        d_vmin_.get(), d_vmax_.get(), nb, rmq, prev, next, &d_flags_.get()->occupied, &d_flags_.get()->changed);
    SS_CUDA_CHECK_LAUNCH(classifyKernel);
    SS_CUDA_CHECK(cudaMemcpyAsync(h_flags_, d_flags_.get(), sizeof(Flags), cudaMemcpyDeviceToHost, stream_));
    SS_CUDA_CHECK(cudaStreamSynchronize(stream_));
    cur_ = 1 - cur_;
    const bool changed = !haveOcc_ || h_flags_->changed != 0;
    haveOcc_ = true;
    occupied_ = int64_t(h_flags_->occupied);
    hostOccValid_ = false;
    return changed;
  }

  void setTransferTable(const std::vector<vec4f>& t, float lo, float scale) override {
    d_table_.reserve(t.size());
    SS_CUDA_CHECK(cudaMemcpyAsync(d_table_.get(), t.data(), t.size() * sizeof(vec4f), cudaMemcpyHostToDevice, stream_));
    SS_CUDA_CHECK(cudaStreamSynchronize(stream_));
    tableSize_ = int(t.size());
    tfLo_ = lo;
    tfScale_ = scale;
  }

  void build(const BuildParams& p, BuildStats& s) override {
    if (!haveOcc_) throw BackendError("CUDA backend: build() before classify()");
    auto t0 = std::chrono::steady_clock::now();
    const BuilderInfo& info = builderInfo(p.builder);
    traversal_ = info.traversal;
    tree_.numNodes = 0;
    tree_.height = 0;
    tree_.leaves = 0;
    hostTree_ = Tree{};
    hybridGridValid_ = false;
    d_distField_ = nullptr;
    s.builtOn = "cuda";
    if (info.extra == BuilderExtra::DistanceField)
      d_distField_ = cuda::computeDistanceField(d_occ_[cur_].get(), bdims_, kMaxSkipDistance, dist_, stream_);
    if (info.cuda) {
      cuda::BuildContext ctx{{d_occ_[cur_].get(), bdims_, brick_, cellDims_, occupied_}, stream_, tree_, workspaces_};
      info.cuda(ctx, p);
      checkTreeHeight(p.builder, tree_.height);
    } else if (buildsTree(info)) {
      // Host builders on the downloaded occupancy; the tree (and Hybrid's grid) is uploaded.
      const OccupancyGrid& occ = occupancy();
      hostTree_ = buildTreeCPU(occ, p);
      uploadTree(hostTree_);
      if (info.extra == BuilderExtra::CoarseGrid) {
        OccupancyGrid coarse = coarsen(occ, std::max(1, kHybridCell / occ.brick));
        d_hybrid_.reserve(coarse.occ.size());
        SS_CUDA_CHECK(cudaMemcpyAsync(d_hybrid_.get(), coarse.occ.data(), coarse.occ.size(), cudaMemcpyHostToDevice,
                                      stream_));
        hybridDims_ = coarse.dims;
        hybridBrick_ = coarse.brick;
        hybridGridValid_ = true;
      }
      SS_CUDA_CHECK(cudaStreamSynchronize(stream_));
      s.builtOn = "cpu";
    }
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    s.nodes = tree_.numNodes;
    s.height = tree_.height;
    s.leaves = tree_.leaves;
  }

  void render(FrameView f, FilterMode filter, const float* depth, Image& out) override {
    const size_t pixels = size_t(f.width) * size_t(f.height);
    f.traversal = traversal_;
    if (traversal_ == TraversalKind::Hybrid && hybridGridValid_)
      f.grid = GridView{d_hybrid_.get(), hybridDims_, hybridBrick_};
    else
      f.grid = GridView{d_occ_[cur_].get(), bdims_, brick_, d_distField_};
    f.tree = TreeView{tree_.nodes.get(), tree_.numNodes};
    // In these modes every skipping builder marches the value ranges (render/Integrator.h, usesValueRanges).
    if (usesValueRanges(f.blend) && traversal_ != TraversalKind::Naive) {
      f.traversal = TraversalKind::Grid;
      f.grid = GridView{nullptr, bdims_, brick_, nullptr, d_vmin_.get(), d_vmax_.get()};
    }
    f.tf = TransferFunctionView{d_table_.get(), tableSize_, tfLo_, tfScale_};
    f.depth = nullptr;
    if (depth) {
      d_depth_.reserve(pixels);
      SS_CUDA_CHECK(cudaMemcpyAsync(d_depth_.get(), depth, pixels * sizeof(float), cudaMemcpyHostToDevice, stream_));
      f.depth = d_depth_.get();
    }
    unsigned* hostCounts = f.sampleCount;
    f.sampleCount = nullptr;
    if (hostCounts) {
      d_counts_.reserve(pixels);
      f.sampleCount = d_counts_.get();
    }
    d_image_.reserve(pixels);
    const dim3 block(blockX_, blockY_);
    const dim3 grid(unsigned((f.width + blockX_ - 1) / blockX_), unsigned((f.height + blockY_ - 1) / blockY_));
    SS_CUDA_CHECK(cudaEventRecord(ev0_, stream_));
    if (filter == FilterMode::Hardware) {
      ensureTexture();
      launchRender(f, TextureSampler{tex_, texScale_}, grid, block);
    } else {
      switch (volume_.type) {
        case VoxelType::UInt8: launch<uint8_t>(f, grid, block); break;
        case VoxelType::Int8: launch<int8_t>(f, grid, block); break;
        case VoxelType::UInt16: launch<uint16_t>(f, grid, block); break;
        case VoxelType::Int16: launch<int16_t>(f, grid, block); break;
        case VoxelType::Float32: launch<float>(f, grid, block); break;
        case VoxelType::Float64: launch<double>(f, grid, block); break;
      }
    }
    SS_CUDA_CHECK_LAUNCH(renderKernel);
    SS_CUDA_CHECK(cuda::injectedRenderError());
    SS_CUDA_CHECK(cudaEventRecord(ev1_, stream_));
    out.width = f.width;
    out.height = f.height;
    if (imageOnDevice_ && !hostCounts) {
      // The caller draws d_image_ itself (CUDA-GL interop): no download.
      out.rgba.clear();
      SS_CUDA_CHECK(cudaStreamSynchronize(stream_));
      float ms = 0;
      SS_CUDA_CHECK(cudaEventElapsedTime(&ms, ev0_, ev1_));
      lastDeviceSeconds_ = double(ms) * 1e-3;
      deviceImageValid_ = true;
      return;
    }
    deviceImageValid_ = false;
    out.rgba.resize(pixels);
    // Through a pinned staging buffer (DMA at full link speed, then a parallel host copy): about
    // twice as fast as a copy into the caller's pageable vector. Without pinned memory, direct.
    const size_t imageBytes = pixels * sizeof(vec4f);
    const bool staged = ensureStage(imageBytes);
    SS_CUDA_CHECK(cudaMemcpyAsync(staged ? h_stage_ : static_cast<void*>(out.rgba.data()), d_image_.get(), imageBytes,
                                  cudaMemcpyDeviceToHost, stream_));
    if (hostCounts)
      SS_CUDA_CHECK(cudaMemcpyAsync(hostCounts, d_counts_.get(), pixels * sizeof(unsigned), cudaMemcpyDeviceToHost,
                                    stream_));
    SS_CUDA_CHECK(cudaStreamSynchronize(stream_));
    if (staged) parallelCopy(out.rgba.data(), h_stage_, imageBytes);
    float ms = 0;
    SS_CUDA_CHECK(cudaEventElapsedTime(&ms, ev0_, ev1_));
    lastDeviceSeconds_ = double(ms) * 1e-3;
  }

  double lastFrameDeviceSeconds() const override { return lastDeviceSeconds_; }
  bool setImageOnDevice(bool on) override {
    imageOnDevice_ = on;
    deviceImageValid_ = false;
    return true;
  }
  const void* deviceImage() const override { return deviceImageValid_ ? d_image_.get() : nullptr; }

  const OccupancyGrid& occupancy() override {
    if (!hostOccValid_) {
      hostOcc_ = OccupancyGrid{};
      hostOcc_.brick = brick_;
      hostOcc_.cellDims = cellDims_;
      hostOcc_.dims = bdims_;
      if (haveOcc_) {
        hostOcc_.occ.resize(size_t(numBricks()));
        SS_CUDA_CHECK(cudaMemcpyAsync(hostOcc_.occ.data(), d_occ_[cur_].get(), hostOcc_.occ.size(),
                                      cudaMemcpyDeviceToHost, stream_));
        SS_CUDA_CHECK(cudaStreamSynchronize(stream_));
        hostOcc_.occupied = occupied_;
      }
      hostOccValid_ = true;
    }
    return hostOcc_;
  }

  Tree tree() override {
    Tree t;
    if (tree_.numNodes > 0) {
      t.nodes.resize(size_t(tree_.numNodes));
      SS_CUDA_CHECK(cudaMemcpyAsync(t.nodes.data(), tree_.nodes.get(), t.nodes.size() * sizeof(Node),
                                    cudaMemcpyDeviceToHost, stream_));
      SS_CUDA_CHECK(cudaStreamSynchronize(stream_));
    }
    t.height = tree_.height;
    t.leaves = tree_.leaves;
    return t;
  }

 private:
  struct Flags {
    unsigned long long occupied;
    int changed;
  };

  int64_t numBricks() const { return int64_t(bdims_.x) * bdims_.y * bdims_.z; }

  template <class T>
  void ranges() {
    rangeKernel<T><<<blocksFor(numBricks(), kThreads), kThreads, 0, stream_>>>(
        static_cast<const T*>(static_cast<const void*>(d_volume_.get())), volume_.dims, bdims_, brick_, d_vmin_.get(),
        d_vmax_.get());
    SS_CUDA_CHECK_LAUNCH(rangeKernel);
  }

  template <class T>
  void launch(const FrameView& f, dim3 grid, dim3 block) {
    ArraySampler<T> s{static_cast<const T*>(static_cast<const void*>(d_volume_.get())), volume_.dims.x,
                      volume_.dims.y, volume_.dims.z};
    launchRender(f, s, grid, block);
  }

  template <class Sampler>
  void launchRender(const FrameView& f, const Sampler& s, dim3 grid, dim3 block) {
    // SPACESKIP_CUDA_RESIDENT=N: persistent launch with N blocks per SM taking tiles from a
    // counter (0: one block per tile, the plain launch). Read per frame (bench items set it).
    int residentBlocks = std::is_same<Sampler, TextureSampler>::value && arrayBytes_ > kLargeTextureBytes
                             ? std::max(1, kLargeTextureResident * 128 / int(block.x * block.y))
                             : 0;
    if (const char* r = std::getenv("SPACESKIP_CUDA_RESIDENT")) residentBlocks = std::max(0, std::atoi(r));
    RenderKernelPtr<Sampler> k = renderKernelFor<Sampler>(f.traversal);
    if (carveout_ >= 0)
      SS_CUDA_CHECK(cudaFuncSetAttribute(k, cudaFuncAttributePreferredSharedMemoryCarveout, carveout_));
    if (residentBlocks <= 0) {
      k<<<grid, block, 0, stream_>>>(f, s, d_image_.get(), nullptr);
      return;
    }
    d_tileCounter_.reserve(1);
    SS_CUDA_CHECK(cudaMemsetAsync(d_tileCounter_.get(), 0, sizeof(unsigned), stream_));
    const unsigned tiles = grid.x * grid.y;
    const unsigned blocks = std::min(tiles, unsigned(residentBlocks) * unsigned(numSMs_));
    k<<<blocks, block, 0, stream_>>>(f, s, d_image_.get(), d_tileCounter_.get());
  }

  void uploadTree(const Tree& t) {
    tree_.numNodes = int(t.nodes.size());
    tree_.height = t.height;
    tree_.leaves = t.leaves;
    if (t.nodes.empty()) return;
    tree_.nodes.reserve(t.nodes.size());
    SS_CUDA_CHECK(cudaMemcpyAsync(tree_.nodes.get(), t.nodes.data(), t.nodes.size() * sizeof(Node),
                                  cudaMemcpyHostToDevice, stream_));
  }

  void ensureTexture() {
    if (tex_) return;
    destroyTexture();  // an array left by an earlier attempt that failed after allocating it
    cudaChannelFormatDesc desc{};
    cudaTextureReadMode mode = cudaReadModeNormalizedFloat;
    const void* src = d_volume_.get();
    size_t elem = voxelSize(volume_.type);
    DeviceBuffer<float> converted;
    switch (volume_.type) {
      case VoxelType::UInt8: desc = cudaCreateChannelDesc<uint8_t>(); texScale_ = 255.f; break;
      case VoxelType::Int8: desc = cudaCreateChannelDesc<int8_t>(); texScale_ = 127.f; break;
      case VoxelType::UInt16: desc = cudaCreateChannelDesc<uint16_t>(); texScale_ = 65535.f; break;
      case VoxelType::Int16: desc = cudaCreateChannelDesc<int16_t>(); texScale_ = 32767.f; break;
      case VoxelType::Float32:
        desc = cudaCreateChannelDesc<float>();
        mode = cudaReadModeElementType;
        texScale_ = 1.f;
        break;
      case VoxelType::Float64: {
        desc = cudaCreateChannelDesc<float>();
        mode = cudaReadModeElementType;
        texScale_ = 1.f;
        const int64_t n = volume_.voxelCount();
        converted.reserve(size_t(n));
        toFloatKernel<<<blocksFor(n, kThreads), kThreads, 0, stream_>>>(
            static_cast<const double*>(static_cast<const void*>(d_volume_.get())), converted.get(), n);
        SS_CUDA_CHECK_LAUNCH(toFloatKernel);
        src = converted.get();
        elem = sizeof(float);
        break;
      }
    }
    const cudaExtent extent = make_cudaExtent(size_t(volume_.dims.x), size_t(volume_.dims.y), size_t(volume_.dims.z));
    SS_CUDA_CHECK(cuda::deviceMalloc3DArray(&array_, &desc, extent, arrayBytes_));
    cudaMemcpy3DParms copy{};
    copy.srcPtr = make_cudaPitchedPtr(const_cast<void*>(src), size_t(volume_.dims.x) * elem, size_t(volume_.dims.x),
                                      size_t(volume_.dims.y));
    copy.dstArray = array_;
    copy.extent = extent;
    copy.kind = cudaMemcpyDeviceToDevice;
    SS_CUDA_CHECK(cudaMemcpy3DAsync(&copy, stream_));
    SS_CUDA_CHECK(cudaStreamSynchronize(stream_));
    cudaResourceDesc res{};
    res.resType = cudaResourceTypeArray;
    res.res.array.array = array_;
    cudaTextureDesc td{};
    td.addressMode[0] = td.addressMode[1] = td.addressMode[2] = cudaAddressModeClamp;
    td.filterMode = cudaFilterModeLinear;
    td.readMode = mode;
    td.normalizedCoords = 0;
    SS_CUDA_CHECK(cudaCreateTextureObject(&tex_, &res, &td, nullptr));
  }

  void destroyTexture() {
    if (tex_) cudaDestroyTextureObject(tex_);
    cuda::deviceFreeArray(array_, arrayBytes_);
    tex_ = 0;
    array_ = nullptr;
    arrayBytes_ = 0;
  }

  /// Grows the pinned staging buffer to `bytes`; false (direct copies) when pinned memory is
  /// not available.
  bool ensureStage(size_t bytes) {
    if (stageBytes_ >= bytes) return true;
    if (h_stage_) cudaFreeHost(h_stage_);
    h_stage_ = nullptr;
    stageBytes_ = 0;
    if (cudaMallocHost(&h_stage_, bytes) != cudaSuccess) {
      (void)cudaGetLastError();
      h_stage_ = nullptr;
      return false;
    }
    stageBytes_ = bytes;
    return true;
  }

  void releaseHandles() {
    if (h_stage_) cudaFreeHost(h_stage_);
    h_stage_ = nullptr;
    stageBytes_ = 0;
    if (h_flags_) cudaFreeHost(h_flags_);
    if (ev0_) cudaEventDestroy(ev0_);
    if (ev1_) cudaEventDestroy(ev1_);
    if (stream_) cudaStreamDestroy(stream_);
    h_flags_ = nullptr;
    ev0_ = ev1_ = nullptr;
    stream_ = nullptr;
  }

  cudaStream_t stream_ = nullptr;
  cudaEvent_t ev0_ = nullptr, ev1_ = nullptr;
  Volume volume_;
  DeviceBuffer<unsigned char> d_volume_;
  cudaArray_t array_ = nullptr;
  size_t arrayBytes_ = 0;
  cudaTextureObject_t tex_ = 0;
  float texScale_ = 1.f;
  int brick_ = 8;
  vec3i cellDims_{0, 0, 0}, bdims_{0, 0, 0};
  DeviceBuffer<float> d_vmin_, d_vmax_;
  DeviceBuffer<uint8_t> d_occ_[2];
  int cur_ = 0;
  bool haveOcc_ = false;
  int64_t occupied_ = 0;
  DeviceBuffer<float> d_sparse_;
  DeviceBuffer<Flags> d_flags_;
  Flags* h_flags_ = nullptr;
  void* h_stage_ = nullptr;  ///< pinned copy of the last frame's image on its way to the caller
  bool imageOnDevice_ = false;     ///< setImageOnDevice(): leave the image in d_image_
  bool deviceImageValid_ = false;  ///< the last render() left its image in d_image_
  size_t stageBytes_ = 0;
  OccupancyGrid hostOcc_;
  bool hostOccValid_ = false;
  DeviceBuffer<vec4f> d_table_;
  int tableSize_ = 0;
  float tfLo_ = 0, tfScale_ = 1;
  TraversalKind traversal_ = TraversalKind::Naive;
  cuda::DeviceTree tree_;
  Tree hostTree_;
  cuda::WorkspaceStore workspaces_;  ///< the device builders' workspaces (BuildContext)
  DeviceBuffer<uint8_t> d_hybrid_;
  vec3i hybridDims_{0, 0, 0};
  int hybridBrick_ = 16;
  bool hybridGridValid_ = false;
  cuda::DistanceWorkspace dist_;
  const uint8_t* d_distField_ = nullptr;  ///< DistanceGrid's field (in dist_) for the current occupancy
  DeviceBuffer<float> d_depth_;
  DeviceBuffer<unsigned> d_counts_;
  DeviceBuffer<vec4f> d_image_;
  double lastDeviceSeconds_ = -1;
  unsigned blockX_ = 16, blockY_ = 8;
  int carveout_ = -1;  ///< -1: the driver's choice
  int numSMs_ = 1;
  DeviceBuffer<unsigned> d_tileCounter_;
};

}  // namespace

bool cudaAvailable(std::string* why) {
  int n = 0;
  cudaError_t e = cudaGetDeviceCount(&n);
  if (e != cudaSuccess) {
    (void)cudaGetLastError();
    if (why) *why = std::string("no usable CUDA device (") + cudaGetErrorName(e) + ": " + cudaGetErrorString(e) + ")";
    return false;
  }
  if (n == 0) {
    if (why) *why = "no CUDA device found";
    return false;
  }
  if (why) why->clear();
  return true;
}

int64_t cudaDeviceBytesInUse() { return cuda::liveDeviceBytes().load(); }

std::unique_ptr<Backend> makeCudaBackend() {
  std::string why;
  if (!cudaAvailable(&why)) throw BackendError(why);
  return std::make_unique<CudaBackend>();
}

}  // namespace spaceskip

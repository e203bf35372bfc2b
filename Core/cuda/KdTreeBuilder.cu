// GPU k-d trees over the brick occupancy: KdTreeGPU (the paper's host-driven recursion with one
// reduction per candidate child) and KdTreeGPUFast (ours: level-parallel over a 3-D SVT).
// Both use decideKdSplit (spaceskip/KdTreeSplit.h, as KdTreeCPU does), so they build the same tree.
#include "KdTreeBuilder.cuh"
#include "BuildContext.cuh"
#include "spaceskip/Morton.h"

#include <cub/device/device_reduce.cuh>
#include <cub/device/device_scan.cuh>
#include <thrust/iterator/transform_iterator.h>

#include <climits>
#include <stdexcept>
#include <string>
#include <vector>

namespace spaceskip::cuda {

namespace {

constexpr int kThreads = 256;

SS_FUNC box3i emptyBox() {
  box3i b;
  b.lo = vec3i{INT_MAX, INT_MAX, INT_MAX};
  b.hi = vec3i{INT_MIN, INT_MIN, INT_MIN};
  return b;
}

struct UniteBoxes {
  SS_FUNC box3i operator()(const box3i& a, const box3i& b) const { return unite(a, b); }
};

/// Keeps a brick box only when it lies inside the region (brick boxes never straddle a
/// region's border: regions are cut on the brick raster).
struct ClipToRegion {
  box3i region;
  SS_FUNC box3i operator()(const box3i& b) const {
    if (b.empty()) return emptyBox();
    if (b.lo.x < region.lo.x || b.lo.y < region.lo.y || b.lo.z < region.lo.z || b.hi.x > region.hi.x ||
        b.hi.y > region.hi.y || b.hi.z > region.hi.z)
      return emptyBox();
    return b;
  }
};

/// 1 for an occupied brick box inside the region, else 0 (leaf criterion Empty's counts).
struct OccupiedInRegion {
  box3i region;
  SS_FUNC int operator()(const box3i& b) const {
    const box3i c = ClipToRegion{region}(b);
    return c.lo.x <= c.hi.x ? 1 : 0;
  }
};

// ---- KdTreeGPU (paper 3.2.2) -----------------------------------------------------------------

// One thread per Morton index of the padded 2^k cube: the brick's clamped cell box when it is
// inside the grid and occupied, else an empty box (the paper's per-macro-cell tight boxes).
__global__ void mortonBoxesKernel(const uint8_t* occ, vec3i dims, int brick, vec3i cellDims, int64_t count,
                                  box3i* boxes) {
  const int64_t m = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (m >= count) return;
  uint32_t x, y, z;
  mortonDecode3(uint64_t(m), x, y, z);
  box3i b = emptyBox();
  if (int(x) < dims.x && int(y) < dims.y && int(z) < dims.z &&
      occ[x + int64_t(dims.x) * (y + int64_t(dims.y) * z)])
    b = brickCellBox(vec3i{int(x), int(y), int(z)}, brick, cellDims);
  boxes[m] = b;
}

/// The paper's boundary(): a full CUB reduction over the region's Morton range, read back to
/// the host (one synchronization per call, as thrust::reduce does in the paper's code).
struct ReductionTight {
  const BrickGridView* g;
  KdTreeGpuWorkspace* ws;
  size_t tempBytes;
  cudaStream_t stream;
  int reductions = 0;

  box3i operator()(const box3i& region) {
    if (region.empty()) return emptyBox();
    const box3i b = cellBrickBox(region, g->brick);
    const uint64_t mlo = mortonEncode3(b.lo.x, b.lo.y, b.lo.z);
    const uint64_t mhi = mortonEncode3(b.hi.x - 1, b.hi.y - 1, b.hi.z - 1);
    auto it = thrust::make_transform_iterator(ws->mortonBoxes.get() + mlo, ClipToRegion{region});
    size_t bytes = tempBytes;
    SS_CUDA_CHECK(cub::DeviceReduce::Reduce(ws->temp.bytes.get(), bytes, it, ws->result.get(), int64_t(mhi - mlo + 1),
                                            UniteBoxes{}, emptyBox(), stream));
    SS_CUDA_CHECK(cudaMemcpyAsync(ws->h_result, ws->result.get(), sizeof(box3i), cudaMemcpyDeviceToHost, stream));
    SS_CUDA_CHECK(cudaStreamSynchronize(stream));
    ++reductions;
    return *ws->h_result;
  }

  /// Occupied bricks in the brick box [lo, hi): one more reduction over its Morton range (leaf
  /// criterion Empty; KdTreeSplit.h).
  int64_t count(vec3i lo, vec3i hi) {
    if (lo.x >= hi.x || lo.y >= hi.y || lo.z >= hi.z) return 0;
    const box3i region = brickCellBox(box3i{lo, hi}, g->brick, g->cellDims);
    const uint64_t mlo = mortonEncode3(lo.x, lo.y, lo.z);
    const uint64_t mhi = mortonEncode3(hi.x - 1, hi.y - 1, hi.z - 1);
    auto it = thrust::make_transform_iterator(ws->mortonBoxes.get() + mlo, OccupiedInRegion{region});
    size_t bytes = 0;
    SS_CUDA_CHECK(cub::DeviceReduce::Sum(nullptr, bytes, it, ws->count.get(), int64_t(mhi - mlo + 1), stream));
    void* temp = ws->countTemp.ensure(bytes);
    SS_CUDA_CHECK(cub::DeviceReduce::Sum(temp, bytes, it, ws->count.get(), int64_t(mhi - mlo + 1), stream));
    int h = 0;
    SS_CUDA_CHECK(cudaMemcpyAsync(&h, ws->count.get(), sizeof(int), cudaMemcpyDeviceToHost, stream));
    SS_CUDA_CHECK(cudaStreamSynchronize(stream));
    ++reductions;
    return h;
  }
};

// ---- KdTreeGPUFast (ours) --------------------------------------------------------------------

// KdTreeGPUFast's tight boxes: the shared SvtView (SummedVolumeTable.h) over a device table.

// One thread per table entry: the occupancy shifted by one (the table's zero faces).
__global__ void svtInitKernel(const uint8_t* occ, vec3i dims, int64_t count, uint32_t* s) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= count) return;
  const int64_t sx = dims.x + 1, sy = dims.y + 1;
  const int x = int(i % sx), y = int((i / sx) % sy), z = int(i / (sx * sy));
  s[i] = (x > 0 && y > 0 && z > 0) ? uint32_t(occ[(x - 1) + int64_t(dims.x) * ((y - 1) + int64_t(dims.y) * (z - 1))])
                                   : 0u;
}

// One warp per x-line (coalesced): inclusive scan in chunks of 32 with a running carry.
__global__ void svtScanXKernel(uint32_t* s, vec3i dims) {
  const int64_t line = (int64_t(blockIdx.x) * blockDim.x + threadIdx.x) / 32;
  const int lane = threadIdx.x & 31;
  const int64_t sx = dims.x + 1, lines = int64_t(dims.y + 1) * (dims.z + 1);
  if (line >= lines) return;  // whole warps leave together
  uint32_t* row = s + line * sx;
  uint32_t carry = 0;
  for (int64_t base = 0; base < sx; base += 32) {
    const int64_t x = base + lane;
    uint32_t v = x < sx ? row[x] : 0u;
    for (int o = 1; o < 32; o *= 2) {
      const uint32_t n = __shfl_up_sync(0xffffffffu, v, o);
      if (lane >= o) v += n;
    }
    v += carry;
    if (x < sx) row[x] = v;
    carry = __shfl_sync(0xffffffffu, v, 31);
  }
}

// One thread per line along y (axis 1) or z (axis 2); neighbouring threads walk neighbouring
// x, so the accesses are coalesced.
__global__ void svtScanYZKernel(uint32_t* s, vec3i dims, int axis) {
  const int64_t t = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  const int64_t sx = dims.x + 1, sy = dims.y + 1, sz = dims.z + 1;
  int64_t start, stride, n;
  if (axis == 1) {
    if (t >= sx * sz) return;
    start = (t % sx) + sx * sy * (t / sx);
    stride = sx;
    n = sy;
  } else {
    if (t >= sx * sy) return;
    start = t;
    stride = sx * sy;
    n = sz;
  }
  uint32_t acc = 0;
  for (int64_t k = 0; k < n; ++k) {
    acc += s[start + k * stride];
    s[start + k * stride] = acc;
  }
}

// Single thread: the root's tight box.
__global__ void rootKernel(SvtView svt, box3i* out) {
  box3i all;
  all.lo = vec3i{0, 0, 0};
  all.hi = svt.cellDims;
  out[0] = svt(all);
}

// Stores node i of the level (its box, no children yet) and its split decision.
__device__ void storeDecision(int64_t i, int levelStart, const box3i& box, const detail::KdDecision& d, Node* nodes, int* flags,
                              box3i* childBoxes) {
  Node node;
  node.box = box;
  node.child = -1;
  node.pad = 0;
  nodes[levelStart + i] = node;
  flags[i] = d.split;
  childBoxes[2 * i] = d.left;
  childBoxes[2 * i + 1] = d.right;
}

// One thread per node of the level: writes the node's box and decides leaf or split.
__global__ void levelDecideKernel(const box3i* boxes, int n, int levelStart, detail::KdSplitParams p, SvtView svt,
                                  Node* nodes, int* flags, box3i* childBoxes) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const box3i box = boxes[i];
  storeDecision(i, levelStart, box, detail::decideKdSplit(box, p, svt), nodes, flags, childBoxes);
}

// Sweep (bins == 0): up to bricks/step - 1 candidates per node (255 for a 2048^3 root with 8^3
// bricks), so one warp per node of the level. Lane j evaluates candidates j+1, j+33, ... in
// increasing order, keeping its first minimum; the warp then reduces (cost, k) to the least cost
// and, among equal costs, the least k: decideKdSplit's serial rule (first minimum in plane order).
// Lane 0 recomputes the winner's children (two tight boxes) or takes the MLS split.
__global__ void levelDecideSweepKernel(const box3i* boxes, int n, int levelStart, detail::KdSplitParams p, SvtView svt,
                                       Node* nodes, int* flags, box3i* childBoxes) {
  const int64_t i = (int64_t(blockIdx.x) * blockDim.x + threadIdx.x) / 32;
  const int lane = threadIdx.x & 31;
  if (i >= n) return;  // whole warps leave together (blockDim is a multiple of 32)
  const box3i box = boxes[i];
  const int axis = detail::longestAxis(box);
  int64_t best = INT64_MAX;
  int bestK = INT_MAX;
  if (!detail::kdHalts(box, p)) {
    const int count = detail::kdCandidateCount(box, axis, p);
    for (int k = lane + 1; k <= count; k += 32) {
      box3i l, r;
      const int64_t c = detail::kdPlaneCost(box, axis, detail::kdCandidatePlane(box, axis, k, p), svt, l, r);
      if (c < best) {
        best = c;
        bestK = k;
      }
    }
  }
  for (int o = 16; o > 0; o /= 2) {
    const int64_t ob = __shfl_down_sync(0xffffffffu, best, o);
    const int ok = __shfl_down_sync(0xffffffffu, bestK, o);
    if (ob < best || (ob == best && ok < bestK)) {
      best = ob;
      bestK = ok;
    }
  }
  if (lane != 0) return;
  detail::KdDecision d;
  if (best != INT64_MAX) {
    d.split = 1;
    detail::kdPlaneCost(box, axis, detail::kdCandidatePlane(box, axis, bestK, p), svt, d.left, d.right);
  } else {
    d = detail::kdLeafSplit(box, axis, p, svt);
  }
  storeDecision(i, levelStart, box, d, nodes, flags, childBoxes);
}

// One thread per node of the level: links split nodes to their child pair in the next level.
__global__ void levelEmitKernel(int n, int levelStart, const int* flags, const int* offsets,
                                const box3i* childBoxes, Node* nodes, box3i* nextBoxes, int* nextSplits) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  if (flags[i]) {
    const int k = offsets[i];
    nodes[levelStart + i].child = levelStart + n + 2 * k;
    nextBoxes[2 * k] = childBoxes[2 * i];
    nextBoxes[2 * k + 1] = childBoxes[2 * i + 1];
  }
  if (i == n - 1) *nextSplits = offsets[i] + flags[i];
}

detail::KdSplitParams splitParams(const KdParams& p, int brick, int64_t rootVol) {
  detail::KdSplitParams s;
  s.deep = p.leaf != LeafCriterion::Shallow ? 1 : 0;
  s.empty = p.leaf == LeafCriterion::Empty ? 1 : 0;
  s.mls = p.maxLeafSize;
  BuildParams checked;  // direct callers (the tests) too: the one check, Builders.cpp's validate
  checked.bins = p.bins;
  validate(checked);
  s.bins = p.bins;
  s.brick = brick;
  s.rootVol = rootVol;
  return s;
}

}  // namespace

KdTreeGpuWorkspace::~KdTreeGpuWorkspace() {
  if (h_result) cudaFreeHost(h_result);
}
KdTreeGpuFastWorkspace::~KdTreeGpuFastWorkspace() {
  if (h_counter) cudaFreeHost(h_counter);
}

void buildKdTreeGpu(const BrickGridView& g, const KdParams& p, KdTreeGpuWorkspace& ws, DeviceTree& out,
                    cudaStream_t stream) {
  out.clear();
  if (g.occupied == 0) return;
  const int maxDim = std::max(g.dims.x, std::max(g.dims.y, g.dims.z));
  const int bits = bitsFor(maxDim);
  if (bits > 10) throw BackendError("KdTreeGPU: more than 1024 bricks along an axis");
  const int64_t count = int64_t(1) << (3 * bits);
  ws.mortonBoxes.reserve(size_t(count));
  ws.result.reserve(1);
  ws.count.reserve(1);
  if (!ws.h_result) SS_CUDA_CHECK(cudaMallocHost(&ws.h_result, sizeof(box3i)));
  mortonBoxesKernel<<<blocksFor(count, kThreads), kThreads, 0, stream>>>(g.d_occ, g.dims, g.brick, g.cellDims,
                                                                         count, ws.mortonBoxes.get());
  SS_CUDA_CHECK_LAUNCH(mortonBoxesKernel);
  size_t bytes = 0;
  auto it = thrust::make_transform_iterator(ws.mortonBoxes.get(), ClipToRegion{});
  SS_CUDA_CHECK(cub::DeviceReduce::Reduce(nullptr, bytes, it, ws.result.get(), count, UniteBoxes{}, emptyBox(),
                                          stream));
  ws.temp.ensure(bytes);

  ReductionTight tight{&g, &ws, bytes, stream};
  box3i all;
  all.lo = vec3i{0, 0, 0};
  all.hi = g.cellDims;
  std::vector<Node> nodes;
  std::vector<int> depth;
  Node root;
  root.box = tight(all);
  root.child = -1;
  root.pad = 0;
  nodes.push_back(root);
  depth.push_back(1);
  const detail::KdSplitParams sp = splitParams(p, g.brick, root.box.volume());
  // Depth-first on the host, as the paper's node_splitting recursion (explicit stack).
  std::vector<int> stack{0};
  int height = 1;
  int64_t leaves = 0;
  while (!stack.empty()) {
    const int idx = stack.back();
    stack.pop_back();
    const box3i box = nodes[size_t(idx)].box;
    detail::KdDecision d = detail::decideKdSplit(box, sp, tight);
    if (!d.split) {
      ++leaves;
      continue;
    }
    const int c = int(nodes.size());
    nodes[size_t(idx)].child = c;
    Node l{d.left, -1, 0}, r{d.right, -1, 0};
    nodes.push_back(l);
    nodes.push_back(r);
    const int dc = depth[size_t(idx)] + 1;
    depth.push_back(dc);
    depth.push_back(dc);
    height = std::max(height, dc);
    stack.push_back(c + 1);
    stack.push_back(c);
  }
  out.nodes.reserve(nodes.size());
  SS_CUDA_CHECK(cudaMemcpyAsync(out.nodes.get(), nodes.data(), nodes.size() * sizeof(Node), cudaMemcpyHostToDevice,
                                stream));
  SS_CUDA_CHECK(cudaStreamSynchronize(stream));
  out.numNodes = int(nodes.size());
  out.height = height;
  out.leaves = leaves;
}

void buildKdTreeGpuFast(const BrickGridView& g, const KdParams& p, KdTreeGpuFastWorkspace& ws, DeviceTree& out,
                        cudaStream_t stream) {
  out.clear();
  if (g.occupied == 0) return;
  const int64_t svtCount = int64_t(g.dims.x + 1) * (g.dims.y + 1) * (g.dims.z + 1);
  if (svtCount > int64_t(INT32_MAX) || g.occupied > int64_t(INT32_MAX) / 2)
    throw BackendError("KdTreeGPUFast: too many bricks for 32-bit counts");
  ws.svt.reserve(size_t(svtCount));
  if (!ws.h_counter) SS_CUDA_CHECK(cudaMallocHost(&ws.h_counter, sizeof(int)));

  // 1. The SVT over the bricks: shift, then inclusive scans along x, y, z.
  svtInitKernel<<<blocksFor(svtCount, kThreads), kThreads, 0, stream>>>(g.d_occ, g.dims, svtCount, ws.svt.get());
  SS_CUDA_CHECK_LAUNCH(svtInitKernel);
  const int64_t xLines = int64_t(g.dims.y + 1) * (g.dims.z + 1);
  svtScanXKernel<<<blocksFor(xLines * 32, kThreads), kThreads, 0, stream>>>(ws.svt.get(), g.dims);
  SS_CUDA_CHECK_LAUNCH(svtScanXKernel);
  const int64_t yLines = int64_t(g.dims.x + 1) * (g.dims.z + 1), zLines = int64_t(g.dims.x + 1) * (g.dims.y + 1);
  svtScanYZKernel<<<blocksFor(yLines, kThreads), kThreads, 0, stream>>>(ws.svt.get(), g.dims, 1);
  SS_CUDA_CHECK_LAUNCH(svtScanYZKernel);
  svtScanYZKernel<<<blocksFor(zLines, kThreads), kThreads, 0, stream>>>(ws.svt.get(), g.dims, 2);
  SS_CUDA_CHECK_LAUNCH(svtScanYZKernel);
  const SvtView svt{g.dims, g.brick, g.cellDims, ws.svt.get()};

  // 2. Root box (its volume drives the Shallow halting rule).
  const size_t maxNodes = size_t(2 * g.occupied);  // leaves <= occupied bricks (disjoint, non-empty)
  for (auto& b : ws.levelBoxes) b.reserve(maxNodes);
  ws.childBoxes.reserve(maxNodes);
  ws.splitFlags.reserve(maxNodes);
  ws.splitOffsets.reserve(maxNodes);
  ws.counter.reserve(1);
  out.nodes.reserve(maxNodes);
  rootKernel<<<1, 1, 0, stream>>>(svt, ws.levelBoxes[0].get());
  SS_CUDA_CHECK_LAUNCH(rootKernel);
  box3i rootBox;
  SS_CUDA_CHECK(cudaMemcpyAsync(&rootBox, ws.levelBoxes[0].get(), sizeof(box3i), cudaMemcpyDeviceToHost, stream));
  SS_CUDA_CHECK(cudaStreamSynchronize(stream));
  const detail::KdSplitParams sp = splitParams(p, g.brick, rootBox.volume());
  size_t scanBytes = 0;
  SS_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(nullptr, scanBytes, ws.splitFlags.get(), ws.splitOffsets.get(),
                                              int(maxNodes), stream));
  void* temp = ws.temp.ensure(scanBytes);

  // 3. One pass per level for all its nodes: decide, scan the split flags, emit the children.
  int n = 1, levelStart = 0, height = 0, cur = 0;
  while (n > 0) {
    if (size_t(levelStart) + size_t(n) > maxNodes)
      throw BackendError("KdTreeGPUFast: node count exceeded its bound (internal error)");
    if (sp.bins == 0) {
      levelDecideSweepKernel<<<blocksFor(int64_t(n) * 32, kThreads), kThreads, 0, stream>>>(
          ws.levelBoxes[cur].get(), n, levelStart, sp, svt, out.nodes.get(), ws.splitFlags.get(), ws.childBoxes.get());
      SS_CUDA_CHECK_LAUNCH(levelDecideSweepKernel);
    } else {
      levelDecideKernel<<<blocksFor(n, kThreads), kThreads, 0, stream>>>(
          ws.levelBoxes[cur].get(), n, levelStart, sp, svt, out.nodes.get(), ws.splitFlags.get(), ws.childBoxes.get());
      SS_CUDA_CHECK_LAUNCH(levelDecideKernel);
    }
    size_t bytes = scanBytes;
    SS_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(temp, bytes, ws.splitFlags.get(), ws.splitOffsets.get(), n, stream));
    levelEmitKernel<<<blocksFor(n, kThreads), kThreads, 0, stream>>>(
        n, levelStart, ws.splitFlags.get(), ws.splitOffsets.get(), ws.childBoxes.get(), out.nodes.get(),
        ws.levelBoxes[1 - cur].get(), ws.counter.get());
    SS_CUDA_CHECK_LAUNCH(levelEmitKernel);
    SS_CUDA_CHECK(cudaMemcpyAsync(ws.h_counter, ws.counter.get(), sizeof(int), cudaMemcpyDeviceToHost, stream));
    SS_CUDA_CHECK(cudaStreamSynchronize(stream));
    const int splits = *ws.h_counter;
    out.leaves += n - splits;
    levelStart += n;
    n = 2 * splits;
    cur = 1 - cur;
    ++height;
  }
  out.numNodes = levelStart;
  out.height = height;
}

namespace {
KdParams kdParams(const BuildParams& p) {
  KdParams kp;
  kp.leaf = p.leaf;
  kp.maxLeafSize = p.maxLeafSize;
  kp.bins = p.bins;
  return kp;
}
}  // namespace

void buildKdTreeGpu(BuildContext& ctx, const BuildParams& p) {
  buildKdTreeGpu(ctx.grid, kdParams(p), ctx.workspace<KdTreeGpuWorkspace>(), ctx.tree, ctx.stream);
}

void buildKdTreeGpuFast(BuildContext& ctx, const BuildParams& p) {
  buildKdTreeGpuFast(ctx.grid, kdParams(p), ctx.workspace<KdTreeGpuFastWorkspace>(), ctx.tree, ctx.stream);
}

}  // namespace spaceskip::cuda

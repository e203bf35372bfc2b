// LBVH over occupied bricks (paper 3.1): compaction, Morton codes, radix sort, Karras 2012
// hierarchy (karrasNode, shared with the CPU twin), bottom-up boxes; the result uses Core's flat
// node layout.
#include "LbvhBuilder.cuh"
#include "BuildContext.cuh"
#include "spaceskip/LbvhBuilder.h"
#include "spaceskip/Morton.h"

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_select.cuh>
#include <thrust/iterator/counting_iterator.h>

namespace spaceskip::cuda {

namespace {

constexpr int kThreads = 256;

struct IsOccupied {
  const uint8_t* occ;
  __device__ bool operator()(int i) const { return occ[i] != 0; }
};

SS_FUNC vec3i brickCoord(int64_t i, vec3i dims) {
  return vec3i{int(i % dims.x), int((i / dims.x) % dims.y), int(i / (int64_t(dims.x) * dims.y))};
}

// One thread per selected brick: its Morton code.
__global__ void mortonKernel(const int* ids, const int* numSelected, vec3i dims, uint64_t* codes) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= *numSelected) return;
  vec3i b = brickCoord(ids[i], dims);
  codes[i] = mortonEncode3(uint32_t(b.x), uint32_t(b.y), uint32_t(b.z));
}

// One thread per internal node i in [0, n-1). Karras node ids: internal i -> i, leaf j -> n-1+j.
// Writes the children's parent and their output slots (children of internal i go to 1+2i, 2+2i).
__global__ void karrasKernel(const uint64_t* keys, int n, int* parent, int* outIndex) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n - 1) return;
  const detail::KarrasNode k = detail::karrasNode(keys, n, i);
  const int left = k.leftLeaf ? (n - 1) + k.left : k.left;
  const int right = k.rightLeaf ? (n - 1) + k.right : k.right;
  parent[left] = i;
  parent[right] = i;
  outIndex[left] = 1 + 2 * i;
  outIndex[right] = 2 + 2 * i;
}

__device__ box3i loadBoxCG(const Node* n) {
  const int* p = reinterpret_cast<const int*>(&n->box);
  box3i b;
  b.lo = vec3i{__ldcg(p + 0), __ldcg(p + 1), __ldcg(p + 2)};
  b.hi = vec3i{__ldcg(p + 3), __ldcg(p + 4), __ldcg(p + 5)};
  return b;
}

// One thread per leaf: writes the leaf, then climbs; the second child to arrive at a node
// (atomic counter) writes the node's union box and height and continues (Karras 2012, sec. 4;
// Apetrei 2014). __threadfence orders the node writes before the counter update.
__global__ void bottomUpKernel(const int* sortedIds, int n, vec3i dims, int brick, vec3i cellDims,
                               const int* parent, const int* outIndex, int* arrivals, int* heights,
                               Node* nodes) {
  const int j = blockIdx.x * blockDim.x + threadIdx.x;
  if (j >= n) return;
  const int leafId = (n - 1) + j;
  const int o = outIndex[leafId];
  Node leaf;
  leaf.box = brickCellBox(brickCoord(sortedIds[j], dims), brick, cellDims);
  leaf.child = -1;
  leaf.pad = 0;
  nodes[o] = leaf;
  heights[o] = 1;
  if (n == 1) return;
  int cur = parent[leafId];
  for (;;) {
    __threadfence();
    if (atomicAdd(&arrivals[cur], 1) == 0) return;  // the sibling subtree is not done yet
    __threadfence();
    const int c = 1 + 2 * cur;
    Node inner;
    inner.box = unite(loadBoxCG(&nodes[c]), loadBoxCG(&nodes[c + 1]));
    inner.child = c;
    inner.pad = 0;
    const int oc = cur == 0 ? 0 : outIndex[cur];
    nodes[oc] = inner;
    heights[oc] = 1 + max(__ldcg(&heights[c]), __ldcg(&heights[c + 1]));
    if (cur == 0) return;
    cur = parent[cur];
  }
}

}  // namespace

void buildLbvh(const BrickGridView& g, LbvhWorkspace& ws, DeviceTree& out, cudaStream_t stream) {
  const int64_t total = g.size();
  if (total > int64_t(INT32_MAX)) throw BackendError("LBVH: more than 2^31 bricks");
  if (g.dims.x > (1 << 21) || g.dims.y > (1 << 21) || g.dims.z > (1 << 21))
    throw BackendError("LBVH: more than 2^21 bricks along an axis");
  const int n = int(g.occupied);
  out.clear();
  if (n == 0) return;

  // 1. Compaction: indices of occupied bricks.
  ws.brickIds.reserve(size_t(n));
  ws.brickIdsSorted.reserve(size_t(n));
  ws.numSelected.reserve(1);
  thrust::counting_iterator<int> first(0);
  size_t selBytes = 0;
  SS_CUDA_CHECK(cub::DeviceSelect::If(nullptr, selBytes, first, ws.brickIds.get(), ws.numSelected.get(), int(total),
                                      IsOccupied{g.d_occ}, stream));
  // 2. Morton codes, 3. radix sort over the bits the brick coordinates use.
  ws.codes.reserve(size_t(n));
  ws.codesSorted.reserve(size_t(n));
  const int bits = max(bitsFor(g.dims.x), max(bitsFor(g.dims.y), bitsFor(g.dims.z)));
  const int endBit = max(1, 3 * bits);
  size_t sortBytes = 0;
  SS_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, sortBytes, ws.codes.get(), ws.codesSorted.get(),
                                                ws.brickIds.get(), ws.brickIdsSorted.get(), n, 0, endBit, stream));
  void* temp = ws.temp.ensure(std::max(selBytes, sortBytes));
  SS_CUDA_CHECK(cub::DeviceSelect::If(temp, selBytes, first, ws.brickIds.get(), ws.numSelected.get(), int(total),
                                      IsOccupied{g.d_occ}, stream));
  mortonKernel<<<blocksFor(n, kThreads), kThreads, 0, stream>>>(ws.brickIds.get(), ws.numSelected.get(), g.dims,
                                                                ws.codes.get());
  SS_CUDA_CHECK_LAUNCH(mortonKernel);
  SS_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp, sortBytes, ws.codes.get(), ws.codesSorted.get(),
                                                ws.brickIds.get(), ws.brickIdsSorted.get(), n, 0, endBit, stream));

  // 4. Karras hierarchy, 5. bottom-up boxes straight into the output layout.
  const int kNodes = 2 * n - 1;
  ws.parent.reserve(size_t(kNodes));
  ws.outIndex.reserve(size_t(kNodes));
  ws.arrivals.reserve(size_t(max(n - 1, 1)));
  ws.heights.reserve(size_t(kNodes));
  out.nodes.reserve(size_t(kNodes));
  SS_CUDA_CHECK(cudaMemsetAsync(ws.arrivals.get(), 0, sizeof(int) * size_t(max(n - 1, 1)), stream));
  // The root's output slot 0: internal 0 when n > 1, else the lone leaf.
  SS_CUDA_CHECK(cudaMemsetAsync(ws.outIndex.get() + (n > 1 ? 0 : n - 1), 0, sizeof(int), stream));
  if (n > 1) {
    karrasKernel<<<blocksFor(n - 1, kThreads), kThreads, 0, stream>>>(ws.codesSorted.get(), n, ws.parent.get(),
                                                                      ws.outIndex.get());
    SS_CUDA_CHECK_LAUNCH(karrasKernel);
  }
  bottomUpKernel<<<blocksFor(n, kThreads), kThreads, 0, stream>>>(
      ws.brickIdsSorted.get(), n, g.dims, g.brick, g.cellDims, ws.parent.get(), ws.outIndex.get(),
      ws.arrivals.get(), ws.heights.get(), out.nodes.get());
  SS_CUDA_CHECK_LAUNCH(bottomUpKernel);
  int height = 0;
  SS_CUDA_CHECK(cudaMemcpyAsync(&height, ws.heights.get(), sizeof(int), cudaMemcpyDeviceToHost, stream));
  SS_CUDA_CHECK(cudaStreamSynchronize(stream));
  out.numNodes = kNodes;
  out.height = height;
  out.leaves = n;
}

void buildLbvh(BuildContext& ctx, const BuildParams&) {
  buildLbvh(ctx.grid, ctx.workspace<LbvhWorkspace>(), ctx.tree, ctx.stream);
}

}  // namespace spaceskip::cuda

// LBVH CPU twin: compaction, Morton codes, parallel sort, Karras 2012 hierarchy (karrasNode, shared
// with the CUDA twin), bottom-up boxes.
#include "spaceskip/LbvhBuilder.h"

#include "spaceskip/Morton.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <memory>
#include <stdexcept>
#include <string>

namespace spaceskip {

uint64_t mortonCode3(uint32_t x, uint32_t y, uint32_t z) { return mortonEncode3(x, y, z); }

namespace detail {

std::vector<KarrasNode> karrasHierarchy(const std::vector<uint64_t>& codes) {
  const int n = int(codes.size());
  std::vector<KarrasNode> nodes(size_t(std::max(n - 1, 0)));
  tbb::parallel_for(tbb::blocked_range<int>(0, n - 1, 1024), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i != r.end(); ++i) nodes[size_t(i)] = karrasNode(codes.data(), n, i);
  });
  return nodes;
}

}  // namespace detail

Tree buildLbvh(const OccupancyGrid& occ) {
  Tree t;
  const vec3i D = occ.dims;
  if (D.x > (1 << 21) || D.y > (1 << 21) || D.z > (1 << 21))
    throw std::length_error("LBVH: more than 2^21 bricks along an axis");
  // 1. Compaction: occupied bricks per z slice, offsets, then the Morton codes in parallel.
  std::vector<int64_t> offset(size_t(D.z) + 1, 0);
  tbb::parallel_for(0, D.z, [&](int z) {
    int64_t c = 0;
    const uint8_t* s = occ.occ.data() + occ.index(0, 0, z);
    for (int64_t i = 0; i < int64_t(D.x) * D.y; ++i) c += s[i] != 0;
    offset[size_t(z) + 1] = c;
  });
  for (int z = 0; z < D.z; ++z) offset[size_t(z) + 1] += offset[size_t(z)];
  const int64_t n = offset.back();
  if (n == 0) return t;
  if (n > (int64_t(1) << 30)) throw std::length_error("LBVH: too many occupied bricks");
  std::vector<uint64_t> codes(static_cast<size_t>(n));
  tbb::parallel_for(0, D.z, [&](int z) {
    int64_t o = offset[size_t(z)];
    for (int y = 0; y < D.y; ++y)
      for (int x = 0; x < D.x; ++x)
        if (occ.at(x, y, z)) codes[size_t(o++)] = mortonCode3(uint32_t(x), uint32_t(y), uint32_t(z));
  });
  // 2. Sort (codes are unique and encode the brick, so no payload is needed).
  tbb::parallel_sort(codes.begin(), codes.end());

  const int N = int(n);
  t.nodes.assign(size_t(2 * N - 1), Node{box3i{}, -1, 0});
  auto brickBox = [&](int leaf) {
    const uint64_t c = codes[size_t(leaf)];
    return occ.brickBox(int(compactBits3(c)), int(compactBits3(c >> 1)), int(compactBits3(c >> 2)));
  };
  if (N == 1) {
    t.nodes[0].box = brickBox(0);
    computeTreeStats(t);
    return t;
  }
  // 3. Hierarchy; output positions: internal i's children at 2i+1, 2i+2.
  const std::vector<detail::KarrasNode> k = detail::karrasHierarchy(codes);
  std::vector<int> internalOut(size_t(N - 1), 0), leafOut(size_t(N), 0);
  internalOut[0] = 0;
  tbb::parallel_for(0, N - 1, [&](int i) {
    const detail::KarrasNode& kn = k[size_t(i)];
    (kn.leftLeaf ? leafOut[size_t(kn.left)] : internalOut[size_t(kn.left)]) = 2 * i + 1;
    (kn.rightLeaf ? leafOut[size_t(kn.right)] : internalOut[size_t(kn.right)]) = 2 * i + 2;
  });
  tbb::parallel_for(0, N - 1, [&](int i) { t.nodes[size_t(internalOut[size_t(i)])].child = 2 * i + 1; });
  // 4. Bottom-up boxes: the second child to arrive at a parent computes its union and climbs.
  // Subtree heights ride along (a serial computeTreeStats walk was 15% of a 7M-leaf build).
  std::vector<int> height(size_t(2 * N - 1), 1);
  std::unique_ptr<std::atomic<int>[]> arrived(new std::atomic<int>[size_t(N - 1)]);
  for (int i = 0; i < N - 1; ++i) arrived[size_t(i)].store(0, std::memory_order_relaxed);
  tbb::parallel_for(tbb::blocked_range<int>(0, N, 256), [&](const tbb::blocked_range<int>& r) {
    for (int leaf = r.begin(); leaf != r.end(); ++leaf) {
      int o = leafOut[size_t(leaf)];
      t.nodes[size_t(o)].box = brickBox(leaf);
      while (o != 0) {
        const int p = (o - 1) / 2;  // Karras index of the parent
        if (arrived[size_t(p)].fetch_add(1, std::memory_order_acq_rel) == 0) break;
        const box3i& a = t.nodes[size_t(2 * p + 1)].box;
        const box3i& b = t.nodes[size_t(2 * p + 2)].box;
        o = internalOut[size_t(p)];
        height[size_t(o)] = 1 + std::max(height[size_t(2 * p + 1)], height[size_t(2 * p + 2)]);
        t.nodes[size_t(o)].box = unite(a, b);
      }
    }
  });
  t.height = height[0];
  t.leaves = N;
  if (t.height >= kMaxTreeHeight)
    throw std::runtime_error("LBVH height " + std::to_string(t.height) + " reaches kMaxTreeHeight");
  return t;
}

}  // namespace spaceskip

// KdTreeCPU: Vidal-style plane sweep over a summed volume table, oneTBB task parallel.
#include "spaceskip/KdTreeBuilder.h"

#include "spaceskip/SummedVolumeTable.h"

#include <tbb/concurrent_vector.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace spaceskip {

namespace detail {

/// A node while building: box in brick coordinates, children by index into the pool.
struct KdBuildNode {
  box3i bricks;
  int left = -1, right = -1;
};

class KdTreeBuild {
 public:
  KdTreeBuild(const OccupancyGrid& occ, const BuildParams& p, bool parallel)
      : occ_(occ), p_(p), parallel_(parallel), svt_(occ) {
    planeStep_ = std::max(1, (8 + occ.brick - 1) / occ.brick);
  }

  Tree run() {
    Tree t;
    box3i all{vec3i{0, 0, 0}, occ_.dims};
    box3i root = svt_.shrink(all);
    if (root.empty()) return t;
    rootVolume_ = cellBox(root).volume();
    pool_.push_back(KdBuildNode{root, -1, -1});
    if (parallel_) {
      tbb::task_group g;
      split(g, 0, 1);
      g.wait();
    } else {
      split(0, 1);
    }
    if (tooDeep_) throw std::runtime_error("k-d tree reaches kMaxTreeHeight (" + std::to_string(kMaxTreeHeight) + ")");
    flatten(t);
    return t;
  }

 private:
  box3i cellBox(const box3i& b) const {
    const int B = occ_.brick;
    return box3i{vec3i{b.lo.x * B, b.lo.y * B, b.lo.z * B},
                 vec3i{std::min(b.hi.x * B, occ_.cellDims.x), std::min(b.hi.y * B, occ_.cellDims.y),
                       std::min(b.hi.z * B, occ_.cellDims.z)}};
  }

  /// Decides the split of a node: false for a leaf, else the two tight child boxes.
  bool chooseSplit(const box3i& node, box3i& lbox, box3i& rbox) const {
    const box3i cb = cellBox(node);
    const int64_t vol = cb.volume();
    vec3i len{cb.hi.x - cb.lo.x, cb.hi.y - cb.lo.y, cb.hi.z - cb.lo.z};
    int axis = 0;  // longest axis, the first one on ties
    if (len.y > len[axis]) axis = 1;
    if (len.z > len[axis]) axis = 2;
    const bool halt = p_.leaf == LeafCriterion::Shallow ? vol < rootVolume_ / 10 : vol <= 8 * 8 * 8;
    if (!halt) {
      // Plane sweep: candidates first + step*k, 0 < k < nb/step (Vidal's raster of 8 voxels).
      const int first = node.lo[axis], nb = node.hi[axis] - node.lo[axis];
      const int planes = nb / planeStep_;
      int64_t best = std::numeric_limits<int64_t>::max();
      for (int k = 1; k < planes; ++k) {
        box3i l = node, r = node;
        l.hi[axis] = r.lo[axis] = first + planeStep_ * k;
        l = svt_.shrink(l);
        r = svt_.shrink(r);
        const int64_t c = cellBox(l).volume() + cellBox(r).volume();
        if (vol - c <= vol / 1000) continue;  // removes (almost) no empty space
        if (c < best) {
          best = c;
          lbox = l;
          rbox = r;
        }
      }
      if (best != std::numeric_limits<int64_t>::max()) return true;
    }
    // Max leaf size: a would-be leaf with an edge above MLS is split in the middle of its
    // longest axis. The node box is tight, so both halves hold occupied bricks.
    if (p_.maxLeafSize > 0 && len[axis] > p_.maxLeafSize) {
      const int nb = node.hi[axis] - node.lo[axis];
      if (nb >= 2) {
        box3i l = node, r = node;
        l.hi[axis] = r.lo[axis] = node.lo[axis] + nb / 2;
        lbox = svt_.shrink(l);
        rbox = svt_.shrink(r);
        return true;
      }
    }
    return false;
  }

  // Serial recursion (the reference, and the tail of every parallel task).
  void split(int index, int depth) {
    int li, ri;
    if (!splitNode(index, depth, li, ri)) return;
    split(li, depth + 1);
    split(ri, depth + 1);
  }

  // Splits node `index` if the cost function (or MLS) asks for it: appends both children and
  // links them; false for a leaf (or when the height bound would be exceeded).
  bool splitNode(int index, int depth, int& li, int& ri) {
    box3i l, r;
    if (!chooseSplit(pool_[size_t(index)].bricks, l, r)) return false;
    if (depth + 1 >= kMaxTreeHeight) {
      tooDeep_ = true;
      return false;
    }
    li = append(l);
    ri = append(r);
    pool_[size_t(index)].left = li;
    pool_[size_t(index)].right = ri;
    return true;
  }

  // Task-parallel recursion above the cutoff.
  void split(tbb::task_group& g, int index, int depth) {
    const box3i node = pool_[size_t(index)].bricks;
    if (node.volume() < kKdTreeSerialCutoffBricks) {
      split(index, depth);
      return;
    }
    int li, ri;
    if (!splitNode(index, depth, li, ri)) return;
    g.run([this, &g, li, depth] { split(g, li, depth + 1); });
    split(g, ri, depth + 1);
  }

  int append(const box3i& b) {
    auto it = pool_.push_back(KdBuildNode{b, -1, -1});
    return int(it - pool_.begin());
  }

  // Emits the flat layout: root at 0, each inner node's children pair appended when the node
  // is reached depth-first, left subtree first. Independent of the order tasks ran in.
  void flatten(Tree& t) const {
    t.nodes.clear();
    t.nodes.reserve(pool_.size());
    t.nodes.push_back(Node{cellBox(pool_[0].bricks), -1, 0});
    std::vector<std::pair<int, int>> stack{{0, 0}};  // (pool index, output index)
    while (!stack.empty()) {
      auto [pi, oi] = stack.back();
      stack.pop_back();
      const KdBuildNode& n = pool_[size_t(pi)];
      if (n.left < 0) continue;
      const int c = int(t.nodes.size());
      t.nodes[size_t(oi)].child = c;
      t.nodes.push_back(Node{cellBox(pool_[size_t(n.left)].bricks), -1, 0});
      t.nodes.push_back(Node{cellBox(pool_[size_t(n.right)].bricks), -1, 0});
      stack.push_back({n.right, c + 1});
      stack.push_back({n.left, c});
    }
    computeTreeStats(t);
  }

  const OccupancyGrid& occ_;
  BuildParams p_;
  bool parallel_;
  SummedVolumeTable svt_;
  int planeStep_ = 1;
  int64_t rootVolume_ = 0;
  tbb::concurrent_vector<KdBuildNode> pool_;
  std::atomic<bool> tooDeep_{false};  // set by any task; read after all joined
};

}  // namespace detail

Tree buildKdTree(const OccupancyGrid& occ, const BuildParams& p) { return detail::KdTreeBuild(occ, p, true).run(); }

Tree buildKdTreeSerial(const OccupancyGrid& occ, const BuildParams& p) {
  return detail::KdTreeBuild(occ, p, false).run();
}

}  // namespace spaceskip

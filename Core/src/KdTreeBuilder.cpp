// KdTreeCPU: a oneTBB task_group recursion over the shared split rule (KdTreeSplit.h, the sweep),
// tight boxes from the summed volume table's shared queries (SvtView).
#include "spaceskip/KdTreeBuilder.h"

#include "spaceskip/KdTreeSplit.h"
#include "spaceskip/SummedVolumeTable.h"

#include <tbb/concurrent_vector.h>
#include <tbb/task_group.h>

#include <atomic>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace spaceskip {

namespace {

/// A node while building: tight cell box, children by index into the pool.
struct KdBuildNode {
  box3i box;
  int left = -1, right = -1;
};

class KdTreeBuild {
 public:
  KdTreeBuild(const OccupancyGrid& occ, const BuildParams& p, bool parallel)
      : occ_(occ), parallel_(parallel), svt_(occ) {
    // KdTreeCPU always sweeps (bins 0) and ignores p.bins.
    sp_.deep = p.leaf != LeafCriterion::Shallow ? 1 : 0;
    sp_.empty = p.leaf == LeafCriterion::Empty ? 1 : 0;
    sp_.mls = p.maxLeafSize;
    sp_.bins = 0;
    sp_.brick = occ.brick;
    sp_.rootVol = 0;
  }

  Tree run() {
    Tree t;
    const box3i root = svt_.view()(box3i{vec3i{0, 0, 0}, occ_.cellDims});
    if (root.empty()) return t;
    sp_.rootVol = root.volume();
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
  // Serial recursion (the reference, and the tail of every parallel task).
  void split(int index, int depth) {
    int li, ri;
    if (!splitNode(index, depth, li, ri)) return;
    split(li, depth + 1);
    split(ri, depth + 1);
  }

  // Task-parallel recursion above the serial cutoff.
  void split(tbb::task_group& g, int index, int depth) {
    if (cellBrickBox(pool_[size_t(index)].box, occ_.brick).volume() < kKdTreeSerialCutoffBricks) {
      split(index, depth);
      return;
    }
    int li, ri;
    if (!splitNode(index, depth, li, ri)) return;
    g.run([this, &g, li, depth] { split(g, li, depth + 1); });
    split(g, ri, depth + 1);
  }

  // Splits node `index` when the shared rule asks for it: appends both children and links them;
  // false for a leaf (or when the height bound would be exceeded).
  bool splitNode(int index, int depth, int& li, int& ri) {
    const detail::KdDecision d = detail::decideKdSplit(pool_[size_t(index)].box, sp_, svt_.view());
    if (!d.split) return false;
    if (depth + 1 >= kMaxTreeHeight) {
      tooDeep_ = true;
      return false;
    }
    li = append(d.left);
    ri = append(d.right);
    pool_[size_t(index)].left = li;
    pool_[size_t(index)].right = ri;
    return true;
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
    t.nodes.push_back(Node{pool_[0].box, -1, 0});
    std::vector<std::pair<int, int>> stack{{0, 0}};  // (pool index, output index)
    while (!stack.empty()) {
      auto [pi, oi] = stack.back();
      stack.pop_back();
      const KdBuildNode& n = pool_[size_t(pi)];
      if (n.left < 0) continue;
      const int c = int(t.nodes.size());
      t.nodes[size_t(oi)].child = c;
      t.nodes.push_back(Node{pool_[size_t(n.left)].box, -1, 0});
      t.nodes.push_back(Node{pool_[size_t(n.right)].box, -1, 0});
      stack.push_back({n.right, c + 1});
      stack.push_back({n.left, c});
    }
    computeTreeStats(t);
  }

  const OccupancyGrid& occ_;
  bool parallel_;
  SummedVolumeTable svt_;
  detail::KdSplitParams sp_{};
  tbb::concurrent_vector<KdBuildNode> pool_;
  std::atomic<bool> tooDeep_{false};  // set by any task; read after all joined
};

}  // namespace

Tree buildKdTree(const OccupancyGrid& occ, const BuildParams& p) { return KdTreeBuild(occ, p, true).run(); }

Tree buildKdTreeSerial(const OccupancyGrid& occ, const BuildParams& p) { return KdTreeBuild(occ, p, false).run(); }

}  // namespace spaceskip

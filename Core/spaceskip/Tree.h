// The flat binary hierarchy every builder emits, and its traversal bound.
#pragma once
#include "Math.h"

#include <cstdint>
#include <string>
#include <vector>

namespace spaceskip {

/// Node 0 is the root. An inner node has children `child` and `child+1`; a leaf has child < 0.
/// Boxes are integer, in cell coordinates, half-open, and tight around occupied cells; leaves
/// are pairwise disjoint and cover every occupied cell. Children of an inner node are separated
/// by an axis-aligned plane (k-d split or Morton split), so ordering children by their entry
/// distance is front-to-back.
struct Node {
  box3i box;
  int32_t child;
  int32_t pad;
};
static_assert(sizeof(Node) == 32, "Node layout is shared with the GPU");

/// Deepest tree the traversal stack supports (the paper reports heights up to 72).
constexpr int kMaxTreeHeight = 120;

struct Tree {
  std::vector<Node> nodes;  ///< empty when nothing is occupied
  int height = 0;           ///< number of levels (a lone root has height 1, as in the paper)
  int64_t leaves = 0;
};

/// Recomputes height and leaf count from the node array.
void computeTreeStats(Tree& t);

}  // namespace spaceskip

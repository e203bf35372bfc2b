// Tree statistics shared by every builder.
#include "spaceskip/Tree.h"

#include <utility>
#include <vector>

namespace spaceskip {

void computeTreeStats(Tree& t) {
  t.height = 0;
  t.leaves = 0;
  if (t.nodes.empty()) return;
  std::vector<std::pair<int, int>> stack{{0, 1}};
  while (!stack.empty()) {
    auto [n, depth] = stack.back();
    stack.pop_back();
    if (depth > t.height) t.height = depth;
    const Node& node = t.nodes[size_t(n)];
    if (node.child < 0) {
      ++t.leaves;
    } else {
      stack.push_back({node.child, depth + 1});
      stack.push_back({node.child + 1, depth + 1});
    }
  }
}

}  // namespace spaceskip

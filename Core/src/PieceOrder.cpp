#include "spaceskip/PieceOrder.h"

#include <algorithm>
#include <cmath>
#include <functional>

namespace spaceskip {

std::vector<size_t> visibilityOrder(const std::vector<PieceBox>& boxes, const double eye[3],
                                    const double dir[3], bool parallel) {
  std::vector<size_t> out;
  out.reserve(boxes.size());
  std::function<void(std::vector<size_t>&)> split = [&](std::vector<size_t>& set) {
    if (set.size() <= 1) {
      out.insert(out.end(), set.begin(), set.end());
      return;
    }
    // A plane through a face of one of the boxes with every box on one side of it.
    for (int a = 0; a < 3; ++a) {
      for (size_t c : set) {
        for (int side = 0; side < 2; ++side) {
          const double plane = boxes[c][2 * a + side];
          std::vector<size_t> lo, hi;
          bool separates = true;
          for (size_t k : set) {
            if (boxes[k][2 * a + 1] <= plane) {
              lo.push_back(k);
            } else if (boxes[k][2 * a] >= plane) {
              hi.push_back(k);
            } else {
              separates = false;
              break;
            }
          }
          if (!separates || lo.empty() || hi.empty()) continue;
          const bool lowFirst = parallel ? dir[a] > 0 : eye[a] < plane;
          split(lowFirst ? lo : hi);
          split(lowFirst ? hi : lo);
          return;
        }
      }
    }
    std::vector<double> dist(boxes.size(), 0.0);
    for (size_t k : set) {
      double v[3];
      for (int a = 0; a < 3; ++a) v[a] = 0.5 * (boxes[k][2 * a] + boxes[k][2 * a + 1]) - eye[a];
      dist[k] = parallel ? v[0] * dir[0] + v[1] * dir[1] + v[2] * dir[2]
                         : std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    }
    std::stable_sort(set.begin(), set.end(), [&dist](size_t x, size_t y) { return dist[x] < dist[y]; });
    out.insert(out.end(), set.begin(), set.end());
  };
  std::vector<size_t> all(boxes.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  split(all);
  return out;
}

}  // namespace spaceskip

// spaceskip::visibilityOrder: the order in which rays meet the pieces, checked ray by ray.
#include "spaceskip/PieceOrder.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

namespace {

using spaceskip::PieceBox;

// Splits `box` recursively at random axis planes into about `n` boxes (a k-d partition, as
// ParaView's extent translator makes for the ranks' pieces).
void kdSplit(const PieceBox& box, int n, std::mt19937& rng, std::vector<PieceBox>& out) {
  if (n <= 1) {
    out.push_back(box);
    return;
  }
  const int a = std::uniform_int_distribution<int>(0, 2)(rng);
  const double lo = box[2 * a], hi = box[2 * a + 1];
  if (hi - lo < 2) {
    out.push_back(box);
    return;
  }
  const double plane = std::floor(std::uniform_real_distribution<double>(lo + 1, hi - 1)(rng));
  PieceBox l = box, h = box;
  l[2 * a + 1] = plane;
  h[2 * a] = plane;
  const int nl = std::max(1, n / 2);
  kdSplit(l, nl, rng, out);
  kdSplit(h, n - nl, rng, out);
}

// Where a ray enters `b`, or infinity when it misses it (or only grazes it).
double entry(const PieceBox& b, const double o[3], const double d[3]) {
  double t0 = -std::numeric_limits<double>::infinity(), t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0) {
      if (o[a] <= b[2 * a] || o[a] >= b[2 * a + 1]) return std::numeric_limits<double>::infinity();
      continue;
    }
    double u = (b[2 * a] - o[a]) / d[a], v = (b[2 * a + 1] - o[a]) / d[a];
    if (u > v) std::swap(u, v);
    t0 = std::max(t0, u);
    t1 = std::min(t1, v);
  }
  return t1 - t0 > 1e-9 && t1 > 0 ? std::max(t0, 0.0) : std::numeric_limits<double>::infinity();
}

// Every ray meets the boxes in the order given: checked for `rays` random rays.
int misorderedRays(const std::vector<PieceBox>& boxes, const std::vector<size_t>& order,
                   const double eye[3], const double dir[3], bool parallel, std::mt19937& rng,
                   int rays) {
  std::vector<size_t> rank(boxes.size());
  for (size_t i = 0; i < order.size(); ++i) rank[order[i]] = i;
  std::uniform_real_distribution<double> u(-10, 110);
  int bad = 0;
  for (int r = 0; r < rays; ++r) {
    const double target[3] = {u(rng), u(rng), u(rng)};
    double o[3], d[3];
    for (int a = 0; a < 3; ++a) {
      // parallel: rays along dir through points of a plane far behind the eye
      o[a] = parallel ? target[a] - 500 * dir[a] : eye[a];
      d[a] = parallel ? dir[a] : target[a] - eye[a];
    }
    std::vector<std::pair<double, size_t>> hits;
    for (size_t k = 0; k < boxes.size(); ++k) {
      const double t = entry(boxes[k], o, d);
      if (t < std::numeric_limits<double>::infinity()) hits.push_back({t, k});
    }
    std::sort(hits.begin(), hits.end());
    for (size_t i = 1; i < hits.size(); ++i) {
      if (hits[i].first > hits[i - 1].first + 1e-9 && rank[hits[i].second] < rank[hits[i - 1].second]) {
        ++bad;
        break;
      }
    }
  }
  return bad;
}

}  // namespace

TEST(PieceOrder, RaysMeetKdPiecesInTheGivenOrder) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(-150, 250), dirs(-1, 1);
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<PieceBox> boxes;
    kdSplit({0, 100, 0, 100, 0, 100}, 2 + trial % 7, rng, boxes);
    const bool parallel = trial % 2 == 1;
    const double eye[3] = {pos(rng), pos(rng), pos(rng)};
    const double dir[3] = {dirs(rng), dirs(rng), dirs(rng)};
    const std::vector<size_t> order = spaceskip::visibilityOrder(boxes, eye, dir, parallel);
    ASSERT_EQ(order.size(), boxes.size());
    std::vector<size_t> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    for (size_t i = 0; i < sorted.size(); ++i) ASSERT_EQ(sorted[i], i);
    EXPECT_EQ(misorderedRays(boxes, order, eye, dir, parallel, rng, 2000), 0)
        << "trial " << trial << ", " << boxes.size() << " boxes, parallel " << parallel;
  }
}

TEST(PieceOrder, TheReverseOrderFailsTheRayCheck) {
  // The check above can fail: two pieces split in x, the eye on the high side.
  std::mt19937 rng(3);
  const std::vector<PieceBox> boxes = {{0, 50, 0, 100, 0, 100}, {50, 100, 0, 100, 0, 100}};
  const double eye[3] = {200, 50, 50}, dir[3] = {-1, 0, 0};
  const std::vector<size_t> order = spaceskip::visibilityOrder(boxes, eye, dir, false);
  ASSERT_EQ(order, (std::vector<size_t>{1, 0}));
  EXPECT_GT(misorderedRays(boxes, {0, 1}, eye, dir, false, rng, 500), 0);
  EXPECT_EQ(spaceskip::visibilityOrder(boxes, eye, dir, true), (std::vector<size_t>{1, 0}));
}

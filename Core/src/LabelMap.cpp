// Label maps: per-brick label sets (one voxel pass per volume) and their classification.
#include "spaceskip/LabelMap.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace spaceskip {

bool LabelTable::operator==(const LabelTable& o) const {
  if (unitDistance != o.unitDistance || labels.size() != o.labels.size()) return false;
  for (size_t i = 0; i < labels.size(); ++i) {
    const Label &a = labels[i], &b = o.labels[i];
    if (a.id != b.id || a.r != b.r || a.g != b.g || a.b != b.b || a.opacity != b.opacity || a.visible != b.visible)
      return false;
  }
  return true;
}

namespace {

/// A label's channel in [0, 1] (NaN: 0).
float unit(float x) { return x == x ? std::clamp(x, 0.f, 1.f) : 0.f; }

/// Brick-row sets: the labels of every brick of row (by, bz), appended in brick order.
template <class T>
void rowSets(const T* data, vec3l n, const LabelSets& s, int by, int bz, int lo, std::vector<uint32_t>& counts,
             std::vector<uint16_t>& out) {
  int64_t y0, y1, z0, z1;
  brickVoxelSpan(by, s.brick, n.y, y0, y1);
  brickVoxelSpan(bz, s.brick, n.z, z0, z1);
  std::vector<uint16_t> found;
  for (int bx = 0; bx < s.dims.x; ++bx) {
    int64_t x0, x1;
    brickVoxelSpan(bx, s.brick, n.x, x0, x1);
    found.clear();
    int last = std::numeric_limits<int>::min();
    for (int64_t z = z0; z <= z1; ++z)
      for (int64_t y = y0; y <= y1; ++y) {
        const T* line = data + n.x * (y + n.y * z);
        for (int64_t x = x0; x <= x1; ++x) {
          const int v = int(line[x]);
          if (v == last) continue;  // runs of one label: the common case
          last = v;
          const uint16_t k = uint16_t(v - lo);
          if (std::find(found.begin(), found.end(), k) == found.end()) found.push_back(k);
        }
      }
    std::sort(found.begin(), found.end());
    counts.push_back(uint32_t(found.size()));
    out.insert(out.end(), found.begin(), found.end());
  }
}

}  // namespace

LabelSets computeLabelSets(const Volume& v, int brick) {
  validate(v);
  if (v.components != 1 || !isLabelType(v.type))
    throw std::invalid_argument("label sets need one component of 8- or 16-bit integers");
  LabelSets s;
  s.brick = std::max(1, brick);
  s.cellDims = v.cellDims();
  s.dims = vec3i{(s.cellDims.x + s.brick - 1) / s.brick, (s.cellDims.y + s.brick - 1) / s.brick,
                 (s.cellDims.z + s.brick - 1) / s.brick};
  double lo = 0, hi = -1;
  if (!v.scalarRange(lo, hi)) lo = 0, hi = 0;
  s.lo = int(lo);
  s.hi = int(hi);
  const int64_t rows = int64_t(s.dims.y) * s.dims.z;
  std::vector<std::vector<uint32_t>> counts(static_cast<size_t>(rows));
  std::vector<std::vector<uint16_t>> sets(static_cast<size_t>(rows));
  dispatchVoxelType(v.type, [&](auto t) {
    using T = decltype(t);
    if constexpr (std::is_integral_v<T>) {
      const T* data = static_cast<const T*>(v.data);
      tbb::parallel_for(tbb::blocked_range<int64_t>(0, rows), [&](const tbb::blocked_range<int64_t>& r) {
        for (int64_t row = r.begin(); row != r.end(); ++row)
          rowSets(data, v.dims, s, int(row % s.dims.y), int(row / s.dims.y), s.lo, counts[size_t(row)],
                  sets[size_t(row)]);
      });
    }
  });
  s.offset.resize(size_t(s.size()) + 1);
  int64_t at = 0, i = 0;
  for (const auto& c : counts)
    for (uint32_t n : c) {
      s.offset[size_t(i++)] = at;
      at += n;
    }
  s.offset[size_t(i)] = at;
  s.labels.reserve(size_t(at));
  for (const auto& l : sets) s.labels.insert(s.labels.end(), l.begin(), l.end());
  return s;
}

OccupancyGrid classifyLabels(const LabelSets& s, const std::vector<uint8_t>& drawn, const CropClip& cc) {
  OccupancyGrid o;
  o.brick = s.brick;
  o.cellDims = s.cellDims;
  o.dims = s.dims;
  o.occ.assign(size_t(s.size()), 0);
  if (drawn.size() < size_t(s.valueCount())) throw std::invalid_argument("classifyLabels: a flag per value is needed");
  o.occupied = tbb::parallel_reduce(
      tbb::blocked_range<int64_t>(0, s.size(), 4096), int64_t(0),
      [&](const tbb::blocked_range<int64_t>& r, int64_t acc) {
        for (int64_t i = r.begin(); i != r.end(); ++i) {
          const uint8_t occ =
              brickLabelsOccupied(i, s.offset.data(), s.labels.data(), drawn.data(), s.dims, s.brick, s.cellDims, cc);
          o.occ[size_t(i)] = occ;
          acc += occ;
        }
        return acc;
      },
      [](int64_t a, int64_t b) { return a + b; });
  return o;
}

std::vector<uint8_t> drawnLabels(const LabelTable& t, int lo, int hi) {
  std::vector<uint8_t> d(size_t(hi >= lo ? hi - lo + 1 : 0), 0);
  for (const Label& l : t.labels)
    if (l.id >= lo && l.id <= hi) d[size_t(l.id - lo)] = l.visible && unit(l.opacity) > 0.f ? 1 : 0;
  return d;
}

TransferFunction labelTransferFunction(const LabelTable& t, int lo, int hi) {
  TransferFunction tf;
  if (hi < lo) hi = lo;
  tf.rangeMin = lo;
  tf.rangeMax = hi;
  tf.unitDistance = t.unitDistance > 0 ? t.unitDistance : 1.0;
  tf.table.assign(size_t(hi - lo + 1), vec4f{0, 0, 0, 0});
  for (const Label& l : t.labels) {
    if (l.id < lo || l.id > hi) continue;
    vec4f& e = tf.table[size_t(l.id - lo)];
    e = l.visible ? vec4f{unit(l.r), unit(l.g), unit(l.b), unit(l.opacity)} : vec4f{0, 0, 0, 0};
  }
  return tf;
}

}  // namespace spaceskip

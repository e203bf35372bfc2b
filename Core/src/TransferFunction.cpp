// Transfer-function tables, presets and the sparse-table range-max query.
#include "spaceskip/TransferFunction.h"
#include "spaceskip/GradientBound.h"  // pairMaxEntries

#include <algorithm>
#include <cmath>
#include <limits>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace spaceskip {

TransferFunction TransferFunction::fromPoints(std::vector<TFPoint> pts, double lo, double hi, int size) {
  if (size < 1) throw std::invalid_argument("transfer function needs at least one entry");
  if (pts.empty()) throw std::invalid_argument("transfer function needs at least one point");
  if (!(hi > lo)) hi = lo + 1.0;  // constant data: give the table a non-empty range
  std::sort(pts.begin(), pts.end(), [](const TFPoint& a, const TFPoint& b) { return a.value < b.value; });
  TransferFunction tf;
  tf.rangeMin = lo;
  tf.rangeMax = hi;
  tf.table.resize(size_t(size));
  for (int i = 0; i < size; ++i) {
    // lo*(1-t) + hi*t and halved differences: no overflow for ranges as wide as +-1e308.
    const double t = size == 1 ? 0.0 : double(i) / double(size - 1);
    double v = lo * (1.0 - t) + hi * t;
    auto it = std::lower_bound(pts.begin(), pts.end(), v, [](const TFPoint& p, double x) { return p.value < x; });
    TFPoint p;
    if (it == pts.begin()) p = pts.front();
    else if (it == pts.end()) p = pts.back();
    else {
      const TFPoint& a = *(it - 1);
      const TFPoint& b = *it;
      // Halved differences cannot overflow; between denormals they can round to 0 (0.5 * 4.9e-324
      // is 0: 0/0 gave NaN table entries, found by fuzz_render), where the plain differences are exact.
      double num = 0.5 * v - 0.5 * a.value, den = 0.5 * b.value - 0.5 * a.value;
      if (!(den > 0)) num = v - a.value, den = b.value - a.value;
      const double f = den > 0 ? std::clamp(num / den, 0.0, 1.0) : 0.0;
      auto mix = [f](float x, float y) { return float(x + (y - x) * f); };
      p = TFPoint{v, mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b), mix(a.a, b.a)};
    }
    tf.table[size_t(i)] = vec4f{p.r, p.g, p.b, std::clamp(p.a, 0.f, 1.f)};
  }
  return tf;
}

TransferFunction TransferFunction::preset(const std::string& name, double lo, double hi, int size) {
  auto at = [&](double f) { return lo * (1.0 - f) + hi * f; };
  std::vector<TFPoint> p;
  if (name == "ramp") {
    p = {{at(0.0), 0.2f, 0.3f, 0.9f, 0.f}, {at(0.1), 0.2f, 0.3f, 0.9f, 0.f},
         {at(0.5), 0.9f, 0.8f, 0.3f, 0.3f}, {at(1.0), 1.f, 0.2f, 0.1f, 0.9f}};
  } else if (name == "grayscale") {
    p = {{at(0.0), 0.f, 0.f, 0.f, 0.f}, {at(1.0), 1.f, 1.f, 1.f, 1.f}};
  } else if (name == "coolwarm") {
    p = {{at(0.0), 0.23f, 0.30f, 0.75f, 0.f}, {at(0.05), 0.23f, 0.30f, 0.75f, 0.f},
         {at(0.5), 0.87f, 0.87f, 0.87f, 0.2f}, {at(1.0), 0.71f, 0.02f, 0.15f, 0.8f}};
  } else if (name == "band") {
    p = {{at(0.0), 1.f, 1.f, 1.f, 0.f}, {at(0.3), 0.3f, 0.8f, 0.3f, 0.f}, {at(0.4), 0.3f, 0.8f, 0.3f, 0.6f},
         {at(0.6), 0.9f, 0.6f, 0.2f, 0.6f}, {at(0.7), 0.9f, 0.6f, 0.2f, 0.f}, {at(1.0), 1.f, 1.f, 1.f, 0.f}};
  } else if (name == "spike") {
    // One table entry in the middle of the range is opaque, every other entry transparent.
    TransferFunction tf = fromPoints({{lo, 0.f, 0.f, 0.f, 0.f}, {hi, 0.f, 0.f, 0.f, 0.f}}, lo, hi, size);
    tf.table[size_t(size / 2)] = vec4f{1.f, 0.9f, 0.2f, 1.f};
    return tf;
  } else if (name == "opaque") {
    p = {{at(0.0), 1.f, 1.f, 1.f, 1.f}, {at(1.0), 1.f, 1.f, 1.f, 1.f}};
  } else if (name == "zero") {
    p = {{at(0.0), 1.f, 1.f, 1.f, 0.f}, {at(1.0), 1.f, 1.f, 1.f, 0.f}};
  } else {
    throw std::invalid_argument("unknown transfer-function preset '" + name +
                                "' (ramp, grayscale, coolwarm, band, spike, opaque, zero)");
  }
  return fromPoints(p, lo, hi, size);
}

bool TransferFunction::sameOpacity(const TransferFunction& o) const {
  if (table.size() != o.table.size() || alphaMin() != o.alphaMin() || alphaMax() != o.alphaMax() ||
      unitDistance != o.unitDistance)
    return false;
  for (size_t i = 0; i < table.size(); ++i)
    if (table[i].w != o.table[i].w) return false;
  return true;
}

bool TransferFunction::sameColor(const TransferFunction& o) const {
  if (table.size() != o.table.size() || rangeMin != o.rangeMin || rangeMax != o.rangeMax) return false;
  for (size_t i = 0; i < table.size(); ++i)
    if (table[i].x != o.table[i].x || table[i].y != o.table[i].y || table[i].z != o.table[i].z) return false;
  return true;
}

bool TransferFunction::sameGradientTables(const TransferFunction& o) const {
  if (width2D != o.width2D || height2D != o.height2D || table2D.size() != o.table2D.size() ||
      gradientOpacity != o.gradientOpacity)
    return false;
  for (size_t i = 0; i < table2D.size(); ++i) {
    const vec4f &a = table2D[i], &b = o.table2D[i];
    if (a.x != b.x || a.y != b.y || a.z != b.z || a.w != b.w) return false;
  }
  return true;
}

TransferFunction classificationTF(const TransferFunction& tf, int components) {
  if (tf.uses2D() && components == 2) {
    const int W = tf.width2D, H = tf.height2D;
    std::vector<float> row(size_t(H), 0.f);  // each row's largest opacity over all columns
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const float a = tf.table2D[size_t(y) * size_t(W) + size_t(x)].w;
        if (a > row[size_t(y)]) row[size_t(y)] = a;
      }
    TransferFunction c;
    c.rangeMin = tf.rangeMin;
    c.rangeMax = tf.rangeMax;
    c.ownOpacityRange = true;  // the entries span the y values' range (OpacityRangeMax reads alphaMin/Max)
    c.opacityRangeMin = tf.alphaMin();
    c.opacityRangeMax = tf.alphaMax();
    c.unitDistance = tf.unitDistance;
    pairMaxEntries(row, c.table);
    return c;
  }
  if (tf.uses2D()) {
    const int W = tf.width2D, H = tf.height2D;
    std::vector<float> col(size_t(W), 0.f);  // each column's largest opacity over all rows
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const float a = tf.table2D[size_t(y) * size_t(W) + size_t(x)].w;
        if (a > col[size_t(x)]) col[size_t(x)] = a;  // NaN entries never raise it (and draw nothing)
      }
    TransferFunction c;
    c.rangeMin = tf.rangeMin;
    c.rangeMax = tf.rangeMax;
    c.unitDistance = tf.unitDistance;
    // The 2-D table stays with it: the backends' classification bounds each brick's gradient
    // and reads only the rows it can reach (GradientBound.h); this 1-D table is its first rule.
    c.table2D = tf.table2D;
    c.width2D = W;
    c.height2D = H;
    // Position x in [j, j+1] of this table is column position x - 1/2: columns j-1, j, j+1,
    // which entries j and j+1 (the query takes both) cover.
    pairMaxEntries(col, c.table);
    return c;
  }
  if (tf.usesGradientOpacity()) {
    bool any = false;
    for (float g : tf.gradientOpacity) any = any || g > 0.f;
    TransferFunction c = tf;
    c.gradientOpacity.clear();
    if (!any)
      for (auto& e : c.table) e.w = 0.f;
    return c;
  }
  return tf;
}

void gradientColumnMapping(const TransferFunction& tf, float& lo, float& scale) {
  tableMapping(tf, tf.width2D + 1, lo, scale);
}

void secondAxisRowMapping(const TransferFunction& tf, float& lo, float& scale) {
  TransferFunction y;
  y.rangeMin = tf.alphaMin();
  y.rangeMax = tf.alphaMax();
  tableMapping(y, tf.height2D + 1, lo, scale);
}

void appendGradientTables(const TransferFunction& tf, std::vector<vec4f>& table, int& offset2D, int& offsetGO) {
  offset2D = offsetGO = -1;
  if (tf.uses2D()) {
    offset2D = int(table.size());
    table.insert(table.end(), tf.table2D.begin(), tf.table2D.end());
  } else if (tf.usesGradientOpacity()) {
    offsetGO = int(table.size());
    for (float g : tf.gradientOpacity) table.push_back(vec4f{0, 0, 0, std::clamp(g, 0.f, 1.f)});
  }
}

std::vector<vec4f> correctedTable(const TransferFunction& tf, float dt) {
  std::vector<vec4f> out(tf.table);
  for (auto& e : out) e.w = correctOpacity(e.w, dt, float(tf.unitDistance));
  return out;
}

std::vector<vec4f> tableForBlend(const TransferFunction& tf, float dt, BlendMode mode) {
  if (mode == BlendMode::Composite) return correctedTable(tf, dt);
  std::vector<vec4f> out(tf.table);
  if (mode == BlendMode::Additive) {
    const float factor = dt / float(tf.unitDistance);
    for (auto& e : out) e.w *= factor;
  }
  return out;
}

OpacityRangeMax::OpacityRangeMax(const TransferFunction& tf) {
  if (tf.table.empty()) throw std::invalid_argument("empty transfer-function table");
  const int size = int(tf.table.size());
  view_.size = size;
  // Over the alpha entries' own range (dependent components: the opacity channel's), mapped as
  // the samplers map it (Engine's fillComponents and setTransferTable use tableMapping too).
  TransferFunction alpha;
  alpha.rangeMin = tf.alphaMin();
  alpha.rangeMax = tf.alphaMax();
  tableMapping(alpha, size, view_.lo, view_.scale);
  // Level k (entries i..i+2^k-1) at offset[k]: the max of two entries of level k-1.
  size_t total = 0;
  int levels = 0;
  for (int64_t len = 1; len <= size && levels < OpacityRangeMaxView::kMaxLevels; len *= 2, ++levels) {
    view_.offset[levels] = int(total);
    total += size_t(size - len + 1);
  }
  levels_.resize(total);
  for (int i = 0; i < size; ++i) levels_[size_t(i)] = tf.table[size_t(i)].w;
  for (int k = 1, len = 2; k < levels; ++k, len *= 2) {
    const float* prev = levels_.data() + view_.offset[k - 1];
    float* cur = levels_.data() + view_.offset[k];
    for (int i = 0; i + len <= size; ++i) cur[i] = std::max(prev[i], prev[i + len / 2]);
  }
  view_.levels = levels_.data();
}

// The voxel-to-table mapping in float for the integrator: lo and entries-per-unit, finite and
// overflow-free for any finite range (ranges are clamped to float; empty ones get one unit).
void tableMapping(const TransferFunction& tf, int size, float& lo, float& scale) {
  const double big = double(std::numeric_limits<float>::max());
  double a = std::isfinite(tf.rangeMin) ? std::clamp(tf.rangeMin, -big, big) : 0.0;
  double b = std::isfinite(tf.rangeMax) ? std::clamp(tf.rangeMax, -big, big) : a + 1.0;
  double width = b - a;
  if (!(width > 0)) width = std::max(std::fabs(a) * 1e-6, 1e-30);
  lo = float(a);
  scale = float(std::min(double(size - 1) / width, big));
}

}  // namespace spaceskip

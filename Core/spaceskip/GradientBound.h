// Classifying a brick against a 2-D transfer function over (value, gradient magnitude) with a
// bound on the gradient magnitude its samples can have: the 1-D rule (classificationTF, the
// largest opacity over every gradient row) keeps every brick whose values reach a column with
// opacity, even where the function is opaque at high gradients only and the brick lies inside a
// flat region. Here a brick is also empty when every row its samples' gradients can reach is
// transparent over its value range.
//
// The bound: a sample's gradient is (s(p+e) - s(p-e)) k per axis (render/GradientTF.h); both
// samples are trilinear within the cells one cell around the brick's, whose voxels lie in the
// brick's 3x3x3 neighbourhood of RangeGrid bricks, so each difference is at most that
// neighbourhood's max - min = R, and the normalised magnitude at most min(1, R |k|). The
// integrator reads rows floor(y) and floor(y) + 1 for y = g height - 1/2, so the rows 0 ..
// floor(y_max) + 1 cover it; for each such prefix of rows a sparse max table over the columns
// (as classificationTF builds over all rows) answers the brick in O(1).
//
// Used by the oneTBB and CUDA classifications alike (Classification.cpp, Classification.cu).
// Not included by the render kernels.
#pragma once
#include "Classification.h"
#include "TransferFunction.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace spaceskip {

/// VTK's gradient normalisation (vtkVolumeShaderComposer, computeGradient with a 2-D function or
/// gradient opacity): per index axis, the factor taking the central difference f(p+e) - f(p-e)
/// to the normalised gradient component, avgSpacing / (2 spacing) / (range / 4) over the
/// transfer function's scalar range (the integrator's GradientTFView::gradScale).
void gradientScale(const double spacing[3], double rangeMin, double rangeMax, float k[3]);

/// The classification table of per-position maxima `m` (texel-centred, as a 2-D table's columns
/// or rows): m.size() + 1 entries in `table`'s alpha, entry j the larger of m[j-1] and m[j]
/// (a position between two texel centres reads both). classificationTF's two 2-D rules and
/// GradientRows build their tables with it.
inline void pairMaxEntries(const std::vector<float>& m, std::vector<vec4f>& table) {
  const size_t n = m.size();
  table.assign(n + 1, vec4f{0, 0, 0, 0});
  for (size_t j = 0; j <= n && n > 0; ++j) table[j].w = std::max(m[j > 0 ? j - 1 : 0], m[j < n ? j : n - 1]);
}

/// The row-prefix tables' view (plain data: host pointers on the CPU, device ones on the GPU).
struct GradientRowsView {
  OpacityRangeMaxView prefix;  ///< rows 0..0; rows 0..r at levels + r * stride (same offsets)
  int64_t stride = 0;
  int height = 0;              ///< rows of the 2-D table; 0: no tables (every row)
  float gradNorm = 0.f;        ///< |k|: normalised gradient magnitude per value unit of difference

  /// Max opacity a sample with value in [vmin, vmax] can get when the voxels around it lie in
  /// [nmin, nmax] (the brick's 3x3x3 neighbourhood).
  SS_FUNC float query(float vmin, float vmax, float nmin, float nmax) const {
    float R = nmax - nmin;
    // Trilinear samples rounding a few ulps outside the voxels' range, and the normalisation's
    // own rounding: widened by relative 1e-5 of the magnitudes, then by 1e-5 of the product.
    R += (fabsf(nmin) + fabsf(nmax)) * 2e-5f;
    float g = R * gradNorm * (1.f + 1e-5f);
    int r = height - 1;
    if (g == g && g < 1.f) {  // NaN or >= 1: every row (the integrator clamps g to [0, 1])
      const float y = (g > 0.f ? g : 0.f) * float(height) - 0.5f;
      const int top = int(floorf(y)) + 1;
      r = top < 0 ? 0 : top > height - 1 ? height - 1 : top;
    }
    OpacityRangeMaxView v = prefix;
    v.levels = prefix.levels + stride * r;
    return v.query(vmin, vmax);
  }
};

/// Builds the row-prefix tables of `tf`'s 2-D table (classificationTF's column mapping over
/// [rangeMin, rangeMax]) for a volume of `spacing`; empty (height 0) when `tf` has no 2-D table
/// or the tables would exceed kMaxFloats (then the 1-D rule alone classifies).
class GradientRows {
 public:
  static constexpr size_t kMaxFloats = size_t(1) << 24;
  GradientRows(const TransferFunction& tf, const double spacing[3]);
  GradientRows(const GradientRows&) = delete;
  GradientRows& operator=(const GradientRows&) = delete;
  bool empty() const { return view_.height == 0; }
  const GradientRowsView& view() const { return view_; }
  const std::vector<float>& levels() const { return levels_; }

 private:
  std::vector<float> levels_;
  GradientRowsView view_{};
};

/// The 3x3x3 neighbourhood's range of brick (bx, by, bz) in a RangeGrid's vmin/vmax (x fastest,
/// `dims` bricks; NaN-only bricks hold +inf/-inf and add nothing).
SS_FUNC void neighbourhoodRange(const float* vmin, const float* vmax, vec3i dims, int bx, int by, int bz, float& lo,
                                float& hi) {
  lo = INFINITY;
  hi = -INFINITY;
  for (int z = bz - 1; z <= bz + 1; ++z) {
    if (z < 0 || z >= dims.z) continue;
    for (int y = by - 1; y <= by + 1; ++y) {
      if (y < 0 || y >= dims.y) continue;
      for (int x = bx - 1; x <= bx + 1; ++x) {
        if (x < 0 || x >= dims.x) continue;
        const int64_t i = x + int64_t(dims.x) * (y + int64_t(dims.y) * z);
        lo = vmin[i] < lo ? vmin[i] : lo;
        hi = vmax[i] > hi ? vmax[i] : hi;
      }
    }
  }
}

/// classify (Classification.h) with the gradient rule of `rows` too (oneTBB).
OccupancyGrid classifyWithGradientRows(const RangeGrid& ranges, const TransferFunction& tf, const CropClip& cc,
                                       const GradientRowsView& rows);

/// Brick i passes the gradient rule too (true when `rows` has no tables).
SS_FUNC bool gradientRowsAllow(int64_t i, const float* vmin, const float* vmax, vec3i dims, const GradientRowsView& rows) {
  if (rows.height == 0) return true;
  const int bx = int(i % dims.x), by = int((i / dims.x) % dims.y), bz = int(i / (int64_t(dims.x) * dims.y));
  float lo, hi;
  neighbourhoodRange(vmin, vmax, dims, bx, by, bz, lo, hi);
  return rows.query(vmin[i], vmax[i], lo, hi) > 0.f;
}

}  // namespace spaceskip

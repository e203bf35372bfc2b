// Transfer-function table (RGBA over the scalar range), opacity correction and the
// range-max query used for conservative classification.
#pragma once
#include "Math.h"

#include <string>
#include <vector>

namespace spaceskip {

/// How the samples along a ray combine (vtkVolumeMapper's blend modes, same numbering).
enum class BlendMode : int {
  Composite = 0,         ///< front-to-back emission-absorption
  MaximumIntensity = 1,  ///< the largest sample, mapped through colour and opacity
  MinimumIntensity = 2,  ///< the smallest sample, mapped through colour and opacity
  AverageIntensity = 3,  ///< grey: mean of opacity * normalised scalar over samples in a range
  Additive = 4,          ///< grey: sum of opacity * normalised scalar, clamped to 1
  Isosurface = 5,        ///< composite of the iso values the ray crosses
  Slice = 6              ///< the sample where the ray meets a plane (RenderParams::slicePlane*)
};

/// A control point: scalar value -> colour and opacity (opacity per unit distance).
struct TFPoint {
  double value;
  float r, g, b, a;
};

/// N-entry RGBA table sampled over [rangeMin, rangeMax]. Alpha is the opacity accumulated over
/// `unitDistance` world units (VTK's ScalarOpacityUnitDistance convention).
struct TransferFunction {
  std::vector<vec4f> table;
  double rangeMin = 0, rangeMax = 1;
  double unitDistance = 1;
  /// Dependent components (Volume::components 2 or 4): the alpha entries span
  /// [opacityRangeMin, opacityRangeMax] of the opacity channel instead of [rangeMin, rangeMax]
  /// (vtkGPUVolumeRayCastMapper builds the opacity table over that component's range).
  bool ownOpacityRange = false;
  double opacityRangeMin = 0, opacityRangeMax = 1;
  double alphaMin() const { return ownOpacityRange ? opacityRangeMin : rangeMin; }
  double alphaMax() const { return ownOpacityRange ? opacityRangeMax : rangeMax; }

  /// Piecewise-linear table of `size` entries through the points (sorted by value).
  static TransferFunction fromPoints(std::vector<TFPoint> pts, double lo, double hi, int size = 1024);
  /// Named presets over [lo, hi]: "ramp", "grayscale", "coolwarm", "spike", "band", "opaque", "zero".
  static TransferFunction preset(const std::string& name, double lo, double hi, int size = 1024);

  /// 2-D transfer function (vtkVolumeProperty TF_2D): RGBA over (value, gradient magnitude),
  /// row-major, width2D columns x height2D rows, read as vtkGPUVolumeRayCastMapper reads its
  /// texture: column position u * width2D - 1/2 for u = (v - rangeMin) / (rangeMax - rangeMin),
  /// row position g * height2D - 1/2 for the normalised gradient magnitude g (gradientMagnitude
  /// in render/GradientTF.h), bilinear, clamped at the edges; opacity raw (VTK corrects it not
  /// for the sample distance). Composite blending of one-component volumes, or of two components
  /// holding the x and y values (a second array as the y axis, vtkGPUVolumeRayCastMapper's
  /// Transfer2DYAxisArray): then the row position is u * height2D - 1/2 for component 1's
  /// u = (y - alphaMin()) / (alphaMax() - alphaMin()). Empty: the 1-D table.
  std::vector<vec4f> table2D;
  int width2D = 0, height2D = 0;
  /// Gradient opacity (vtkVolumeProperty::GetGradientOpacity, 1-D mode): the factor on a
  /// sample's opacity over the normalised gradient magnitude g in [0, 1], entry positions
  /// g * size - 1/2 as VTK's 1-D texture (the function sampled over [0, (max-min)/4]). Empty: none.
  std::vector<float> gradientOpacity;

  bool uses2D() const { return width2D > 0 && height2D > 0 && table2D.size() == size_t(width2D) * size_t(height2D); }
  bool usesGradientOpacity() const { return !uses2D() && !gradientOpacity.empty(); }

  bool sameOpacity(const TransferFunction& o) const;
  bool sameColor(const TransferFunction& o) const;
  /// Same 2-D table and gradient-opacity table (either change re-classifies).
  bool sameGradientTables(const TransferFunction& o) const;
};

/// The table classification tests a brick's value range against (OpacityRangeMax): the TF itself
/// with a 1-D table; with a 2-D one, over width2D + 1 entries (the integrator's column mapping:
/// gradientColumnMapping) entry j holds the largest opacity of columns j-1 and j over every row
/// (every gradient magnitude), so a brick is empty only when no value it can take has opacity
/// at any gradient; with gradient opacity the 1-D table (the factor only lowers opacity), all
/// transparent when the factor is 0 everywhere. Lossless without any per-brick gradient range.
/// With `components` 1 the result keeps the 2-D table itself too (table2D, width2D, height2D),
/// for the backends' per-brick gradient bound (GradientBound.h: a brick's value range x the
/// gradient magnitude its neighbourhood can reach), which narrows the column rule above.
/// With `components` 2 (a 2-D table read at component 0 and component 1) the table runs over
/// the rows instead, height2D + 1 entries over [alphaMin(), alphaMax()] (the range grid's
/// component), entry j the largest opacity of rows j-1 and j over every column: a brick whose
/// y values reach no row with opacity is empty, whatever its x values.
TransferFunction classificationTF(const TransferFunction& tf, int components = 1);

/// The 2-D table's column mapping in float: position x = (v - lo) * scale - 1/2 with scale =
/// width2D / (rangeMax - rangeMin), the same floats classificationTF's table is queried with.
void gradientColumnMapping(const TransferFunction& tf, float& lo, float& scale);
/// The 2-D table's row mapping for a second array as its y axis (component 1): position
/// y = (v - lo) * scale - 1/2 with scale = height2D / (alphaMax() - alphaMin()), the same floats
/// classificationTF(tf, 2)'s table is queried with (OpacityRangeMax maps over alphaMin/Max).
void secondAxisRowMapping(const TransferFunction& tf, float& lo, float& scale);

/// Appends the 2-D table and the gradient-opacity factors (in .w) to `table` (the table a backend
/// uploads), returning their offsets (-1: none): they travel to the device with the 1-D table.
void appendGradientTables(const TransferFunction& tf, std::vector<vec4f>& table, int& offset2D, int& offsetGO);

/// Opacity correction for a step of dt world units: 1-(1-a)^(dt/unitDistance).
SS_FUNC float correctOpacity(float a, float dt, float unitDistance) {
  if (a <= 0.f) return 0.f;
  if (a >= 1.f) return 1.f;
  return 1.f - powf(1.f - a, dt / unitDistance);
}

/// The table after opacity correction for sample distance dt.
std::vector<vec4f> correctedTable(const TransferFunction& tf, float dt);
/// The table a blend mode samples, as vtkOpenGLVolumeOpacityTable prepares it: composite
/// corrects opacity for dt, additive scales it by dt/unitDistance, the others use it raw.
std::vector<vec4f> tableForBlend(const TransferFunction& tf, float dt, BlendMode mode);

/// The voxel-to-table mapping in float for the integrator: entry x = (v - lo) * scale over
/// [tf.rangeMin, tf.rangeMax] for a table of `size` entries; finite for any range.
void tableMapping(const TransferFunction& tf, int size, float& lo, float& scale);

/// Plain view of a (corrected) table for the integrator; device pointers on the GPU.
struct TransferFunctionView {
  const vec4f* table;
  int size;
  float lo;     ///< scalar mapped to entry 0
  float scale;  ///< entries per scalar unit: idx = (v - lo) * scale
};

/// Post-classification lookup with linear interpolation between entries; NaN is transparent.
SS_FUNC vec4f lookup(const TransferFunctionView& tf, float v) {
  float x = (v - tf.lo) * tf.scale;
  if (!(x == x)) return vec4f{0, 0, 0, 0};
  x = ss_clamp(x, 0.f, float(tf.size - 1));
  int i0 = int(x);
  int i1 = i0 + 1 < tf.size ? i0 + 1 : i0;
  float f = x - float(i0);
  vec4f a = tf.table[i0], b = tf.table[i1];
  return vec4f{a.x + (b.x - a.x) * f, a.y + (b.y - a.y) * f, a.z + (b.z - a.z) * f,
               a.w + (b.w - a.w) * f};
}

/// O(1) max-opacity query over entry ranges of a TF table: a sparse table whose level k holds the
/// max over 2^k consecutive entries, flat in `levels`. Plain data, read as it is by the CPU
/// classification (host pointer) and the CUDA kernel (device pointer), so both classify alike.
struct OpacityRangeMaxView {
  static constexpr int kMaxLevels = 32;  ///< any int-sized table has at most 31 levels
  const float* levels;                   ///< level k at levels + offset[k]: size - 2^k + 1 entries
  int offset[kMaxLevels];
  int size;         ///< table entries (level 0)
  float lo, scale;  ///< the samplers' own mapping (tableMapping): entry x = (v - lo) * scale

  /// Relative widening of a value range before it is mapped: a trilinear sample of voxels in
  /// [vmin, vmax], computed in float (or by the texture unit), can round a few ulps outside it.
  static constexpr float kRoundingPad = 1e-5f;

  /// Max opacity any sample with value in [vmin, vmax] can get (0 for an empty/NaN range).
  /// Exact where it matters for skipping: the entries are the ones lookup() can blend for such a
  /// value, mapped in float exactly as the samplers map it (float subtraction and multiplication
  /// are monotonic, so every sample's position lies in [x(vmin), x(vmax)]). A position that is a
  /// whole entry reads that entry alone (lookup's weight of the next one is 0), so a brick whose
  /// voxels all sit at a value of opacity 0 (ParaView's default ramp at its lower end, exact-zero
  /// backgrounds) is empty.
  SS_FUNC float query(double vmin, double vmax) const {
    if (!(vmin <= vmax)) return 0.f;  // empty or NaN range
    float a = float(vmin), b = float(vmax);
    const float pad = fmaxf(fabsf(a), fabsf(b)) * kRoundingPad;  // 0 for an all-zero brick
    a -= pad;
    b += pad;
    float x0 = (a - lo) * scale, x1 = (b - lo) * scale;
    const float top = float(size - 1);
    x0 = fminf(fmaxf(x0, 0.f), top);  // fmax/fmin: NaN (inf - inf) becomes the bound
    x1 = fminf(fmaxf(x1, 0.f), top);
    if (!(x0 <= x1)) x0 = 0.f, x1 = top;  // cannot happen for ordered finite input; stay safe
    int i0 = int(floorf(x0));
    int i1 = int(floorf(x1));
    if (float(i1) < x1) ++i1;  // a fractional position blends the next entry too
    i0 = i0 < 0 ? 0 : (i0 > size - 1 ? size - 1 : i0);
    i1 = i1 < i0 ? i0 : (i1 > size - 1 ? size - 1 : i1);
    const int len = i1 - i0 + 1;
    int k = 0;
    while ((2 << k) <= len) ++k;
    const float* L = levels + offset[k];
    return fmaxf(L[i0], L[i1 - (1 << k) + 1]);
  }
};

/// Builds the sparse table over a TF's (uncorrected) opacity on the host. The CPU queries it in
/// place; the CUDA backend copies levels() to the device and points a copy of view() there.
/// Throws std::invalid_argument for an empty table.
class OpacityRangeMax {
 public:
  explicit OpacityRangeMax(const TransferFunction& tf);
  OpacityRangeMax(const OpacityRangeMax&) = delete;  // view_ points into levels_
  OpacityRangeMax& operator=(const OpacityRangeMax&) = delete;
  /// Max opacity any sample with value in [vmin, vmax] can get (0 for an empty/NaN range).
  float query(double vmin, double vmax) const { return view_.query(vmin, vmax); }
  const OpacityRangeMaxView& view() const { return view_; }
  const std::vector<float>& levels() const { return levels_; }

 private:
  std::vector<float> levels_;
  OpacityRangeMaxView view_{};
};

}  // namespace spaceskip

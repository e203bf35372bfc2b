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
  Isosurface = 5         ///< composite of the iso values the ray crosses
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

  /// Piecewise-linear table of `size` entries through the points (sorted by value).
  static TransferFunction fromPoints(std::vector<TFPoint> pts, double lo, double hi, int size = 1024);
  /// Named presets over [lo, hi]: "ramp", "grayscale", "coolwarm", "spike", "band", "opaque", "zero".
  static TransferFunction preset(const std::string& name, double lo, double hi, int size = 1024);
  /// Text file: optional "range LO HI", "size N", "unit U" lines, then "value r g b a" lines.
  static TransferFunction load(const std::string& path, double lo, double hi);

  bool sameOpacity(const TransferFunction& o) const;
  bool sameColor(const TransferFunction& o) const;
};

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

/// O(1) max-opacity query over entry ranges (sparse table), for classification.
class OpacityRangeMax {
 public:
  explicit OpacityRangeMax(const TransferFunction& tf);
  /// Max opacity any sample with value in [vmin, vmax] can get (0 for an empty/NaN range).
  float query(double vmin, double vmax) const;

 private:
  std::vector<std::vector<float>> levels_;
  double lo_, scale_;
  int size_;
};

}  // namespace spaceskip

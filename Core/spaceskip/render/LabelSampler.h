// Nearest-voxel and label-map sampling, written once for the oneTBB and CUDA executors
// (LabelMap.h for the label table and the per-brick label sets).
//   kSampleNearest:  the value of the voxel nearest the sample, through the ordinary table
//                    (vtkVolumeProperty's InterpolationType NEAREST).
//   kLabelNearest:   the label of the nearest voxel.
//   kLabelBlend:     of the labels of the 8 voxels around the sample (the trilinear corners),
//                    the one whose weights sum highest: the argmax of the labels' interpolated
//                    indicator functions.
// Either label mode returns the id of a voxel that a trilinear sample at the same point reads, so
// the brick's label set (with its +1 halo) holds it and skipping stays lossless; its colour comes
// from labelLookup, one table entry, never a blend of two labels' entries.
#pragma once
#include "FrameShared.h"

namespace spaceskip {

/// FrameView::sampling.
constexpr int kSampleTrilinear = 0, kSampleNearest = 1, kLabelNearest = 2, kLabelBlend = 3;

/// Nearest and label sampling from a linear voxel array of one component (clamped at the border,
/// the cells and corners of ArraySampler).
template <class T>
struct NearestSampler {
  const T* data;
  int64_t nx, ny, nz;
  int mode;  ///< kSampleNearest, kLabelNearest or kLabelBlend

  SS_FUNC float fetch(int64_t i, int64_t j, int64_t k) const { return voxelValue(data[i + nx * (j + ny * k)]); }
  SS_FUNC bool labels() const { return mode != kSampleNearest; }

  SS_FUNC float sample(vec3f p) const {
    int64_t x0, x1, y0, y1, z0, z1;
    float fx, fy, fz;
    ArraySampler<T>::axis(p.x, nx, x0, x1, fx);
    ArraySampler<T>::axis(p.y, ny, y0, y1, fy);
    ArraySampler<T>::axis(p.z, nz, z0, z1, fz);
    if (mode != kLabelBlend) return fetch(fx < 0.5f ? x0 : x1, fy < 0.5f ? y0 : y1, fz < 0.5f ? z0 : z1);
    float v[8], w[8];
    for (int c = 0; c < 8; ++c) {
      v[c] = fetch(c & 1 ? x1 : x0, c & 2 ? y1 : y0, c & 4 ? z1 : z0);
      w[c] = (c & 1 ? fx : 1.f - fx) * (c & 2 ? fy : 1.f - fy) * (c & 4 ? fz : 1.f - fz);
    }
    // Sum the weights of each corner's label (a corner whose label came earlier adds nothing
    // new); the largest sum wins, ties to the corner of the larger own weight, then the first.
    float best = v[0], bestSum = -1.f, bestOwn = -1.f;
    for (int c = 0; c < 8; ++c) {
      float sum = 0.f;
      for (int d = 0; d < 8; ++d) sum += v[d] == v[c] ? w[d] : 0.f;
      if (sum > bestSum || (sum == bestSum && w[c] > bestOwn)) {
        best = v[c];
        bestSum = sum;
        bestOwn = w[c];
      }
    }
    return best;
  }

  /// The trilinear interpolation at p of label `label`'s indicator (1 where a voxel has it), as
  /// nested lerps: exactly 1 (0) where all 8 corners have (lack) the label, so that the central
  /// differences of a label's inside are exactly 0 (a sum of the 8 weights rounds near 1, and its
  /// differences normalised into a random normal: speckled shading inside translucent labels,
  /// and CPU and CUDA rounding differently).
  SS_FUNC float indicator(vec3f p, float label) const {
    int64_t x0, x1, y0, y1, z0, z1;
    float fx, fy, fz;
    ArraySampler<T>::axis(p.x, nx, x0, x1, fx);
    ArraySampler<T>::axis(p.y, ny, y0, y1, fy);
    ArraySampler<T>::axis(p.z, nz, z0, z1, fz);
    auto has = [&](int64_t i, int64_t j, int64_t k) { return fetch(i, j, k) == label ? 1.f : 0.f; };
    auto lerp = [](float a, float b, float t) { return a + (b - a) * t; };
    const float y0z0 = lerp(has(x0, y0, z0), has(x1, y0, z0), fx), y1z0 = lerp(has(x0, y1, z0), has(x1, y1, z0), fx);
    const float y0z1 = lerp(has(x0, y0, z1), has(x1, y0, z1), fx), y1z1 = lerp(has(x0, y1, z1), has(x1, y1, z1), fx);
    return lerp(lerp(y0z0, y1z0, fy), lerp(y0z1, y1z1, fy), fz);
  }
};

template <class Sampler>
struct IsNearestSampler {
  static constexpr bool value = false;
};
template <class T>
struct IsNearestSampler<NearestSampler<T>> {
  static constexpr bool value = true;
};

/// A label's table entry: entry v - lo of a table with one entry per value (scale 1,
/// labelTransferFunction); a value off the table or between entries is transparent (NaN too).
SS_FUNC vec4f labelLookup(const TransferFunctionView& tf, float v) {
  const float x = (v - tf.lo) * tf.scale;
  if (!(x >= 0.f && x <= float(tf.size - 1))) return vec4f{0, 0, 0, 0};
  const int i = int(x + 0.5f);
  return float(i) == x || tf.size == 1 ? tf.table[i] : vec4f{0, 0, 0, 0};
}

}  // namespace spaceskip

// 2-D transfer functions (value x gradient magnitude) and gradient opacity, as
// vtkGPUVolumeRayCastMapper (VTK 9.2, vtkVolumeShaderComposer) classifies a sample with them:
// the gradient by central differences one voxel apart, each component divided by
// 2 spacing / average spacing, its length divided by a quarter of the scalar range and clamped
// to [0, 1]; then the 2-D texture at (normalised value, that magnitude) gives colour and raw
// opacity, or the 1-D opacity is multiplied by the gradient-opacity texture at it. With a second
// array as the y axis (Transfer2DYAxisArray) the volume holds two components, the table's x and
// y values, and the texture is read at both, each normalised over its own range. Written once
// for the oneTBB and CUDA executors; skipping stays lossless through classificationTF
// (TransferFunction.h), which needs no gradient per brick.
#pragma once
#include "Components.h"  // IsChannelSampler (Integrator.h includes this after it)
#include "FrameShared.h"

namespace spaceskip {

/// VTK's normalised gradient magnitude in [0, 1] at index-space position p (NaN: 0).
template <class Sampler>
SS_FUNC float gradientMagnitude(const FrameView& f, const Sampler& s, vec3f p) {
  const float* k = f.gtf.gradScale;
  const float gx = (s.sample(p + vec3f{1, 0, 0}) - s.sample(p - vec3f{1, 0, 0})) * k[0];
  const float gy = (s.sample(p + vec3f{0, 1, 0}) - s.sample(p - vec3f{0, 1, 0})) * k[1];
  const float gz = (s.sample(p + vec3f{0, 0, 1}) - s.sample(p - vec3f{0, 0, 1})) * k[2];
  const float m = sqrtf(gx * gx + gy * gy + gz * gz);
  return m == m ? ss_clamp(m, 0.f, 1.f) : 0.f;
}

/// Linear read of `n` entries at texel-centred position x (clamped to the edge entries).
SS_FUNC void texelAxis(float x, int n, int& i0, int& i1, float& w) {
  x = ss_clamp(x, 0.f, float(n - 1));
  i0 = int(x);
  i1 = i0 + 1 < n ? i0 + 1 : i0;
  w = x - float(i0);
}

SS_FUNC vec4f lerp4(vec4f a, vec4f b, float w) {
  return vec4f{a.x + (b.x - a.x) * w, a.y + (b.y - a.y) * w, a.z + (b.z - a.z) * w, a.w + (b.w - a.w) * w};
}

/// The 2-D table bilinear at texel-centred column position x and row position y.
SS_FUNC vec4f table2DAt(const FrameView& f, float x, float y) {
  const GradientTFView& g = f.gtf;
  const vec4f* T = f.tf.table + g.offset;
  int x0, x1, y0, y1;
  float wx, wy;
  texelAxis(x, g.width, x0, x1, wx);
  texelAxis(y, g.height, y0, y1, wy);
  const vec4f a = T[y0 * g.width + x0], b = T[y0 * g.width + x1];
  const vec4f c = T[y1 * g.width + x0], d = T[y1 * g.width + x1];
  return lerp4(lerp4(a, b, wx), lerp4(c, d, wx), wy);
}

/// Colour and opacity of a sample of value v at p (not premultiplied): the 2-D table, or the 1-D
/// table's (opacity-corrected) entry with its opacity times the gradient-opacity factor.
template <class Sampler>
SS_FUNC vec4f classifyWithGradient(const FrameView& f, const Sampler& s, vec3f p) {
  const GradientTFView& g = f.gtf;
  if constexpr (IsChannelSampler<Sampler>::value) {
    if (g.mode != 3) return classifySample(f, s, p);  // the engine sets no other mode for these
    // Mode 3: x from component 0, y from component 1 (NaN in either: transparent, which the
    // classification's NaN-free ranges of component 1 agree with).
    const float v = s.sampleChannel(p, 0), y = s.sampleChannel(p, 1);
    if (!(v == v) || !(y == y)) return vec4f{0, 0, 0, 0};
    return table2DAt(f, (v - g.xLo) * g.xScale - 0.5f, (y - g.yLo) * g.yScale - 0.5f);
  }
  const float v = s.sample(p);
  if (!(v == v)) return vec4f{0, 0, 0, 0};  // NaN: transparent, as the 1-D lookup
  const vec4f* T = f.tf.table + g.offset;
  if (g.mode == 2)
    return table2DAt(f, (v - g.xLo) * g.xScale - 0.5f, gradientMagnitude(f, s, p) * float(g.height) - 0.5f);
  vec4f c = lookup(f.tf, v);
  if (!(c.w > 0.f)) return vec4f{0, 0, 0, 0};
  int i0, i1;
  float w;
  texelAxis(gradientMagnitude(f, s, p) * float(g.width) - 0.5f, g.width, i0, i1, w);
  c.w *= T[i0].w + (T[i1].w - T[i0].w) * w;
  return c;
}

}  // namespace spaceskip

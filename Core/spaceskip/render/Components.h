// Dependent multi-component volumes (vtkVolumeProperty::IndependentComponentsOff), as
// vtkGPUVolumeRayCastMapper classifies them (VTK vtkVolumeShaderComposer.h, ComputeColor/
// ComputeOpacityDeclaration; vtkVolumeInputHelper::UpdateTransferFunctions):
//   2 components: colour = colour TF of component 0, opacity = opacity TF of component 1;
//   4 components: RGB = components 0..2, each normalised over its own range (vtkVolumeTexture's
//                 scale and bias), opacity = opacity TF of component 3.
// The opacity channel is the last one: the range grid and so every builder's skipping use it.
// Written once for the oneTBB and CUDA executors; the Integrator calls classifySample and
// gradientSample, which reduce to the single-component code for every other sampler.
#pragma once
#include "FrameShared.h"

namespace spaceskip {

/// Exact trilinear sampling of a volume of `nc` (2 or 4) interleaved components.
template <class T>
struct ChannelSampler {
  const T* data;
  int64_t nx, ny, nz;
  int nc;

  SS_FUNC float fetch(int64_t i, int64_t j, int64_t k, int c) const {
    return voxelValue(data[(i + nx * (j + ny * k)) * nc + c]);
  }
  /// Component c at p: the same arithmetic as ArraySampler::sample.
  SS_FUNC float sampleChannel(vec3f p, int c) const {
    int64_t x0, x1, y0, y1, z0, z1;
    float fx, fy, fz;
    ArraySampler<T>::axis(p.x, nx, x0, x1, fx);
    ArraySampler<T>::axis(p.y, ny, y0, y1, fy);
    ArraySampler<T>::axis(p.z, nz, z0, z1, fz);
    float c00 = fetch(x0, y0, z0, c) + (fetch(x1, y0, z0, c) - fetch(x0, y0, z0, c)) * fx;
    float c10 = fetch(x0, y1, z0, c) + (fetch(x1, y1, z0, c) - fetch(x0, y1, z0, c)) * fx;
    float c01 = fetch(x0, y0, z1, c) + (fetch(x1, y0, z1, c) - fetch(x0, y0, z1, c)) * fx;
    float c11 = fetch(x0, y1, z1, c) + (fetch(x1, y1, z1, c) - fetch(x0, y1, z1, c)) * fx;
    float c0 = c00 + (c10 - c00) * fy;
    float c1 = c01 + (c11 - c01) * fy;
    return c0 + (c1 - c0) * fz;
  }
  /// The opacity channel: what the blend modes and the range grid see.
  SS_FUNC float sample(vec3f p) const { return sampleChannel(p, nc - 1); }
};

template <class Sampler>
struct IsChannelSampler {
  static constexpr bool value = false;
};
template <class T>
struct IsChannelSampler<ChannelSampler<T>> {
  static constexpr bool value = true;
};

/// Alpha of table entry position x (linear between entries, clamped; NaN: 0), as lookup().
SS_FUNC float lookupAlphaAt(const TransferFunctionView& tf, float x) {
  if (!(x == x)) return 0.f;
  x = ss_clamp(x, 0.f, float(tf.size - 1));
  const int i0 = int(x);
  const int i1 = i0 + 1 < tf.size ? i0 + 1 : i0;
  const float a = tf.table[i0].w;
  return a + (tf.table[i1].w - a) * (x - float(i0));
}

/// 4 components: colour channel c normalised as vtkVolumeTexture does (NaN: 0).
SS_FUNC float directColor(const FrameView& f, float v, int c) {
  return v == v ? ss_clamp((v - f.rgbLo[c]) * f.rgbScale[c], 0.f, 1.f) : 0.f;
}

/// Colour and opacity of the sample at p (not premultiplied, opacity corrected as the table is).
template <class Sampler>
SS_FUNC vec4f classifySample(const FrameView& f, const Sampler& s, vec3f p) {
  if constexpr (IsChannelSampler<Sampler>::value) {
    const float a = lookupAlphaAt(f.tf, (s.sample(p) - f.alphaLo) * f.alphaScale);
    if (!(a > 0.f)) return vec4f{0, 0, 0, 0};  // transparent: the colour channels are not read
    if (s.nc == 2) {
      const vec4f c = lookup(f.tf, s.sampleChannel(p, 0));
      return vec4f{c.x, c.y, c.z, a};
    }
    return vec4f{directColor(f, s.sampleChannel(p, 0), 0), directColor(f, s.sampleChannel(p, 1), 1),
                 directColor(f, s.sampleChannel(p, 2), 2), a};
  } else if constexpr (IsNearestSampler<Sampler>::value) {
    return s.labels() ? labelLookup(f.tf, s.sample(p)) : lookup(f.tf, s.sample(p));
  } else {
    return lookup(f.tf, s.sample(p));
  }
}

/// The value whose gradient shades the sample at q (FrameView::gradientComponent with
/// dependent components, else the scalar).
template <class Sampler>
SS_FUNC float gradientSample(const FrameView& f, const Sampler& s, vec3f q) {
  if constexpr (IsChannelSampler<Sampler>::value) return s.sampleChannel(q, f.gradientComponent);
  else return s.sample(q);
}

}  // namespace spaceskip

// The per-ray integrator (absorption + emission, front to back, post-classification), written
// once for the oneTBB and CUDA executors. Sample positions are global per ray
// (t = t0 + k*dt from the ray's entry into the volume box), so skipping never moves a sample.
// Ray generation is RayGen.h, the skipping traversals Traversal.h, the frame's data FrameShared.h.
#pragma once
#include <type_traits>

#include "../Volume.h"  // VoxelType
#include "FrameShared.h"
#include "RayGen.h"
#include "Traversal.h"

namespace spaceskip {

/// Index of the first lattice sample at or after (t - t0) / dt = x: ceil(x) as int64_t, with x
/// clamped to +-2^62 first (a far origin or extreme spacings can give 1e30 and more; converting
/// that to an integer is undefined) and NaN taken as 0.
SS_FUNC int64_t sampleIndexCeil(float x) {
  constexpr float kLimit = 4.611686e18f;  // 2^62
  return x == x ? int64_t(ceilf(ss_clamp(x, -kLimit, kLimit))) : int64_t(0);
}

/// A traversal's interval [a, b) inside the drawn part [wa, wb) of a ray, its ends snapped to
/// wa and wb where they lie within rounding of them. The iterators compute where the ray enters
/// its first brick and leaves its last by their own float arithmetic, a few ulps off the box's
/// entry and exit that Naive marches between, and a sample in that sliver was lost (measured:
/// rm 512^3, 1024^2, orbit 148,15: Grid left out the last sample of one ray, 2.85/255 off
/// Naive's pixel; the CPU's packets alike). Snapping only adds samples of [wa, wb), which
/// Naive takes too. No snapping without a drawn part (wa >= wb).
SS_FUNC void snapToDrawn(float& a, float& b, float wa, float wb) {
  if (!(wa < wb)) return;
  const float tol = (fabsf(wa) + fabsf(wb)) * 1e-5f;
  if (a - wa <= tol) a = wa;
  if (wb - b <= tol) b = wb;
}

/// Blend modes whose result a brick can change although the TF gives it no opacity (MIP, MinIP:
/// the extreme sample is mapped after the march; average: transparent samples count), or whose
/// skipping test depends on the ray (isosurface). They march the range grid with the ray-dependent
/// test IntervalMarcher::active instead of the opacity occupancy.
SS_FUNC bool usesValueRanges(BlendMode m) {
  return m == BlendMode::MaximumIntensity || m == BlendMode::MinimumIntensity ||
         m == BlendMode::AverageIntensity || m == BlendMode::Isosurface;
}

/// A voxel as the integrator samples it. +-Inf becomes +-2^100: above every finite value (the
/// engine rescales floating volumes into [2^-60, 2^60]), so it takes the end entry of the table,
/// and trilinear weights never form Inf - Inf = NaN next to it. NaN stays NaN.
SS_FUNC float voxelValue(float v) {
  const float big = 1.2676506e30f;  // 2^100
  return v > big ? big : (v < -big ? -big : v);
}
SS_FUNC float voxelValue(double v) { return voxelValue(float(v)); }
template <class T>
SS_FUNC float voxelValue(T v) { return float(v); }

/// Trilinear interpolation in the cell [x0, x1] x [y0, y1] x [z0, z1] at the fractions fx, fy, fz,
/// the corners read by `fetch(i, j, k)`: one body for every sampler (voxel arrays, grids read
/// through their coordinates, the sparse pool's bricks).
template <class Fetch>
SS_FORCE_FUNC float trilinear(const Fetch& fetch, int64_t x0, int64_t x1, int64_t y0, int64_t y1, int64_t z0,
                              int64_t z1, float fx, float fy, float fz) {
  const float c00 = fetch(x0, y0, z0) + (fetch(x1, y0, z0) - fetch(x0, y0, z0)) * fx;
  const float c10 = fetch(x0, y1, z0) + (fetch(x1, y1, z0) - fetch(x0, y1, z0)) * fx;
  const float c01 = fetch(x0, y0, z1) + (fetch(x1, y0, z1) - fetch(x0, y0, z1)) * fx;
  const float c11 = fetch(x0, y1, z1) + (fetch(x1, y1, z1) - fetch(x0, y1, z1)) * fx;
  const float c0 = c00 + (c10 - c00) * fy;
  const float c1 = c01 + (c11 - c01) * fy;
  return c0 + (c1 - c0) * fz;
}

/// Exact trilinear sampling in float from a linear voxel array (clamped at the border).
template <class T>
struct ArraySampler {
  const T* data;
  int64_t nx, ny, nz;

  SS_FUNC float fetch(int64_t i, int64_t j, int64_t k) const {
    return voxelValue(data[i + nx * (j + ny * k)]);
  }
  SS_FUNC static void axis(float p, int64_t n, int64_t& i0, int64_t& i1, float& f) {
    // Clamped so that NaN lands on 0 (ss_clamp would pass it through to the int conversion).
    const float x = p > 0.f ? ss_min(p, float(n - 1)) : 0.f;
    i0 = int64_t(x);
    if (i0 > n - 2) i0 = n > 1 ? n - 2 : 0;
    f = x - float(i0);
    i1 = n > 1 ? i0 + 1 : 0;
  }
  SS_FORCE_FUNC float sample(vec3f p) const {
    int64_t x0, x1, y0, y1, z0, z1;
    float fx, fy, fz;
    axis(p.x, nx, x0, x1, fx);
    axis(p.y, ny, y0, y1, fy);
    axis(p.z, nz, z0, z1, fz);
    return trilinear([this](int64_t i, int64_t j, int64_t k) { return fetch(i, j, k); }, x0, x1, y0, y1, z0, z1, fx,
                     fy, fz);
  }
};

/// A rectilinear grid drawn through its coordinates (AxisWarp.h): the position (the virtual
/// lattice's) read through the coordinates, then ArraySampler's trilinear sample in the grid's
/// own cells. One sampler for every voxel type (a switch per voxel read): one more set of render
/// kernels, not one per type, and the plain ArraySampler keeps no warp on its hot path (a branch
/// there cost N-body 1024^3 Grid frames 11 % on the H200).
struct WarpedSampler {
  const void* data;
  VoxelType type;
  int64_t nx, ny, nz;
  AxisWarpView warp;

  SS_FUNC float fetch(int64_t i, int64_t j, int64_t k) const {
    const int64_t n = i + nx * (j + ny * k);
    switch (type) {
      case VoxelType::UInt8: return voxelValue(static_cast<const uint8_t*>(data)[n]);
      case VoxelType::Int8: return voxelValue(static_cast<const int8_t*>(data)[n]);
      case VoxelType::UInt16: return voxelValue(static_cast<const uint16_t*>(data)[n]);
      case VoxelType::Int16: return voxelValue(static_cast<const int16_t*>(data)[n]);
      case VoxelType::Float32: return voxelValue(static_cast<const float*>(data)[n]);
      case VoxelType::Float64: return voxelValue(static_cast<const double*>(data)[n]);
    }
    return 0.f;
  }
  SS_FORCE_FUNC float sample(vec3f p) const {
    p = warp.apply(p);
    int64_t x0, x1, y0, y1, z0, z1;
    float fx, fy, fz;
    ArraySampler<float>::axis(p.x, nx, x0, x1, fx);
    ArraySampler<float>::axis(p.y, ny, y0, y1, fy);
    ArraySampler<float>::axis(p.z, nz, z0, z1, fz);
    return trilinear([this](int64_t i, int64_t j, int64_t k) { return fetch(i, j, k); }, x0, x1, y0, y1, z0, z1, fx,
                     fy, fz);
  }
};

}  // namespace spaceskip

#include "LabelSampler.h"  // needs voxelValue and ArraySampler
#include "Components.h"  // needs voxelValue and ArraySampler
#include "GradientTF.h"
#include "Scattering.h"

namespace spaceskip {

/// Marches the samples of one interval [a, b): k in [ceil((a-t0)/dt), ceil((b-t0)/dt)),
/// never before `nextK`, so adjacent intervals never take a sample twice. Sample indices are
/// 64-bit: the engine bounds a ray to kMaxSamplesPerRay samples, but an index computed from a
/// far interval end must never wrap (a tiny step once overflowed int and drew nothing). It also
/// keeps each blend mode's running state, from which `active` decides which bricks can still
/// matter.
/// A plain frame: composite blending, no shading, no clipping planes, no cropping, no 2-D TF or
/// gradient opacity. The GPU
/// compiles its kernels for plain frames separately (renderPixel's `Plain`): without the code of
/// the other modes the kernel needs far fewer registers, so more warps hide the voxel fetches.
SS_FUNC bool isPlainFrame(const FrameView& f) {
  return f.blend == BlendMode::Composite && !f.shade && f.cut.numClipPlanes == 0 && !f.cut.cropping &&
         f.gtf.mode == 0;
}

/// Samples a GPU march fetches per step with a sampler (IntervalMarcher::takeBatch): the
/// sampler's kBatch, else 1. Measured on the H100 (docs/results/HISTORY.md, batches of
/// samples): with the hardware filter 4 a step is 1.04-1.22x faster, with exact trilinear
/// sampling (8 loads and their index arithmetic per sample, 4 times over) 0.90-0.95x.
template <class S, class = void>
struct SamplerBatch {
  static constexpr int value = 1;
};
template <class S>
struct SamplerBatch<S, std::void_t<decltype(S::kBatch)>> {
  static constexpr int value = S::kBatch < kMaxSampleBatch ? S::kBatch : kMaxSampleBatch;
};

template <class Sampler, bool Plain = false>
struct IntervalMarcher {
  const FrameView* f;
  const Sampler* s;
  Ray ray;
  float t0;
  int64_t nextK;
  vec4f acc;         ///< composite, isosurface: premultiplied colour so far
  unsigned samples;
  vec3f lightW, viewW;  ///< shading: towards the light and towards the eye, world space
  float extreme;     ///< MIP/MinIP: running max/min; average/additive: running sum
  unsigned count;    ///< MIP/MinIP: samples seen; average: samples counted
  int isoIndex;      ///< isosurface: the iso interval of the last sample, -1 before the first
  vec3f orgW{0, 0, 0}, dirW{0, 0, 0};  ///< the ray in world space (light list, positional lights)
  float shadowL = 0.f;  ///< scattering: the shadow rays' step, the primary step in texture units
  int pixel = -1;       ///< scattering: the pixel (row-major), for queued shadow rays
  float drawnA = 0.f, drawnB = 0.f;  ///< the part of the ray a traversal walks (snapToDrawn; none: equal)

  /// Can a brick whose samples lie in [lo, hi] change this ray's result, given what it has seen?
  SS_FUNC bool active(float lo, float hi) const {
    if (Plain) return true;
    switch (f->blend) {
      case BlendMode::MaximumIntensity: return count == 0 || hi > extreme;
      case BlendMode::MinimumIntensity: return count == 0 || lo < extreme;
      case BlendMode::AverageIntensity: return lo <= f->avgHi && hi >= f->avgLo;
      case BlendMode::Isosurface:  // no crossing possible when [lo, hi] is inside the interval
        return isoIndex < 0 || !(isoBound(isoIndex) <= lo && hi <= isoBound(isoIndex + 1));
      default: return true;
    }
  }
  /// Iso interval bounds: -inf, iso[0], ..., iso[n-1], +inf.
  SS_FUNC float isoBound(int i) const { return i <= 0 ? -INFINITY : i > f->numIso ? INFINITY : f->iso[i - 1]; }

  /// Phong shading as vtkGPUVolumeRayCastMapper does it for its headlight (VTK 9.2): gradient by
  /// central differences one voxel apart (to world space through the inverse transpose of
  /// index->world), two-sided diffuse, specular from the reflected light vector, white light,
  /// specular not tinted, the result clamped to [0, 1].
  /// A label map (LabelSampler.h) is lit by the gradient of the sampled label's interpolated
  /// indicator: its border is the surface, whatever the ids of the labels on either side.
  /// With `alpha` >= 0 (the sample's opacity) and FrameView::scatter on, the gradient shading is
  /// blended with the scattered light (render/Scattering.h) as vtkGPUVolumeRayCastMapper does;
  /// `compW` >= 0, the sample's weight in the pixel's composite, lets its shadow rays be queued.
  SS_FUNC vec3f shadeColor(vec3f rgb, vec3f p, float alpha = -1.f, float compW = -1.f) const {
    float gx = 0.f, gy = 0.f, gz = 0.f;
    bool done = false;
    if constexpr (IsNearestSampler<Sampler>::value) {
      if (s->labels()) {
        const float l = s->sample(p);
        gx = s->indicator(p + vec3f{1, 0, 0}, l) - s->indicator(p - vec3f{1, 0, 0}, l);
        gy = s->indicator(p + vec3f{0, 1, 0}, l) - s->indicator(p - vec3f{0, 1, 0}, l);
        gz = s->indicator(p + vec3f{0, 0, 1}, l) - s->indicator(p - vec3f{0, 0, 1}, l);
        done = true;
      }
    }
    if (!done) {
      gx = gradientSample(*f, *s, p + vec3f{1, 0, 0}) - gradientSample(*f, *s, p - vec3f{1, 0, 0});
      gy = gradientSample(*f, *s, p + vec3f{0, 1, 0}) - gradientSample(*f, *s, p - vec3f{0, 1, 0});
      gz = gradientSample(*f, *s, p + vec3f{0, 0, 1}) - gradientSample(*f, *s, p - vec3f{0, 0, 1});
    }
    if (Plain || !(alpha >= 0.f) || !f->scatter.on) return clamp01(shadeGradient(rgb, p, gx, gy, gz));
    // The blend's gradient magnitude: VTK's (normalised scalar per world length), 1 wherever a
    // 2-D transfer function or gradient opacity normalises its gradient.
    const ScatterView& S = f->scatter;
    float G;
    if (f->gtf.mode != 0) {
      G = gx != 0.f || gy != 0.f || gz != 0.f ? 1.f : 0.f;
    } else {
      const float ax = gx * S.gradScale[0], ay = gy * S.gradScale[1], az = gz * S.gradScale[2];
      G = sqrtf(ax * ax + ay * ay + az * az);
    }
    const float coef = scatterBlend(S.blending, G, alpha);
    const vec3f phong = shadeGradient(rgb, p, gx, gy, gz);
    if (!(coef > 0.f)) return clamp01(phong);
    const vec3f e = S.eyeIdx - p;
    const vec3f viewU = normalize(vec3f{e.x * S.dirScale.x, e.y * S.dirScale.y, e.z * S.dirScale.z});
    return clamp01(scatterShade(*f, *s, p, f->useLights ? worldAt(p) : vec3f{0, 0, 0}, viewU, rgb, shadowL, coef, phong,
                                compW, pixel));
  }
  SS_FUNC static vec3f clamp01(vec3f c) {
    return vec3f{ss_clamp(c.x, 0.f, 1.f), ss_clamp(c.y, 0.f, 1.f), ss_clamp(c.z, 0.f, 1.f)};
  }
  /// The gradient (Phong) shading for the index-space central differences (gx, gy, gz), not
  /// clamped (shadeColor clamps, after the blend with scattering as VTK does).
  SS_FUNC vec3f shadeGradient(vec3f rgb, vec3f p, float gx, float gy, float gz) const {
    const float* M = f->worldToIndex;
    vec3f n{M[0] * gx + M[4] * gy + M[8] * gz, M[1] * gx + M[5] * gy + M[9] * gz, M[2] * gx + M[6] * gy + M[10] * gz};
    const float len = length(n);
    n = len > 0.f ? n * (1.f / len) : vec3f{0, 0, 0};
    if (f->useLights) return shadeLights(rgb, n, p);
    const float nl = -dot(n, lightW);  // VTK: the gradient points inwards, hence -l
    float spec = 0.f;
    if (f->specular != 0.f) {  // ParaView's default Specular is 0: no reflection, no powf
      const vec3f r = normalize(n * (2.f * nl) + lightW);
      const float vr = ss_max(-dot(r, viewW), 0.f);
      spec = vr > 0.f ? f->specular * powf(vr, f->specularPower) : 0.f;
    }
    const float k = f->ambient + f->diffuse * fabsf(nl);
    return vec3f{k * rgb.x + spec, k * rgb.y + spec, k * rgb.z + spec};
  }

  /// World position (origin-relative) of index-space sample p on this ray: the ray's parameter
  /// is the world distance from orgW along dirW (primaryRay).
  SS_FUNC vec3f worldAt(vec3f p) const {
    const float t = dot(p - ray.org, ray.dir) / dot(ray.dir, ray.dir);
    return orgW + dirW * t;
  }

  /// Phong over the light list as vtkGPUVolumeRayCastMapper does it when its lighting is not the
  /// single default headlight (VTK 9.2, ComputeLightingDeclaration; e.g. ParaView's light kit):
  /// unit normal n (towards larger values), per light its direction of travel, two-sided
  /// diffuse when asked, specular from -reflect; positional lights with attenuation and spot
  /// cone; ambient = the lights' ambient colours (not the sample's colour); shadeColor clamps
  /// to [0, 1] as VTK's computeColor does.
  SS_FUNC vec3f shadeLights(vec3f rgb, vec3f n, vec3f p) const {
    const vec3f pw = worldAt(p);
    const vec3f v = normalize(pw - f->eyeW);  // eye -> sample (VTK: -viewDirection)
    vec3f dif{0, 0, 0}, spe{0, 0, 0};
    for (int i = 0; i < f->numLights; ++i) {
      const LightView& L = f->lights[i];
      vec3f ld = L.dir;
      float att = 1.f;
      if (L.positional) positionalLight(L, pw, ld, att);
      float nl = dot(n, ld);
      if (nl < 0.f && f->twoSided) nl = -nl;
      if (nl > 0.f) {
        dif = dif + L.diffuse * ss_max(0.f, att * nl);
        if (f->specular == 0.f) continue;  // ParaView's default: the specular sum is not used
        const vec3f r = normalize(n * (2.f * nl) - ld);
        float rv = dot(v, r);
        if (L.positional && rv < 0.f && f->twoSided) rv = -rv;
        if (rv > 0.f) spe = spe + L.specular * (att * powf(rv, f->specularPower));
      }
    }
    // Without specular reflection spe stays 0 (0 * spe was 0 already, or NaN where a
    // positional light's attenuation was infinite).
    const vec3f a = f->lightAmbient;
    return vec3f{f->ambient * a.x + f->diffuse * dif.x * rgb.x + f->specular * spe.x,
                 f->ambient * a.y + f->diffuse * dif.y * rgb.y + f->specular * spe.y,
                 f->ambient * a.z + f->diffuse * dif.z * rgb.z + f->specular * spe.z};
  }

  /// Slice blend mode (vtkVolumeShaderComposer, VTK 9.2): the ray's value is its one sample where
  /// it meets the plane, through the transfer functions (raw opacity, shaded when shading is on),
  /// when that point lies in [a, b), a drawn part of the ray; no marching. false: done. With
  /// sliceAsVTK the sample is read where VTK's shader reads it (its unadjusted texture
  /// coordinates: up to half a voxel off the plane), else at the plane point itself.
  SS_FUNC bool slice(float a, float b) {
    const float* P = f->slicePlane;
    const float den = P[0] * ray.dir.x + P[1] * ray.dir.y + P[2] * ray.dir.z;
    if (den == 0.f) return true;  // parallel to the plane: never meets it
    const float t = -(P[0] * ray.org.x + P[1] * ray.org.y + P[2] * ray.org.z + P[3]) / den;
    if (!(t >= a && t < b)) return true;
    vec3f p = ray.org + ray.dir * t;
    if (f->sliceAsVTK) {
      // VTK 9.2 takes the plane point's texture coordinate over the box (0..1 from the first to
      // the last point) and samples the texture of N+1 texels there: index i(N+1)/N - 1/2.
      // A piece (MPI) does it in the whole volume's index space, as the serial image.
      const vec3f N = f->boxHi;
      const vec3f o = f->lattice.active ? f->lattice.pieceLo : vec3f{0, 0, 0};
      const vec3f q = p + o;
      p = vec3f{N.x > 0.f ? q.x * (N.x + 1.f) / N.x - 0.5f : q.x, N.y > 0.f ? q.y * (N.y + 1.f) / N.y - 0.5f : q.y,
                N.z > 0.f ? q.z * (N.z + 1.f) / N.z - 0.5f : q.z} - o;
    }
    vec4f c = lookup(f->tf, s->sample(p));
    if (f->shade && c.w > 0.f) {
      const vec3f rgb = shadeColor(vec3f{c.x, c.y, c.z}, p);
      c = vec4f{rgb.x, rgb.y, rgb.z, c.w};
    }
    acc = vec4f{c.x * c.w, c.y * c.w, c.z * c.w, c.w};
    ++samples;
    return false;
  }

  /// Front-to-back "over" of classified colour c at sample position p; false: terminate.
  SS_FUNC bool composite(vec4f c, vec3f p) {
    const float w = (1.f - acc.w) * c.w;
    if (!Plain && f->shade) {
      vec3f rgb = shadeColor(vec3f{c.x, c.y, c.z}, p, c.w, w);
      c.x = rgb.x;
      c.y = rgb.y;
      c.z = rgb.z;
    }
    acc.x += w * c.x;
    acc.y += w * c.y;
    acc.z += w * c.z;
    acc.w += w;
    return acc.w < f->ertThreshold;
  }

  /// Every mode but composite, one sample of value v at p; false: terminate.
  SS_FUNC bool blendSample(float v, vec3f p) {
    if (!(v == v)) return true;  // NaN: no contribution, as in classification
    switch (f->blend) {
      case BlendMode::MaximumIntensity:
        if (count == 0 || v > extreme) extreme = v;
        ++count;
        return true;
      case BlendMode::MinimumIntensity:
        if (count == 0 || v < extreme) extreme = v;
        ++count;
        return true;
      case BlendMode::AverageIntensity:
        if (v >= f->avgLo && v <= f->avgHi) {
          extreme += lookup(f->tf, v).w * (v - f->normLo) * f->normScale;
          ++count;
        }
        return true;
      case BlendMode::Additive:
        extreme += lookup(f->tf, v).w * (v - f->normLo) * f->normScale;
        return true;
      case BlendMode::Isosurface: {
        // vtkVolumeShaderComposer: the first sample picks its interval; later, leaving the
        // interval crosses the iso value on that side (one per sample), composited with that
        // value's colour and opacity and shaded at the sample.
        if (isoIndex < 0) {
          int i = 0;
          while (i < f->numIso && v > f->iso[i]) ++i;
          isoIndex = i;
          return true;
        }
        float iv;
        if (v < isoBound(isoIndex)) {
          iv = isoBound(isoIndex);
          --isoIndex;
        } else if (v > isoBound(isoIndex + 1)) {
          iv = isoBound(isoIndex + 1);
          ++isoIndex;
        } else {
          return true;
        }
        vec4f c = lookup(f->tf, iv);
        return c.w > 0.f ? composite(c, p) : true;
      }
      default: return true;
    }
  }

  /// The samples of interval [a, b) not taken yet: k in [kBegin, kEnd). Marks them as taken.
  SS_FUNC void range(float a, float b, int64_t& kBegin, int64_t& kEnd) {
    snapToDrawn(a, b, drawnA, drawnB);
    const float dt = f->dt;
    kBegin = sampleIndexCeil((a - t0) / dt);
    kEnd = sampleIndexCeil((b - t0) / dt);
    if (kBegin < nextK) kBegin = nextK;
    if (kEnd > nextK) nextK = kEnd;
  }

  /// Sample k of the ray; false: terminate.
  SS_FUNC bool take(int64_t k) {
    const float t = t0 + float(k) * f->dt;
    const vec3f p = ray.org + ray.dir * t;
    ++samples;
    if (Plain || f->blend == BlendMode::Composite) {
      // lookup(f->tf, s->sample(p)); dependent components; 2-D TF or gradient opacity (not Plain)
      const vec4f c = !Plain && f->gtf.mode != 0 ? classifyWithGradient(*f, *s, p) : classifySample(*f, *s, p);
      return c.w > 0.f ? composite(c, p) : true;
    }
    return blendSample(s->sample(p), p);
  }

  /// Samples k .. k+n-1 (1 <= n <= kMaxSampleBatch) exactly as n calls of take() (the same
  /// positions, values, colours, order of compositing and termination), but in plain frames
  /// their voxel fetches are all issued before the first value is used, then their table
  /// lookups: on a GPU a run of samples otherwise waits for one memory latency per sample, one
  /// after another, which is what the rays crossing N-body's dense clusters spend their time on
  /// (batches of samples). Other modes and dependent components call take() n times. false:
  /// terminate.
  SS_FUNC bool takeBatch(int64_t k, int n) {
    constexpr int kBatch = SamplerBatch<Sampler>::value;
    if constexpr (IsChannelSampler<Sampler>::value || !Plain || kBatch == 1) {
      for (int i = 0; i < n; ++i)
        if (!take(k + i)) return false;
      return true;
    } else {
      float v[kBatch];
      vec4f c[kBatch];
#ifdef __CUDA_ARCH__
#pragma unroll
#endif
      for (int i = 0; i < kBatch; ++i)
        if (i < n) v[i] = s->sample(ray.org + ray.dir * (t0 + float(k + i) * f->dt));
#ifdef __CUDA_ARCH__
#pragma unroll
#endif
      for (int i = 0; i < kBatch; ++i)
        if (i < n) c[i] = lookup(f->tf, v[i]);
#ifdef __CUDA_ARCH__
#pragma unroll
#endif
      for (int i = 0; i < kBatch; ++i) {
        if (i >= n) break;
        ++samples;
        if (c[i].w > 0.f && !composite(c[i], ray.org + ray.dir * (t0 + float(k + i) * f->dt))) return false;
      }
      return true;
    }
  }

  /// The samples of [k, kEnd) (k < kEnd) a GPU step takes: FrameView::sampleBatch of them at
  /// most (and SamplerBatch's), at least one.
  SS_FUNC int batchOf(int64_t k, int64_t kEnd) const {
    constexpr int kBatch = SamplerBatch<Sampler>::value;
    const int64_t b = f->sampleBatch < 1 ? 1 : (f->sampleBatch < kBatch ? f->sampleBatch : kBatch);
    return int(b < kEnd - k ? b : kEnd - k);
  }

  /// Every sample of [a, b) in one loop (Naive, and the last step of cropping's edge cases);
  /// on a GPU in batches (takeBatch).
  SS_FUNC bool operator()(float a, float b) {
    int64_t k, kEnd;
    range(a, b, k, kEnd);
#ifdef __CUDA_ARCH__
    if constexpr (SamplerBatch<Sampler>::value > 1) {
      while (k < kEnd) {
        const int n = batchOf(k, kEnd);
        if (!takeBatch(k, n)) return false;
        k += n;
      }
      return true;
    }
#endif
    for (; k < kEnd; ++k)
      if (!take(k)) return false;
    return true;
  }

  /// Sample 0 of the ray, if [t0, t0 + dt) has it not taken yet (a ray that leaves the box
  /// before its first step: firstSample).
  SS_FUNC void takeFirst() {
    int64_t k, kEnd;
    range(t0, t0 + f->dt, k, kEnd);
    if (k < kEnd) take(k);
  }

  /// Walks a traversal iterator (Traversal.h) the way a CPU core likes it: consecutive
  /// intervals are merged into runs and each run is marched in one tight loop (the samples are
  /// the same: intervals that touch share their end points). With value ranges every interval
  /// is marched before the next brick is decided. false: terminated.
  template <class Iter>
  SS_FUNC bool marchRuns(Iter& it) {
    const bool eachOnItsOwn = f->grid.vmin != nullptr;
    float ra = 0.f, rb = 0.f;
    bool have = false;
    for (;;) {
      float a = 0.f, b = 0.f;
      const Step st = it.next(*this, a, b);
      if (st == Step::Done) break;
      if (st != Step::Interval) continue;
      if (have && a == rb) {
        rb = b;
      } else {
        if (have && !(*this)(ra, rb)) return false;
        ra = a;
        rb = b;
        have = true;
      }
      if (eachOnItsOwn) {
        have = false;
        if (!(*this)(ra, rb)) return false;
      }
    }
    return have ? (*this)(ra, rb) : true;
  }

  /// The iterator's driver for this processor: on a GPU one traversal step or one sample per
  /// loop iteration (march), on a CPU whole runs (marchRuns). Same samples either way.
  template <class Iter>
  SS_FUNC bool walk(Iter& it) {
#ifdef __CUDA_ARCH__
    return march(it);
#else
    return marchRuns(it);
#endif
  }

  /// Walks a traversal iterator (Traversal.h), one traversal step or one sample (a batch with
  /// samplers that ask for it: takeBatch) per iteration, so neighbouring rays of a warp advance together.
  /// false: terminated.
  template <class Iter>
  SS_FUNC bool march(Iter& it) {
    int64_t k = 0, kEnd = 0;
    for (;;) {
      if (k < kEnd) {
        if constexpr (SamplerBatch<Sampler>::value > 1) {  // a batch of the interval's samples
          const int n = batchOf(k, kEnd);
          if (!takeBatch(k, n)) return false;
          k += n;
        } else {
          if (!take(k)) return false;
          ++k;
        }
        continue;
      }
      float a, b;
      const Step st = it.next(*this, a, b);
      if (st == Step::Done) return true;
      if (st == Step::Interval) range(a, b, k, kEnd);
    }
  }

  /// The pixel's premultiplied RGBA once the march is over.
  SS_FUNC vec4f result() const {
    switch (f->blend) {
      case BlendMode::MaximumIntensity:
      case BlendMode::MinimumIntensity: {
        if (count == 0) return vec4f{0, 0, 0, 0};
        vec4f c = lookup(f->tf, extreme);
        return vec4f{c.x * c.w, c.y * c.w, c.z * c.w, c.w};
      }
      case BlendMode::AverageIntensity: {
        if (count == 0) return vec4f{0, 0, 0, 0};
        const float g = ss_clamp(extreme / float(count), 0.f, 1.f);
        return vec4f{g, g, g, 1.f};
      }
      case BlendMode::Additive: {
        const float g = ss_clamp(extreme, 0.f, 1.f);
        return vec4f{g, g, g, 1.f};
      }
      default: return acc;
    }
  }
};

/// Whether a frame's rays may be cut into segments marched apart (renderPixel's `segment`):
/// composite plain frames without early ray termination, a piece's incoming opacity or sample
/// counts, where the segments' premultiplied colours composited front to back ("over") give the
/// whole ray's colour (up to float rounding: the same samples, the sums associated differently).
SS_FUNC bool segmentableFrame(const FrameView& f) {
  return isPlainFrame(f) && !(f.ertThreshold <= 1.f) && !f.alphaIn && !f.sampleCount && !f.lattice.active;
}

/// A shaded ray's light and view directions in world space (IntervalMarcher::lightW, viewW) for
/// the headlight model: VTK's headlight is at the eye, seen from the ray's entry point; a set
/// light direction is the same for every ray. The scalar integrator and the SIMD packets
/// (Core/src/CpuMarch.cpp) both set their rays up here.
SS_FUNC void rayLighting(const FrameView& f, const PrimaryRay& p, vec3f& lightW, vec3f& viewW) {
  const vec3f toEye = normalize(f.eyeW - (p.nearW + p.dirW * p.tEnter));
  const bool head = f.lightDir.x == 0.f && f.lightDir.y == 0.f && f.lightDir.z == 0.f;
  lightW = head ? toEye : normalize(f.lightDir);
  viewW = toEye;
}

/// Premultiplied RGBA of pixel (px, py); row 0 is the bottom row (OpenGL convention).
/// `Traversal` >= 0 fixes the traversal at compile time (the CUDA kernels, one per traversal);
/// -1 reads f.traversal.
/// `Plain` (only for frames where isPlainFrame holds) compiles the composite path alone.
/// With `segments` > 1 (segmentableFrame frames only) only segment `segment` of the ray's
/// samples is marched: the lattice's samples split into `segments` runs of equal count, the
/// shared boundaries computed alike on both sides, so each sample is taken by one segment.
template <class Sampler, int Traversal = -1, bool Plain = false>
SS_FUNC vec4f renderPixel(const FrameView& f, const Sampler& s, int px, int py, int segment = 0, int segments = 1) {
  const PrimaryRay p = primaryRay(f, px, py);
  const Ray& r = p.r;
  const Ray rl = pieceRay(f, r);  // voxels, grid and tree (a piece's own index space; RayGen.h)
  const vec3f inv = p.inv;
  const vec3f nearW = p.nearW, dirW = p.dirW;
  const float tEnter = p.tEnter, tExit = p.tExit;
  if (f.sampleCount) f.sampleCount[int64_t(py) * f.width + px] = 0;
  if (!(tEnter < tExit)) return vec4f{0, 0, 0, 0};
  float ownA = 0.f, ownB = 0.f;  // a piece of the volume (MPI): where this ray is its own
  if (f.lattice.active && !ownedInterval(f, r, inv, ownA, ownB)) return vec4f{0, 0, 0, 0};
  // The opacity the ray brings from pieces in front (FrameView::alphaIn): early ray termination
  // then stops where the whole volume's ray stops.
  const float aIn = f.alphaIn && (Plain || f.blend == BlendMode::Composite || f.blend == BlendMode::Isosurface)
                        ? f.alphaIn[int64_t(py) * f.width + px]
                        : 0.f;
  if (aIn >= f.ertThreshold) return vec4f{0, 0, 0, 0};

  IntervalMarcher<Sampler, Plain> m{&f, &s, rl, tEnter, 0, vec4f{0, 0, 0, aIn}, 0u, vec3f{0, 0, 0}, vec3f{0, 0, 0},
                             0.f, 0u, -1};
  if (!Plain && f.shade) rayLighting(f, p, m.lightW, m.viewW);
  m.orgW = nearW;
  m.dirW = dirW;
  if (!Plain && f.scatter.on) {  // VTK's g_lengthStep: the primary step in texture units
    const vec3f st = rl.dir * f.dt;
    m.shadowL = length(vec3f{st.x / f.scatter.texN.x, st.y / f.scatter.texN.y, st.z / f.scatter.texN.z});
    m.pixel = py * f.width + px;
  }
  if (!Plain && f.blend == BlendMode::Slice) {  // no marching: the sample on the plane, if drawn
    float a = tEnter, b = tExit;
    if (f.cut.numClipPlanes == 0 || clipToPlanes(f.cut, r, a, b)) {
      auto slice = [&](float a0, float b0) -> bool {
        if (f.lattice.active) {  // a piece (MPI) draws the plane where the ray is its own
          a0 = ss_max(a0, ownA);
          b0 = ss_min(b0, ownB);
        }
        return m.slice(a0, b0);
      };
      if (f.cut.cropping) forEachCroppedInterval(f.cut, r, a, b, slice);
      else slice(a, b);
    }
    if (f.sampleCount) f.sampleCount[int64_t(py) * f.width + px] = m.samples;
    return m.result();
  }
  // The sample lattice is anchored where the ray enters the drawn part of the volume (the box,
  // cut by the clipping planes, and the first drawn cropping region), as VTK's mapper does by
  // clipping its proxy geometry: no wood grain on cut faces; firstSample steps in and the
  // jitter follow. The anchor depends on the ray and the planes only, never on the skipping
  // structure, so every builder takes the same samples.
  float lead = f.firstSample * f.dt +
                     (f.jitter ? f.dt * float(hashPixel(px, py, f.jitterSeed) >> 8) * (1.f / 16777216.f) : 0.f);
  bool anchored = false;
  auto march = [&](float a, float b) -> bool {  // [a, b): a drawn part of the whole ray
    if (!anchored) {
      m.t0 = a + lead;
      anchored = true;
    }
    if (f.lattice.active) {  // anchored on the whole ray above; draws its owned part only
      a = ss_max(a, ownA);
      b = ss_min(b, ownB);
      if (!(a < b)) return true;
    }
    m.drawnA = a;
    m.drawnB = b;
    switch (Traversal >= 0 ? TraversalKind(Traversal) : f.traversal) {
      case TraversalKind::Naive: return m(a, b);
      case TraversalKind::Grid: {
        GridIter it;
        it.init(f.grid, rl, inv, a, b);
        return m.walk(it);
      }
      case TraversalKind::GridParts: {
        GridPartsIter it;
        it.init(f.grid, rl, inv, a, b);
        return m.walk(it);
      }
      case TraversalKind::Tree: {
        TreeIter it;
        it.init(f.tree, rl, inv, a, b);
        return m.walk(it);
      }
      case TraversalKind::Hybrid: {
        HybridIter it;
        it.init(f.tree, f.grid, rl, inv, a, b);
        return m.walk(it);
      }
    }
    return true;
  };
  float a = tEnter, b = tExit;
  if (Plain || f.cut.numClipPlanes == 0 || clipToPlanes(f.cut, r, a, b)) {
    if (!Plain && f.cut.cropping) {
      // VTK starts cropped rays on the face of the first drawn region itself, not one step in
      // (measured against vtkGPUVolumeRayCastMapper: sub-volume 43.5 dB this way, 38.9 dB one
      // step in, 40.7 dB on the box's lattice).
      lead -= f.firstSample * f.dt;
      forEachCroppedInterval(f.cut, r, a, b, march);
    } else if (f.firstSample > 0.f && !(a + lead < b)) {
      // Starting one or more steps in, the ray may leave the box before its first sample: that
      // sample is still taken (clamped to the box), as vtkGPUVolumeRayCastMapper does; every
      // traversal alike. (A segmented ray: its first segment.)
      m.t0 = a + lead;
      if (segment == 0 && (!f.lattice.active || ownsClampedSample(f, r.org + r.dir * m.t0))) m.takeFirst();
    } else {
      // One call of `march` for whole rays and segments alike: each call site is a copy of the
      // traversal and the batch of samples, and a GPU kernel twice that size ran several times
      // slower on sparse data (its instructions no longer cached).
      float sa = a, sb = b;
      if (segments > 1) {
        m.t0 = a + lead;
        anchored = true;
        const int64_t k0 = sampleIndexCeil((a - m.t0) / f.dt), n = sampleIndexCeil((b - m.t0) / f.dt) - k0;
        if (segment > 0) sa = m.t0 + float(k0 + n * segment / segments) * f.dt;
        if (segment < segments - 1) sb = m.t0 + float(k0 + n * (segment + 1) / segments) * f.dt;
      }
      if (sa < sb) march(sa, sb);
    }
  }
  if (f.sampleCount) f.sampleCount[int64_t(py) * f.width + px] = m.samples;
  vec4f res = m.result();
  res.w -= aIn;  // the piece's own share (premultiplied colour was weighted from aIn on)
  return f.lattice.active ? pieceResult(f, res, ownB, tExit) : res;
}

}  // namespace spaceskip

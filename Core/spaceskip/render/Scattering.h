// Volumetric shadows and scattering (FrameView::scatter), written once for the oneTBB and CUDA
// executors, with vtkGPUVolumeRayCastMapper's semantics (VTK 9.2, ParaView 5.11): a shaded
// sample casts one shadow ray per light through the same opacity-corrected transfer function,
// the lit colour is diffuse * light colour * transmittance * phase (Henyey-Greenstein, not
// divided by 4 pi), and it is blended with the gradient (Phong) shading by a coefficient of
// VolumetricScatteringBlending, the sample's opacity and its gradient magnitude.
// Unlike VTK's, the shadow rays skip empty space: a DDA over the brick occupancy the primary rays'
// classification made, walking the set parts of sparse bricks and leaping with DistanceGrid's
// field where there are (a brick or part it calls empty holds no sample of non-zero opacity, so
// skipping it multiplies the transmittance by exactly 1), and they stop once their light can no
// longer change the colour by ScatterView::cutoff. Both hold for the naive shadow march as well,
// so every builder gives the image of Naive. On the GPU the primary rays queue their shadow rays
// for a second kernel (scatterShade), which gives the same image.
#pragma once
#include "FrameShared.h"
#include "Traversal.h"

namespace spaceskip {

/// Traversal.h's iterators ask their marcher about value ranges only with GridView::vmin; the
/// occupancy grid of shadow rays has none.
struct AllBricksActive {
  SS_FUNC bool active(float, float) const { return true; }
};

/// VTK's phase function: 1 when |g| < 0.01, else Henyey-Greenstein without its 1 / (4 pi), for
/// the cosine c between the light's direction of travel and the direction towards the eye.
SS_FUNC float scatterPhase(float g, float c) {
  if (fabsf(g) < 0.01f) return 1.f;
  const float d = ss_max(1.f + g * g - 2.f * g * c, 1e-12f);
  return (1.f - g * g) / (d * sqrtf(d));
}

/// Opacity of a shadow ray's sample: the primary ray's classification (the same corrected table,
/// 2-D transfer function or gradient opacity included), in [0, 1].
template <class Sampler>
SS_FUNC float shadowAlpha(const FrameView& f, const Sampler& s, vec3f q) {
  const float a = f.gtf.mode != 0 ? classifyWithGradient(f, s, q).w : classifySample(f, s, q).w;
  return a > 0.f ? ss_min(a, 1.f) : 0.f;
}

/// Transmittance from the sample at index-space point p towards a light, as VTK's volumeShadow:
/// the ray starts one step L (texture units, the primary ray's step there) towards the light,
/// casts nothing when the texture box [0, 1]^3 ends within that step, and takes the samples
/// p + j L n for j = 1 .. ceil(maxdist / L), maxdist the distance to the box (and to a
/// positional light) and at most the reach. `towardT`: the direction towards the light in
/// texture units, `distT`: the distance to a positional light (INFINITY: directional),
/// `weight`: the most the light can add to the colour (the cutoff's scale).
template <class Sampler>
SS_FUNC float shadowTransmittance(const FrameView& f, const Sampler& s, vec3f p, vec3f towardT, float distT, float L,
                                  float weight) {
  const ScatterView& S = f.scatter;
  const float len = length(towardT);
  if (!(len > 0.f) || !(L > 0.f)) return 1.f;
  const vec3f n = towardT * (1.f / len);
  const vec3f dI{n.x * S.texN.x, n.y * S.texN.y, n.z * S.texN.z};  // index units per texture unit
  const Ray sr{p, dI};
  const vec3f inv = safeInverse(dI);
  float t0, tBox;  // the texture box is [-1/2, n - 1/2] in index units
  intersectBox(sr, inv, vec3f{-0.5f, -0.5f, -0.5f}, f.boxHi + vec3f{0.5f, 0.5f, 0.5f}, t0, tBox);
  if (!(tBox - L >= L)) return 1.f;
  float maxd = tBox - L;
  if (distT < INFINITY) maxd = ss_min(maxd, fabsf(distT - L));
  maxd = ss_min(maxd, S.reach);
  if (!(maxd >= 0.001f)) return 1.f;
  const int64_t jEnd = int64_t(ceilf(maxd / L)) + 1;  // samples j in [1, jEnd)
  float T = 1.f;
  int64_t next = 1;
  bool done = false;
  // The samples of [a, b) not taken yet, in order; each exactly once however the ray is cut.
  auto run = [&](float a, float b) {
    int64_t j = sampleIndexCeil(a / L), j1 = sampleIndexCeil(b / L);
    if (j < next) j = next;
    if (j1 > jEnd) j1 = jEnd;
    for (; j < j1; ++j) {
      T *= 1.f - shadowAlpha(f, s, p + dI * (float(j) * L));
      if (T * weight < S.cutoff) {
        done = true;
        return;
      }
    }
    if (j1 > next) next = j1;
  };
  const float tLast = (float(jEnd) - 0.5f) * L;  // between the last sample and the one after
  float tGrid = L;  // [L, tGrid): inside the voxels' box, walked over the occupancy grid
  if (S.occ.occ) {
    float i0, i1;
    intersectBox(sr, inv, vec3f{0, 0, 0}, f.boxHi, i0, i1);
    tGrid = ss_max(L, ss_min(i1, tLast));
    if (tGrid > L) {
      GridIterT<true> it;
      it.init(S.occ, sr, inv, L * 0.5f, tGrid);
      const AllBricksActive all;
      for (;;) {
        float a, b;
        const Step st = it.next(all, a, b);
        if (st == Step::Done) break;
        if (st != Step::Interval) continue;
        run(a, b);
        if (done) return T;
      }
    }
  }
  // The rest: every sample (no grid, or the half voxel between the voxels and the texture box,
  // where the sampler clamps to the border voxels).
  run(tGrid, tLast);
  return T;
}

/// One light's share of the scattered light at a sample, before its shadow ray: where the
/// light is (`towardT`, `distT`, as shadowTransmittance takes them), the colour it adds at
/// transmittance 1 (phase * attenuation * diffuse * light colour * the sample's colour; no N.L
/// and no specular: VTK's secondary contribution) and the most it can add (`weight`: the
/// cutoff's scale, the blend coefficient included).
struct ScatterLight {
  vec3f towardT;
  float distT;
  vec3f rgb;
  float weight;
};

/// Light i's ScatterLight at the sample at pT (adjusted texture units; pw: its origin-relative
/// world position, viewU: the unit direction towards the eye in unadjusted texture units).
/// false: the light adds nothing there.
SS_FUNC bool scatterLight(const FrameView& f, int i, vec3f pT, vec3f pw, vec3f viewU, vec3f rgb, float coef,
                          ScatterLight& out) {
  const ScatterView& S = f.scatter;
  const bool positional = f.useLights ? f.lights[i].positional != 0 : S.headPositional != 0;
  const vec3f lightDiffuse = f.useLights ? f.lights[i].diffuse : vec3f{1, 1, 1};
  float phase, atten = 1.f;
  out.distT = INFINITY;
  if (positional) {
    out.towardT = S.lightU[i] - pT;  // VTK mixes the light's unadjusted and the sample's adjusted coordinates
    out.distT = length(out.towardT);
    // The default headlight: a point light at the eye, its phase taken for light coming
    // straight at the viewer (cos = -1), as VTK does.
    phase = scatterPhase(S.g, f.useLights ? dot(normalize(pT - S.lightU[i]), viewU) : -1.f);
    if (f.useLights) {
      const LightView& Lv = f.lights[i];
      const vec3f d = pw - Lv.pos;
      const float dist = length(d);
      atten = 1.f / (Lv.atten.x + Lv.atten.y * dist + Lv.atten.z * dist * dist);
      if (Lv.cosCone > -2.f) {
        const float coneDot = dist > 0.f ? dot(d * (1.f / dist), Lv.dir) : 1.f;
        atten = coneDot >= Lv.cosCone ? atten * powf(coneDot, Lv.exponent) : 0.f;
      }
    }
  } else {
    out.towardT = S.lightU[i];
    phase = scatterPhase(S.g, dot(normalize(out.towardT * -1.f), viewU));
  }
  const float lightMax = ss_max(lightDiffuse.x, ss_max(lightDiffuse.y, lightDiffuse.z));
  const float rgbMax = ss_max(rgb.x, ss_max(rgb.y, rgb.z));
  const float w = phase * atten * f.diffuse;
  out.rgb = vec3f{rgb.x * lightDiffuse.x, rgb.y * lightDiffuse.y, rgb.z * lightDiffuse.z} * w;
  out.weight = w * lightMax * rgbMax * coef;
  return out.weight > 0.f;
}

/// Offers a shadow ray to the queue (device code only); false: full (or host), march it here.
SS_FUNC bool pushShadow(const ScatterView& S, const ShadowRecord& r) {
#ifdef __CUDA_ARCH__
  // Once full, the count stops growing (but for the rays in flight), so it cannot wrap.
  if (*static_cast<volatile unsigned*>(S.queueCount) >= S.queueCapacity) return false;
  const unsigned i = atomicAdd(S.queueCount, 1u);
  if (i >= S.queueCapacity) return false;
  S.queue[i] = r;
  return true;
#else
  (void)S;
  (void)r;
  return false;
#endif
}

/// A shaded sample's colour with scattering, before VTK's clamp: phong * (1 - coef) + coef *
/// (the lights' ambient colour * ambient + per light its ScatterLight colour * the transmittance
/// of its shadow ray) (p: index space; pw, viewU: as scatterLight; L: the shadow step).
/// With a shadow queue (ScatterView::queue: the CUDA executor) and the sample's weight in the
/// pixel's front-to-back composite `compW` (>= 0), the shadow rays are not marched here: each goes
/// to the queue with the colour it adds to the pixel at transmittance 1, and a second pass
/// (queuedShadowColour) marches them in full warps and adds colour * transmittance to the pixel,
/// instead of the few lanes of a warp whose samples cast a ray marching while the others wait.
/// The pixel is linear in each transmittance wherever VTK's clamp to [0, 1] cannot act for any
/// transmittance in [0, 1]; that is checked first, and a sample where it could marches its rays
/// here. Either way the image is the same (up to the order of float additions).
/// Out of line on the GPU: inlined, this path (a DDA and a march per light) made every shaded
/// kernel several times larger and its compilation minutes longer.
template <class Sampler>
SS_NOINLINE_FUNC vec3f scatterShade(const FrameView& f, const Sampler& s, vec3f p, vec3f pw, vec3f viewU, vec3f rgb,
                                    float L, float coef, vec3f phong, float compW, int pixel) {
  const ScatterView& S = f.scatter;
  const vec3f pT{(p.x + 0.5f) / S.texN.x, (p.y + 0.5f) / S.texN.y, (p.z + 0.5f) / S.texN.z};
  const int numLights = f.useLights ? f.numLights : 1;
  vec3f c = phong * (1.f - coef);
  if (f.useLights) c = c + f.lightAmbient * (f.ambient * coef);
  bool defer = S.queue != nullptr && compW >= 0.f && pixel >= 0;
  if (defer) {  // the brightest the sample can get: no channel may need the clamp
    vec3f hi = c;
    for (int i = 0; i < numLights; ++i) {
      ScatterLight l;
      if (scatterLight(f, i, pT, pw, viewU, rgb, coef, l)) hi = hi + l.rgb * coef;
    }
    defer = hi.x <= 1.f && hi.y <= 1.f && hi.z <= 1.f && c.x >= 0.f && c.y >= 0.f && c.z >= 0.f;
  }
  for (int i = 0; i < numLights; ++i) {
    ScatterLight l;
    if (!scatterLight(f, i, pT, pw, viewU, rgb, coef, l)) continue;
    if (defer && pushShadow(S, ShadowRecord{p, l.towardT, l.distT, L, l.weight, l.rgb * (coef * compW), pixel}))
      continue;
    c = c + l.rgb * (coef * shadowTransmittance(f, s, p, l.towardT, l.distT, L, l.weight));
  }
  return c;
}

/// What a queued shadow ray adds to its pixel (the second pass of scatterShade's queue).
template <class Sampler>
SS_FUNC vec3f queuedShadowColour(const FrameView& f, const Sampler& s, const ShadowRecord& r) {
  return r.rgb * shadowTransmittance(f, s, r.p, r.towardT, r.distT, r.L, r.weight);
}

/// Whether a frame's shadow rays skip over the brick occupancy (ScatterView::occ): every builder
/// but Naive (whose frames are the reference), and only without cropping and clipping planes,
/// which empty the bricks they cut away while VTK's shadow rays still see those voxels.
SS_FUNC bool scatterSkips(const FrameView& f, TraversalKind traversal) {
  return f.scatter.on && traversal != TraversalKind::Naive && f.cut.numClipPlanes == 0 && !f.cut.cropping;
}

/// VTK's blend coefficient between the gradient shading (0) and the scattered light (1) for a
/// sample of opacity a and gradient magnitude G: b exp(-b G a) for b < 1, else
/// (2 - b) exp(-b G a) + b - 1 (b = VolumetricScatteringBlending; 1 at b = 2).
SS_FUNC float scatterBlend(float b, float G, float a) {
  const float e = expf(-b * G * a);
  return b < 1.f ? b * e : (2.f - b) * e + (b - 1.f);
}

}  // namespace spaceskip

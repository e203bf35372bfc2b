// SIMD ray packets for the oneTBB backend (CpuMarch.h). Compiled once per instruction set by
// Highway's foreach_target; the scalar parts (ray set-up, odd pixels) are compiled once.
// The build compiles this file with -ffp-contract=off: a fused multiply-add would round the
// samples differently from the scalar integrator.
#include "src/CpuMarch.h"

#include "spaceskip/render/Integrator.h"

#include <cmath>
#include <cstring>

#ifndef SPACESKIP_CPU_MARCH_ONCE
#define SPACESKIP_CPU_MARCH_ONCE
namespace spaceskip {
namespace march_detail {

/// The most drawn parts of one ray: the cropping planes cut it into at most seven pieces.
constexpr int kMaxParts = 7;

/// One ray's share of a packet, set up as renderPixel sets it up: the ray (index space), the
/// lattice anchor t0, the drawn parts of the ray (the box cut by the clipping planes, then by
/// the cropping regions: renderPixel's calls of its march, front to back) and, in shaded
/// frames, the light and view directions of the headlight model (rayLighting) and the ray in
/// world space (the light list's view vector, IntervalMarcher::worldAt).
struct LaneSetup {
  enum Kind { Empty, Packet, Scalar } kind;
  Ray r;
  vec3f inv;
  float t0;
  int numParts;
  float part[2 * kMaxParts];  ///< [a, b) of each drawn part
  vec3f light, view, orgW, dirW;
};

/// renderPixel up to its march. Empty: nothing drawn (renderPixel returns 0). Scalar: a pixel
/// the packet leaves to renderPixel (its first sample lies past the box's exit, or sample
/// indices too large for exact float lanes).
inline LaneSetup setupLane(const FrameView& f, int px, int py) {
  LaneSetup s{};
  const PrimaryRay p = primaryRay(f, px, py);
  s.kind = LaneSetup::Empty;
  if (!(p.tEnter < p.tExit)) return s;
  float lead =
      f.firstSample * f.dt + (f.jitter ? f.dt * float(hashPixel(px, py, f.jitterSeed) >> 8) * (1.f / 16777216.f) : 0.f);
  float a = p.tEnter, b = p.tExit;
  if (f.cut.numClipPlanes != 0 && !clipToPlanes(f.cut, p.r, a, b)) return s;
  if (f.cut.cropping) {
    lead -= f.firstSample * f.dt;  // cropped rays start on the first drawn region's face
    forEachCroppedInterval(f.cut, p.r, a, b, [&](float x, float y) {
      s.part[2 * s.numParts] = x;
      s.part[2 * s.numParts + 1] = y;
      return ++s.numParts < kMaxParts;
    });
    if (s.numParts == 0) return s;
  } else {
    if (f.firstSample > 0.f && !(a + lead < b)) {
      s.kind = LaneSetup::Scalar;
      return s;
    }
    s.part[0] = a;
    s.part[1] = b;
    s.numParts = 1;
  }
  const float t0 = s.part[0] + lead;  // anchored where the first drawn part starts
  // Every run of the ray lies in its drawn parts: its sample indices are at most this one's.
  const int64_t kEnd = sampleIndexCeil((s.part[2 * s.numParts - 1] - t0) / f.dt);
  constexpr int64_t kExact = int64_t(1) << 24;  // float(k) exact in a float lane
  if (kEnd > kExact) {
    s.kind = LaneSetup::Scalar;
    return s;
  }
  s.kind = LaneSetup::Packet;
  s.r = p.r;
  s.inv = p.inv;
  s.t0 = t0;
  if (f.shade) {
    rayLighting(f, p, s.light, s.view);
    s.orgW = p.nearW;
    s.dirW = p.dirW;
  }
  return s;
}

/// The Naive traversal as an iterator: the whole drawn part of the ray, one interval.
struct WholeIter {
  float a, b;
  bool done;
  template <class Marcher>
  Step next(const Marcher&, float& x, float& y) {
    if (done) return Step::Done;
    done = true;
    x = a;
    y = b;
    return Step::Interval;
  }
};

/// Stands in for the marcher the iterators ask which bricks are active: in plain frames every
/// occupied brick is (IntervalMarcher::active with Plain).
struct PlainMarcher {
  bool active(float, float) const { return true; }
};

/// IntervalMarcher::marchRuns for one lane, a run at a time: touching intervals merged into
/// runs, and the samples of each run as IntervalMarcher::range gives them (never one twice).
template <class Iter>
struct LaneRuns {
  Iter it;
  float ra = 0.f, rb = 0.f;
  bool have = false, done = false;
  int64_t nextK = 0;
  float wa = 0.f, wb = 0.f;  ///< the drawn part of the ray the iterator walks (snapToDrawn)

  /// The next run with samples: k in [kBegin, kEnd). false: the ray has no samples left.
  bool next(float t0, float dt, int64_t& kBegin, int64_t& kEnd) {
    float a, b;
    while (run(a, b)) {
      snapToDrawn(a, b, wa, wb);
      kBegin = sampleIndexCeil((a - t0) / dt);
      kEnd = sampleIndexCeil((b - t0) / dt);
      if (kBegin < nextK) kBegin = nextK;
      if (kEnd > nextK) nextK = kEnd;
      if (kBegin < kEnd) return true;
    }
    return false;
  }

  bool run(float& a, float& b) {
    const PlainMarcher m;
    while (!done) {
      float x = 0.f, y = 0.f;
      const Step st = it.next(m, x, y);
      if (st == Step::Done) {
        done = true;
        break;
      }
      if (st != Step::Interval) continue;
      if (have && x == rb) {
        rb = y;
        continue;
      }
      const bool had = have;
      a = ra;
      b = rb;
      ra = x;
      rb = y;
      have = true;
      if (had) return true;
    }
    if (!have) return false;
    a = ra;
    b = rb;
    have = false;
    return true;
  }
};

/// The traversal iterator of frame `f` over [a, b) of ray r, as renderPixel's march starts it.
inline void initIter(WholeIter& it, const FrameView&, const Ray&, vec3f, float a, float b) { it = WholeIter{a, b, false}; }
inline void initIter(GridIter& it, const FrameView& f, const Ray& r, vec3f inv, float a, float b) {
  it.init(f.grid, r, inv, a, b);
}
inline void initIter(GridPartsIter& it, const FrameView& f, const Ray& r, vec3f inv, float a, float b) {
  it.init(f.grid, r, inv, a, b);
}
inline void initIter(TreeIter& it, const FrameView& f, const Ray& r, vec3f inv, float a, float b) {
  it.init(f.tree, r, inv, a, b);
}
inline void initIter(HybridIter& it, const FrameView& f, const Ray& r, vec3f inv, float a, float b) {
  it.init(f.tree, f.grid, r, inv, a, b);
}

/// A lane's walk over its drawn parts: the runs of each part (LaneRuns), a fresh traversal per
/// part as renderPixel's march starts one, the samples taken so far kept (nextK).
template <class Iter>
struct LaneParts {
  LaneSetup s;
  int part = 0;
  LaneRuns<Iter> runs;

  void start(const FrameView& f, const LaneSetup& setup) {
    s = setup;
    part = -1;
    runs = LaneRuns<Iter>{};
    nextPart(f);
  }
  void nextPart(const FrameView& f) {
    ++part;
    const int64_t taken = runs.nextK;
    runs = LaneRuns<Iter>{};
    runs.nextK = taken;
    runs.wa = s.part[2 * part];
    runs.wb = s.part[2 * part + 1];
    initIter(runs.it, f, s.r, s.inv, runs.wa, runs.wb);
  }
  /// The next run with samples, k in [kBegin, kEnd); false: the ray has none left.
  bool next(const FrameView& f, int64_t& kBegin, int64_t& kEnd) {
    for (;;) {
      if (runs.next(s.t0, f.dt, kBegin, kEnd)) return true;
      if (part + 1 >= s.numParts) return false;
      nextPart(f);
    }
  }
};

template <class T>
vec4f scalarPixel(const FrameView& f, const T* v, int64_t nx, int64_t ny, int64_t nz, int px, int py) {
  const ArraySampler<T> s{v, nx, ny, nz};
  return isPlainFrame(f) ? renderPixel<ArraySampler<T>, -1, true>(f, s, px, py)
                         : renderPixel<ArraySampler<T>, -1, false>(f, s, px, py);
}

/// Composite frames the packets take, with or without clipping planes and cropping: unshaded,
/// or shaded with the headlight model or the light list (ParaView's light kit, positional and
/// spot lights); the 1-D transfer function, gradient opacity or a 2-D transfer function over
/// the gradient magnitude (not over a second array: two components); no scattering.
inline bool packetFrame(const FrameView& f) {
  if (!(f.blend == BlendMode::Composite && f.gtf.mode >= 0 && f.gtf.mode <= 2)) return false;
  if (!f.shade) return true;
  return !f.scatter.on;
}

}  // namespace march_detail
}  // namespace spaceskip
#endif  // SPACESKIP_CPU_MARCH_ONCE

#ifdef SPACESKIP_HAVE_HWY
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "src/CpuMarch.cpp"
#include <hwy/foreach_target.h>  // re-includes this file once per target
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace spaceskip {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using DU = hn::RebindToUnsigned<DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;
using MF = hn::Mask<DF>;

/// ss_clamp(v, lo, hi) lane by lane: v < lo ? lo : (v > hi ? hi : v).
HWY_INLINE VF Clamp(VF v, VF lo, VF hi) {
  return hn::IfThenElse(hn::Lt(v, lo), lo, hn::IfThenElse(hn::Gt(v, hi), hi, v));
}

/// base[i] and base[i + 1] for each lane: one 64-bit gather per pair of lanes' pairs (half the
/// elements of two 32-bit gathers), split into the two vectors.
HWY_INLINE void GatherPairs(const float* base, VI i, VF& v0, VF& v1) {
  const DF df;
#if HWY_TARGET == HWY_SCALAR
  const DI di;
  v0 = hn::GatherIndex(df, base, i);
  v1 = hn::GatherIndex(df, base, hn::Add(i, hn::Set(di, 1)));
#else
  const hn::Repartition<int64_t, DF> d64;
  const hn::Half<DI> dh;
  const auto off0 = hn::ShiftLeft<2>(hn::PromoteTo(d64, hn::LowerHalf(dh, i)));
  const auto off1 = hn::ShiftLeft<2>(hn::PromoteTo(d64, hn::UpperHalf(dh, i)));
  const int64_t* b = reinterpret_cast<const int64_t*>(base);
  const VF lo = hn::BitCast(df, hn::GatherOffset(d64, b, off0));  // lanes 0..N/2-1: (v0, v1) pairs
  const VF hi = hn::BitCast(df, hn::GatherOffset(d64, b, off1));
  v0 = hn::ConcatEven(df, hi, lo);
  v1 = hn::ConcatOdd(df, hi, lo);
#endif
}

/// The voxels at index i and i + 1 (x and x + 1 of a row), as voxelValue() gives them.
HWY_INLINE void FetchPair(const float* d, VI i, VF& v0, VF& v1) {
  const DF df;
  const VF big = hn::Set(df, 1.2676506e30f), nbig = hn::Set(df, -1.2676506e30f);
  VF a, b;
  GatherPairs(d, i, a, b);
  v0 = hn::IfThenElse(hn::Gt(a, big), big, hn::IfThenElse(hn::Lt(a, nbig), nbig, a));
  v1 = hn::IfThenElse(hn::Gt(b, big), big, hn::IfThenElse(hn::Lt(b, nbig), nbig, b));
}
// 16-bit voxels: one 32-bit gather at voxel i holds voxels i and i + 1 (little endian), never
// reading past voxel i + 1.
HWY_INLINE void FetchPair(const uint16_t* d, VI i, VF& v0, VF& v1) {
  const DF df;
  const DI di;
  const DU du;
  const VI w = hn::GatherOffset(di, reinterpret_cast<const int32_t*>(d), hn::ShiftLeft<1>(i));
  v0 = hn::ConvertTo(df, hn::And(w, hn::Set(di, 0xFFFF)));
  v1 = hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<16>(hn::BitCast(du, w))));
}
HWY_INLINE void FetchPair(const int16_t* d, VI i, VF& v0, VF& v1) {
  const DF df;
  const DI di;
  const VI w = hn::GatherOffset(di, reinterpret_cast<const int32_t*>(d), hn::ShiftLeft<1>(i));
  v0 = hn::ConvertTo(df, hn::ShiftRight<16>(hn::ShiftLeft<16>(w)));
  v1 = hn::ConvertTo(df, hn::ShiftRight<16>(w));
}
// 8-bit voxels: the 32-bit word at byte max(i - 2, 0) holds voxels i and i + 1 and ends no
// later than voxel i + 1 (or voxel 3 for i < 2; volumes have at least 8 voxels here).
HWY_INLINE hn::Vec<DU> BytePairWord(const void* d, VI i) {
  const DI di;
  const DU du;
  const VI off = hn::Max(hn::Sub(i, hn::Set(di, 2)), hn::Zero(di));
  const VI w = hn::GatherOffset(di, static_cast<const int32_t*>(d), off);
  return hn::BitCast(du, w) >> hn::BitCast(du, hn::ShiftLeft<3>(hn::Sub(i, off)));
}
HWY_INLINE void FetchPair(const uint8_t* d, VI i, VF& v0, VF& v1) {
  const DF df;
  const DI di;
  const DU du;
  const auto w = BytePairWord(d, i);
  v0 = hn::ConvertTo(df, hn::BitCast(di, hn::And(w, hn::Set(du, 0xFFu))));
  v1 = hn::ConvertTo(df, hn::BitCast(di, hn::And(hn::ShiftRight<8>(w), hn::Set(du, 0xFFu))));
}
HWY_INLINE void FetchPair(const int8_t* d, VI i, VF& v0, VF& v1) {
  const DF df;
  const DI di;
  const VI w = hn::BitCast(di, BytePairWord(d, i));
  v0 = hn::ConvertTo(df, hn::ShiftRight<24>(hn::ShiftLeft<24>(w)));
  v1 = hn::ConvertTo(df, hn::ShiftRight<24>(hn::ShiftLeft<16>(w)));
}

/// ArraySampler::axis for a vector of coordinates (n >= 2): i0 and the fraction.
HWY_INLINE void Axis(VF p, VF hiF, VI hiI, VI& i0, VF& fr) {
  const DF df;
  const DI di;
  const VF x = Clamp(p, hn::Zero(df), hiF);
  i0 = hn::Min(hn::ConvertTo(di, x), hiI);
  fr = hn::Sub(x, hn::ConvertTo(df, i0));
}

constexpr size_t kMaxLanes = HWY_MAX_BYTES / sizeof(float);

/// A packet's rays, lane by lane: each one's ray, lattice anchor t0, current run of samples
/// [kc, ke) and where its pixel goes (outAt, -1: nowhere). What the march needs of a packet,
/// whatever its traversal (PacketLanes adds that).
struct PacketRays {
  HWY_ALIGN float ox[kMaxLanes], oy[kMaxLanes], oz[kMaxLanes], dx[kMaxLanes], dy[kMaxLanes], dz[kMaxLanes],
      t0[kMaxLanes];
  // Shaded frames: the headlight model's light and view directions, the ray in world space.
  HWY_ALIGN float lx[kMaxLanes], ly[kMaxLanes], lz[kMaxLanes], vx[kMaxLanes], vy[kMaxLanes], vz[kMaxLanes],
      wox[kMaxLanes], woy[kMaxLanes], woz[kMaxLanes], wdx[kMaxLanes], wdy[kMaxLanes], wdz[kMaxLanes];
  HWY_ALIGN int32_t kc[kMaxLanes], ke[kMaxLanes];
  int64_t outAt[kMaxLanes];

  /// Lane l's ray, anchor and shading vectors from its set-up.
  void put(size_t l, const march_detail::LaneSetup& s) {
    auto put3 = [l](float* x, float* y, float* z, vec3f v) { x[l] = v.x, y[l] = v.y, z[l] = v.z; };
    put3(ox, oy, oz, s.r.org);
    put3(dx, dy, dz, s.r.dir);
    put3(lx, ly, lz, s.light);
    put3(vx, vy, vz, s.view);
    put3(wox, woy, woz, s.orgW);
    put3(wdx, wdy, wdz, s.dirW);
    t0[l] = s.t0;
  }
};

/// A packet's rays and each lane's traversal (its drawn parts and their runs).
template <class Iter>
struct PacketLanes : PacketRays {
  march_detail::LaneParts<Iter> runs[kMaxLanes];
};

/// The pixel at (x, y) as the scalar integrator draws it (march_detail::scalarPixel for the
/// frame's voxel type): pixels a packet leaves to renderPixel.
using ScalarPixelFn = vec4f (*)(const FrameView&, const void* vox, int64_t nx, int64_t ny, int64_t nz, int x, int y);
/// Gives the lanes whose run is used up (kc == ke, stop[l] == 0) their next run.
using AdvanceFn = void (*)(const FrameView&, PacketRays&, const int32_t* stop);

/// Sets up the packet of pixels from (bx, by) (bw wide, clipped to x1, y1), lane by lane. Empty
/// pixels and those left to renderPixel are written at once. false: no lane marches.
/// Not inlined, and independent of the voxel type: one copy per traversal and target.
template <class Iter>
HWY_NOINLINE bool SetupPacket(const FrameView& f, ScalarPixelFn scalar, const void* vox, int64_t nx, int64_t ny,
                              int64_t nz, int bx, int by, int bw, int x1, int y1, vec4f* px, PacketLanes<Iter>& P) {
  using march_detail::LaneSetup;
  const size_t N = hn::Lanes(DF());
  bool any = false;
  for (size_t l = 0; l < N; ++l) {
    const int x = bx + int(l) % bw, y = by + int(l) / bw;
    P.kc[l] = P.ke[l] = 0;
    const LaneSetup none{};
    P.put(l, none);
    P.outAt[l] = -1;
    if (x >= x1 || y >= y1) continue;
    const int64_t at = int64_t(y) * f.width + x;
    const LaneSetup s = march_detail::setupLane(f, x, y);
    if (s.kind == LaneSetup::Empty) {
      px[at] = vec4f{0, 0, 0, 0};
      continue;
    }
    if (s.kind == LaneSetup::Scalar) {
      px[at] = scalar(f, vox, nx, ny, nz, x, y);
      continue;
    }
    P.outAt[l] = at;
    P.put(l, s);
    P.runs[l].start(f, s);
    int64_t kb = 0, kEnd = 0;
    if (P.runs[l].next(f, kb, kEnd)) {
      P.kc[l] = int32_t(kb);
      P.ke[l] = int32_t(kEnd);
    }
    any = true;
  }
  return any;
}

/// AdvanceFn of traversal Iter (IntervalMarcher::marchRuns, lane by lane): lanes with no run
/// left get an empty one. Not inlined: the march calls it through a pointer when a lane's run
/// is used up, so that the march is compiled once per voxel type, not per type and traversal.
template <class Iter>
HWY_NOINLINE void AdvanceLanes(const FrameView& f, PacketRays& R, const int32_t* stop) {
  PacketLanes<Iter>& P = static_cast<PacketLanes<Iter>&>(R);
  const size_t N = hn::Lanes(DF());
  for (size_t l = 0; l < N; ++l) {
    if (stop[l] || P.kc[l] < P.ke[l]) continue;
    int64_t kb = 0, kx = 0;
    if (P.runs[l].next(f, kb, kx)) {
      P.kc[l] = int32_t(kb);
      P.ke[l] = int32_t(kx);
    } else {
      P.kc[l] = P.ke[l] = 0;
    }
  }
}

/// Lanes whose run is used up (and that have not stopped) take their next run; lanes with none
/// left stop.
HWY_INLINE void NextRuns(const FrameView& f, PacketRays& P, AdvanceFn advance, VI& k, VI& kEnd, MF& stopped) {
  const DF df;
  const DI di;
  hn::Store(k, di, P.kc);
  hn::Store(kEnd, di, P.ke);
  HWY_ALIGN int32_t stop[kMaxLanes];
  hn::Store(hn::VecFromMask(di, hn::RebindMask(di, stopped)), di, stop);
  advance(f, P, stop);
  k = hn::Load(di, P.kc);
  kEnd = hn::Load(di, P.ke);
  stopped = hn::Or(stopped, hn::RebindMask(df, hn::Not(hn::Lt(k, kEnd))));
}

/// ArraySampler::sample at points (x, y, z) of the index space: trilinear between the eight
/// voxels around each point.
template <class T>
HWY_INLINE VF Sample(const T* vox, int64_t nx, int64_t ny, int64_t nz, VF x, VF y, VF z) {
  const DF df;
  const DI di;
  const VF hx = hn::Set(df, float(nx - 1)), hy = hn::Set(df, float(ny - 1)), hz = hn::Set(df, float(nz - 1));
  const VI mx = hn::Set(di, int32_t(nx - 2)), my = hn::Set(di, int32_t(ny - 2)), mz = hn::Set(di, int32_t(nz - 2));
  const VI sy = hn::Set(di, int32_t(nx)), sz = hn::Set(di, int32_t(nx * ny));
  const VI sxy = hn::Set(di, int32_t(nx + nx * ny));
  const VI nyv = hn::Set(di, int32_t(ny));
  VI ix, iy, iz;
  VF fx, fy, fz;
  Axis(x, hx, mx, ix, fx);
  Axis(y, hy, my, iy, fy);
  Axis(z, hz, mz, iz, fz);
  const VI base = hn::Add(ix, hn::Mul(sy, hn::Add(iy, hn::Mul(nyv, iz))));
  VF v000, v100, v010, v110, v001, v101, v011, v111;
  FetchPair(vox, base, v000, v100);
  FetchPair(vox, hn::Add(base, sy), v010, v110);
  FetchPair(vox, hn::Add(base, sz), v001, v101);
  FetchPair(vox, hn::Add(base, sxy), v011, v111);
  const VF c00 = hn::Add(v000, hn::Mul(hn::Sub(v100, v000), fx));
  const VF c10 = hn::Add(v010, hn::Mul(hn::Sub(v110, v010), fx));
  const VF c01 = hn::Add(v001, hn::Mul(hn::Sub(v101, v001), fx));
  const VF c11 = hn::Add(v011, hn::Mul(hn::Sub(v111, v011), fx));
  const VF c0 = hn::Add(c00, hn::Mul(hn::Sub(c10, c00), fy));
  const VF c1 = hn::Add(c01, hn::Mul(hn::Sub(c11, c01), fy));
  return hn::Add(c0, hn::Mul(hn::Sub(c1, c0), fz));
}

/// The lanes' ray position, light and view (headlight model), rays and volume: what shading a
/// sample needs.
template <class T>
struct LaneShading {
  const T* vox;
  int64_t nx, ny, nz;
  VF x, y, z;     ///< the samples' positions (index space)
  VF lx, ly, lz;  ///< towards the light (rayLighting), world space
  VF vx, vy, vz;  ///< towards the eye (rayLighting), world space
  VF ox, oy, oz, dx, dy, dz;      ///< the ray, index space
  VF wox, woy, woz, wdx, wdy, wdz;  ///< the ray, world space (primaryRay's nearW, dirW)
};

HWY_INLINE VF Dot(VF ax, VF ay, VF az, VF bx, VF by, VF bz) {
  return hn::Add(hn::Add(hn::Mul(ax, bx), hn::Mul(ay, by)), hn::Mul(az, bz));
}

/// normalize() lane by lane: a / |a| where |a| > 0, else a unchanged.
HWY_INLINE void Normalize(VF& x, VF& y, VF& z) {
  const DF df;
  const VF l = hn::Sqrt(Dot(x, y, z, x, y, z));
  const MF pos = hn::Gt(l, hn::Zero(df));
  const VF inv = hn::Div(hn::Set(df, 1.f), l);
  x = hn::IfThenElse(pos, hn::Mul(x, inv), x);
  y = hn::IfThenElse(pos, hn::Mul(y, inv), y);
  z = hn::IfThenElse(pos, hn::Mul(z, inv), z);
}

/// powf(x, power) where x > 0, else 0: the C library's powf lane by lane (a vector power
/// would round differently from the scalar integrator's).
HWY_INLINE VF PowLanes(VF x, float power) {
  const DF df;
  HWY_ALIGN float a[kMaxLanes];
  hn::Store(x, df, a);
  for (size_t l = 0; l < hn::Lanes(df); ++l) a[l] = a[l] > 0.f ? powf(a[l], power) : 0.f;
  return hn::Load(df, a);
}

/// A positional light's direction of travel (ld) and attenuation (att) at world positions
/// (px, py, pz), lane by lane with IntervalMarcher::shadeLights' scalar code (its powf of the
/// spot falloff included).
HWY_INLINE void PositionalLanes(const LightView& L, VF px, VF py, VF pz, VF& ldx, VF& ldy, VF& ldz, VF& att) {
  const DF df;
  HWY_ALIGN float x[kMaxLanes], y[kMaxLanes], z[kMaxLanes], a[kMaxLanes];
  hn::Store(px, df, x);
  hn::Store(py, df, y);
  hn::Store(pz, df, z);
  for (size_t l = 0; l < hn::Lanes(df); ++l) {
    vec3f ld;
    positionalLight(L, vec3f{x[l], y[l], z[l]}, ld, a[l]);
    x[l] = ld.x, y[l] = ld.y, z[l] = ld.z;
  }
  ldx = hn::Load(df, x);
  ldy = hn::Load(df, y);
  ldz = hn::Load(df, z);
  att = hn::Load(df, a);
}

/// IntervalMarcher::shadeColor of colours (r, g, b) for the shaded frames packetFrame accepts:
/// the central differences one voxel apart, then shadeGradient with the headlight model or
/// shadeLights over the light list, clamped to [0, 1]; each lane with the scalar integrator's
/// float operations in its order.
template <class T>
HWY_INLINE void ShadeLanes(const FrameView& f, const LaneShading<T>& S, VF& r, VF& g, VF& b) {
  const DF df;
  const VF one = hn::Set(df, 1.f), zero = hn::Zero(df);
  // p + vec3f{1, 0, 0} adds 0.f to the other coordinates (which turns -0 into +0); p - {1, 0, 0}
  // subtracts it (which changes nothing).
  const VF xp = hn::Add(S.x, zero), yp = hn::Add(S.y, zero), zp = hn::Add(S.z, zero);
  const VF gx = hn::Sub(Sample(S.vox, S.nx, S.ny, S.nz, hn::Add(S.x, one), yp, zp),
                        Sample(S.vox, S.nx, S.ny, S.nz, hn::Sub(S.x, one), S.y, S.z));
  const VF gy = hn::Sub(Sample(S.vox, S.nx, S.ny, S.nz, xp, hn::Add(S.y, one), zp),
                        Sample(S.vox, S.nx, S.ny, S.nz, S.x, hn::Sub(S.y, one), S.z));
  const VF gz = hn::Sub(Sample(S.vox, S.nx, S.ny, S.nz, xp, yp, hn::Add(S.z, one)),
                        Sample(S.vox, S.nx, S.ny, S.nz, S.x, S.y, hn::Sub(S.z, one)));
  // shadeGradient: the gradient to world space, normalised (zero where its length is not > 0).
  const float* M = f.worldToIndex;
  auto row = [&](float a, float b2, float c) {
    return hn::Add(hn::Add(hn::Mul(hn::Set(df, a), gx), hn::Mul(hn::Set(df, b2), gy)), hn::Mul(hn::Set(df, c), gz));
  };
  VF n0 = row(M[0], M[4], M[8]), n1 = row(M[1], M[5], M[9]), n2 = row(M[2], M[6], M[10]);
  const VF len = hn::Sqrt(Dot(n0, n1, n2, n0, n1, n2));
  const MF pos = hn::Gt(len, zero);
  const VF inv = hn::Div(one, len);
  n0 = hn::IfThenElseZero(pos, hn::Mul(n0, inv));
  n1 = hn::IfThenElseZero(pos, hn::Mul(n1, inv));
  n2 = hn::IfThenElseZero(pos, hn::Mul(n2, inv));
  const bool specular = f.specular != 0.f;  // ParaView's default Specular 0: no reflection, no powf
  if (!f.useLights) {  // the headlight model: ambient + diffuse |n.l| + the reflection's specular
    const VF nl = hn::Neg(Dot(n0, n1, n2, S.lx, S.ly, S.lz));
    VF spec = zero;
    if (specular) {
      const VF t2 = hn::Mul(hn::Set(df, 2.f), nl);
      VF rx = hn::Add(hn::Mul(n0, t2), S.lx), ry = hn::Add(hn::Mul(n1, t2), S.ly), rz = hn::Add(hn::Mul(n2, t2), S.lz);
      Normalize(rx, ry, rz);
      const VF vr = hn::Neg(Dot(rx, ry, rz, S.vx, S.vy, S.vz));
      spec = hn::Mul(hn::Set(df, f.specular), PowLanes(vr, f.specularPower));
    }
    const VF k = hn::Add(hn::Set(df, f.ambient), hn::Mul(hn::Set(df, f.diffuse), hn::Abs(nl)));
    r = Clamp(hn::Add(hn::Mul(k, r), spec), zero, one);
    g = Clamp(hn::Add(hn::Mul(k, g), spec), zero, one);
    b = Clamp(hn::Add(hn::Mul(k, b), spec), zero, one);
    return;
  }
  // shadeLights over the light list: directional lights (attenuation 1) in vectors, a positional
  // light's direction and attenuation lane by lane (PositionalLanes).
  bool positional = false;
  for (int i = 0; i < f.numLights; ++i) positional = positional || f.lights[i].positional != 0;
  VF vx = zero, vy = zero, vz = zero;  // eye -> sample, world space (IntervalMarcher::worldAt)
  VF wx = zero, wy = zero, wz = zero;  // the sample, world space
  if (specular || positional) {
    const VF ex = hn::Sub(S.x, S.ox), ey = hn::Sub(S.y, S.oy), ez = hn::Sub(S.z, S.oz);
    const VF t = hn::Div(Dot(ex, ey, ez, S.dx, S.dy, S.dz), Dot(S.dx, S.dy, S.dz, S.dx, S.dy, S.dz));
    wx = hn::Add(S.wox, hn::Mul(S.wdx, t));
    wy = hn::Add(S.woy, hn::Mul(S.wdy, t));
    wz = hn::Add(S.woz, hn::Mul(S.wdz, t));
  }
  if (specular) {
    vx = hn::Sub(wx, hn::Set(df, f.eyeW.x));
    vy = hn::Sub(wy, hn::Set(df, f.eyeW.y));
    vz = hn::Sub(wz, hn::Set(df, f.eyeW.z));
    Normalize(vx, vy, vz);
  }
  VF d0 = zero, d1 = zero, d2 = zero, s0 = zero, s1 = zero, s2 = zero;
  for (int i = 0; i < f.numLights; ++i) {
    const LightView& L = f.lights[i];
    VF ldx = hn::Set(df, L.dir.x), ldy = hn::Set(df, L.dir.y), ldz = hn::Set(df, L.dir.z), att = one;
    if (L.positional) PositionalLanes(L, wx, wy, wz, ldx, ldy, ldz, att);
    VF nl = Dot(n0, n1, n2, ldx, ldy, ldz);
    if (f.twoSided) nl = hn::IfThenElse(hn::Lt(nl, zero), hn::Neg(nl), nl);
    const MF lit = hn::Gt(nl, zero);
    VF m = nl;  // ss_max(0, att * nl): nl itself where att is 1
    if (L.positional) {
      m = hn::Mul(att, nl);
      m = hn::IfThenElse(hn::Gt(zero, m), zero, m);
    }
    d0 = hn::IfThenElse(lit, hn::Add(d0, hn::Mul(hn::Set(df, L.diffuse.x), m)), d0);
    d1 = hn::IfThenElse(lit, hn::Add(d1, hn::Mul(hn::Set(df, L.diffuse.y), m)), d1);
    d2 = hn::IfThenElse(lit, hn::Add(d2, hn::Mul(hn::Set(df, L.diffuse.z), m)), d2);
    if (!specular || hn::AllFalse(df, lit)) continue;
    const VF t2 = hn::Mul(hn::Set(df, 2.f), nl);
    VF rx = hn::Sub(hn::Mul(n0, t2), ldx), ry = hn::Sub(hn::Mul(n1, t2), ldy), rz = hn::Sub(hn::Mul(n2, t2), ldz);
    Normalize(rx, ry, rz);
    VF rv = Dot(vx, vy, vz, rx, ry, rz);
    if (L.positional && f.twoSided) rv = hn::IfThenElse(hn::Lt(rv, zero), hn::Neg(rv), rv);
    const MF up = hn::And(lit, hn::Gt(rv, zero));
    VF pw = PowLanes(hn::IfThenElseZero(lit, rv), f.specularPower);
    if (L.positional) pw = hn::Mul(att, pw);
    s0 = hn::IfThenElse(up, hn::Add(s0, hn::Mul(hn::Set(df, L.specular.x), pw)), s0);
    s1 = hn::IfThenElse(up, hn::Add(s1, hn::Mul(hn::Set(df, L.specular.y), pw)), s1);
    s2 = hn::IfThenElse(up, hn::Add(s2, hn::Mul(hn::Set(df, L.specular.z), pw)), s2);
  }
  const vec3f a = f.lightAmbient;
  const VF kd = hn::Set(df, f.diffuse), ks = hn::Set(df, f.specular);
  r = Clamp(hn::Add(hn::Add(hn::Set(df, f.ambient * a.x), hn::Mul(hn::Mul(kd, d0), r)), specular ? hn::Mul(ks, s0) : zero),
            zero, one);
  g = Clamp(hn::Add(hn::Add(hn::Set(df, f.ambient * a.y), hn::Mul(hn::Mul(kd, d1), g)), specular ? hn::Mul(ks, s1) : zero),
            zero, one);
  b = Clamp(hn::Add(hn::Add(hn::Set(df, f.ambient * a.z), hn::Mul(hn::Mul(kd, d2), b)), specular ? hn::Mul(ks, s2) : zero),
            zero, one);
}

/// gradientMagnitude (render/GradientTF.h) lane by lane at the lanes' positions: VTK's normalised
/// gradient magnitude in [0, 1] (NaN: 0), with the scalar code's central differences.
template <class T>
HWY_INLINE VF GradientMagnitudeLanes(const FrameView& f, const LaneShading<T>& S) {
  const DF df;
  const VF one = hn::Set(df, 1.f), zero = hn::Zero(df);
  // p + vec3f{1, 0, 0} adds 0.f to the other coordinates, as in ShadeLanes.
  const VF xp = hn::Add(S.x, zero), yp = hn::Add(S.y, zero), zp = hn::Add(S.z, zero);
  const float* k = f.gtf.gradScale;
  const VF gx = hn::Mul(hn::Sub(Sample(S.vox, S.nx, S.ny, S.nz, hn::Add(S.x, one), yp, zp),
                                Sample(S.vox, S.nx, S.ny, S.nz, hn::Sub(S.x, one), S.y, S.z)),
                        hn::Set(df, k[0]));
  const VF gy = hn::Mul(hn::Sub(Sample(S.vox, S.nx, S.ny, S.nz, xp, hn::Add(S.y, one), zp),
                                Sample(S.vox, S.nx, S.ny, S.nz, S.x, hn::Sub(S.y, one), S.z)),
                        hn::Set(df, k[1]));
  const VF gz = hn::Mul(hn::Sub(Sample(S.vox, S.nx, S.ny, S.nz, xp, yp, hn::Add(S.z, one)),
                                Sample(S.vox, S.nx, S.ny, S.nz, S.x, S.y, hn::Sub(S.z, one))),
                        hn::Set(df, k[2]));
  const VF m = hn::Sqrt(hn::Add(hn::Add(hn::Mul(gx, gx), hn::Mul(gy, gy)), hn::Mul(gz, gz)));
  return hn::IfThenZeroElse(hn::IsNaN(m), Clamp(m, zero, one));
}

/// texelAxis (render/GradientTF.h) lane by lane: the entries i0, i1 of `n` and the weight at
/// texel-centred positions x (not NaN).
HWY_INLINE void TexelAxisLanes(VF x, int n, VI& i0, VI& i1, VF& w) {
  const DF df;
  const DI di;
  x = Clamp(x, hn::Zero(df), hn::Set(df, float(n - 1)));
  i0 = hn::ConvertTo(di, x);
  i1 = hn::Min(hn::Add(i0, hn::Set(di, 1)), hn::Set(di, n - 1));
  w = hn::Sub(x, hn::ConvertTo(df, i0));
}

/// Channel `c` of entries `i` of the vec4f table at `T` (one gather).
HWY_INLINE VF TableChannel(const float* T, VI i, int c) {
  const DF df;
  return hn::GatherIndex(df, T + c, hn::ShiftLeft<2>(i));
}

/// a + (b - a) * w, as lerp4 and lookup() take it.
HWY_INLINE VF Lerp(VF a, VF b, VF w) { return hn::Add(a, hn::Mul(hn::Sub(b, a), w)); }

/// classifyWithGradient's 2-D table (mode 2) lane by lane: table2DAt at the column of value v
/// (not NaN) and the row of gradient magnitude gm.
HWY_INLINE void Table2DLanes(const FrameView& f, VF v, VF gm, VF& r, VF& g, VF& b, VF& a) {
  const DF df;
  const GradientTFView& G = f.gtf;
  const float* T = reinterpret_cast<const float*>(f.tf.table + G.offset);
  const VF half = hn::Set(df, 0.5f);
  VI x0, x1, y0, y1;
  VF wx, wy;
  TexelAxisLanes(hn::Sub(hn::Mul(hn::Sub(v, hn::Set(df, G.xLo)), hn::Set(df, G.xScale)), half), G.width, x0, x1, wx);
  TexelAxisLanes(hn::Sub(hn::Mul(gm, hn::Set(df, float(G.height))), half), G.height, y0, y1, wy);
  const DI di;
  const VI w = hn::Set(di, G.width);
  const VI r0 = hn::Mul(y0, w), r1 = hn::Mul(y1, w);
  const VI ia = hn::Add(r0, x0), ib = hn::Add(r0, x1), ic = hn::Add(r1, x0), id = hn::Add(r1, x1);
  VF* out[4] = {&r, &g, &b, &a};
  for (int c = 0; c < 4; ++c) {
    const VF ab = Lerp(TableChannel(T, ia, c), TableChannel(T, ib, c), wx);
    const VF cd = Lerp(TableChannel(T, ic, c), TableChannel(T, id, c), wx);
    *out[c] = Lerp(ab, cd, wy);
  }
}

/// lookup() of samples v (or classifyWithGradient's gradient opacity or 2-D table) and
/// IntervalMarcher::composite into (ax, ay, az, aw) for the live lanes: NaN is transparent;
/// opacity first, colour only where a lane composites (shaded when `shade`); a lane that
/// composites and reaches the threshold stops. `S` holds the lanes' positions.
template <class T>
HWY_INLINE void LookupComposite(const FrameView& f, const float* pairs, VF v, MF live, const LaneShading<T>& S,
                                bool shade, VF& ax, VF& ay, VF& az, VF& aw, MF& stopped) {
  const DF df;
  const DI di;
  const VF onef = hn::Set(df, 1.f), ert = hn::Set(df, f.ertThreshold);
  const VF tfLo = hn::Set(df, f.tf.lo), tfScale = hn::Set(df, f.tf.scale), tfHi = hn::Set(df, float(f.tf.size - 1));
  const int64_t pairStride = 2 * int64_t(f.tf.size);  // floats per channel in `pairs`
  VF cx, cy, cz, cw;  // the sample's colour and opacity where it composites (comp)
  MF comp;
  if (f.gtf.mode == 2) {
    // The 2-D table at (value, gradient magnitude): colour and raw opacity (NaN: transparent).
    const MF nanV = hn::IsNaN(v);
    const MF any = hn::AndNot(nanV, live);
    if (hn::AllFalse(df, any)) return;
    Table2DLanes(f, hn::IfThenZeroElse(nanV, v), GradientMagnitudeLanes(f, S), cx, cy, cz, cw);
    comp = hn::And(any, hn::Gt(cw, hn::Zero(df)));
    if (hn::AllFalse(df, comp)) return;
  } else {
    VF xt = hn::Mul(hn::Sub(v, tfLo), tfScale);
    const MF nan = hn::IsNaN(xt);
    xt = Clamp(hn::IfThenZeroElse(nan, xt), hn::Zero(df), tfHi);
    const VI e0 = hn::ConvertTo(di, xt);
    const VF fr = hn::Sub(xt, hn::ConvertTo(df, e0));
    // Entry e0 and the next one (e1 = min(e0 + 1, size - 1)) side by side in the pair table.
    const VI q = hn::ShiftLeft<1>(e0);
    VF a0, a1;
    GatherPairs(pairs + 3 * pairStride, q, a0, a1);
    cw = hn::Add(a0, hn::Mul(hn::Sub(a1, a0), fr));
    comp = hn::And(live, hn::AndNot(nan, hn::Gt(cw, hn::Zero(df))));
    if (hn::AllFalse(df, comp)) return;
    if (f.gtf.mode == 1) {
      // Gradient opacity: the 1-D opacity times the table's factor at the gradient magnitude.
      const float* go = reinterpret_cast<const float*>(f.tf.table + f.gtf.offset);
      VI i0, i1;
      VF wg;
      TexelAxisLanes(hn::Sub(hn::Mul(GradientMagnitudeLanes(f, S), hn::Set(df, float(f.gtf.width))), hn::Set(df, 0.5f)),
                     f.gtf.width, i0, i1, wg);
      cw = hn::Mul(cw, Lerp(TableChannel(go, i0, 3), TableChannel(go, i1, 3), wg));
      comp = hn::And(comp, hn::Gt(cw, hn::Zero(df)));
      if (hn::AllFalse(df, comp)) return;
    }
    VF r0, r1, g0, g1, b0, b1;
    GatherPairs(pairs, q, r0, r1);
    GatherPairs(pairs + pairStride, q, g0, g1);
    GatherPairs(pairs + 2 * pairStride, q, b0, b1);
    cx = hn::Add(r0, hn::Mul(hn::Sub(r1, r0), fr));
    cy = hn::Add(g0, hn::Mul(hn::Sub(g1, g0), fr));
    cz = hn::Add(b0, hn::Mul(hn::Sub(b1, b0), fr));
  }
  if (shade) ShadeLanes(f, S, cx, cy, cz);
  // IntervalMarcher::composite, front-to-back "over".
  const VF w = hn::Mul(hn::Sub(onef, aw), cw);
  ax = hn::IfThenElse(comp, hn::Add(ax, hn::Mul(w, cx)), ax);
  ay = hn::IfThenElse(comp, hn::Add(ay, hn::Mul(w, cy)), ay);
  az = hn::IfThenElse(comp, hn::Add(az, hn::Mul(w, cz)), az);
  aw = hn::IfThenElse(comp, hn::Add(aw, w), aw);
  // Early ray termination after a composited sample: !(acc.w < threshold).
  stopped = hn::Or(stopped, hn::AndNot(hn::Lt(aw, ert), comp));
}

/// Marches the set-up packet P to the end (all lanes stopped) and writes its pixels; `advance`
/// gives the lanes their next runs (AdvanceLanes of the frame's traversal). Not inlined: one copy
/// per voxel type and target (the sampling, lookup and shading code is most of this file's
/// machine code and compile time).
template <class T>
HWY_NOINLINE void MarchPacket(const FrameView& f, const float* pairs, const T* vox, int64_t nx, int64_t ny,
                              int64_t nz, PacketRays& P, AdvanceFn advance, vec4f* px) {
  const DF df;
  const DI di;
  const size_t N = hn::Lanes(df);
  const VI one = hn::Set(di, 1);
  const VF dtv = hn::Set(df, f.dt);
  const VF vox_ = hn::Load(df, P.ox), voy = hn::Load(df, P.oy), voz = hn::Load(df, P.oz);
  const VF vdx = hn::Load(df, P.dx), vdy = hn::Load(df, P.dy), vdz = hn::Load(df, P.dz);
  const VF vt0 = hn::Load(df, P.t0);
  LaneShading<T> S{vox, nx, ny, nz, hn::Zero(df), hn::Zero(df), hn::Zero(df),
                   hn::Load(df, P.lx), hn::Load(df, P.ly), hn::Load(df, P.lz),
                   hn::Load(df, P.vx), hn::Load(df, P.vy), hn::Load(df, P.vz),
                   vox_, voy, voz, vdx, vdy, vdz,
                   hn::Load(df, P.wox), hn::Load(df, P.woy), hn::Load(df, P.woz),
                   hn::Load(df, P.wdx), hn::Load(df, P.wdy), hn::Load(df, P.wdz)};
  VI k = hn::Load(di, P.kc), kEnd = hn::Load(di, P.ke);
  VF ax = hn::Zero(df), ay = hn::Zero(df), az = hn::Zero(df), aw = hn::Zero(df);
  MF stopped = hn::RebindMask(df, hn::Not(hn::Lt(k, kEnd)));  // no samples, or terminated
  for (;;) {
    const MF spent = hn::AndNot(stopped, hn::RebindMask(df, hn::Not(hn::Lt(k, kEnd))));
    if (!hn::AllFalse(df, spent)) NextRuns(f, P, advance, k, kEnd, stopped);
    const MF live = hn::Not(stopped);
    if (hn::AllFalse(df, live)) break;
    // IntervalMarcher::take(k): t = t0 + float(k) * dt, p = org + dir * t.
    const VF t = hn::Add(vt0, hn::Mul(hn::ConvertTo(df, k), dtv));
    S.x = hn::Add(vox_, hn::Mul(vdx, t));
    S.y = hn::Add(voy, hn::Mul(vdy, t));
    S.z = hn::Add(voz, hn::Mul(vdz, t));
    const VF v = Sample(vox, nx, ny, nz, S.x, S.y, S.z);
    LookupComposite(f, pairs, v, live, S, f.shade, ax, ay, az, aw, stopped);
    k = hn::Add(k, one);
  }
  HWY_ALIGN float rx[kMaxLanes], ry[kMaxLanes], rz[kMaxLanes], rw[kMaxLanes];
  hn::Store(ax, df, rx);
  hn::Store(ay, df, ry);
  hn::Store(az, df, rz);
  hn::Store(aw, df, rw);
  for (size_t l = 0; l < N; ++l)
    if (P.outAt[l] >= 0) px[P.outAt[l]] = vec4f{rx[l], ry[l], rz[l], rw[l]};
}

template <class T>
vec4f ScalarPixelOf(const FrameView& f, const void* vox, int64_t nx, int64_t ny, int64_t nz, int x, int y) {
  return march_detail::scalarPixel(f, static_cast<const T*>(vox), nx, ny, nz, x, y);
}

template <class T, class Iter>
void MarchTileT(const FrameView& f, const float* pairs, const T* vox, int64_t nx, int64_t ny, int64_t nz, int x0,
                int y0, int x1, int y1, vec4f* px) {
  const size_t N = hn::Lanes(DF());
  // A packet is a block of pixels (4x4 for 16 lanes, 4x2 for 8, 2x2 for 4): neighbouring rays
  // have similar lengths and fetch neighbouring voxels.
  const int bw = N >= 8 ? 4 : (N >= 4 ? 2 : int(N));
  const int bh = int(N) / bw;
  PacketLanes<Iter> P;
  for (int by = y0; by < y1; by += bh)
    for (int bx = x0; bx < x1; bx += bw)
      if (SetupPacket(f, &ScalarPixelOf<T>, vox, nx, ny, nz, bx, by, bw, x1, y1, px, P))
        MarchPacket(f, pairs, vox, nx, ny, nz, P, &AdvanceLanes<Iter>, px);
}

template <class T>
void MarchTileOf(const FrameView& f, const float* pairs, const T* vox, int64_t nx, int64_t ny, int64_t nz, int x0,
                 int y0, int x1, int y1, vec4f* px) {
  switch (f.traversal) {
    case TraversalKind::Naive:
      return MarchTileT<T, march_detail::WholeIter>(f, pairs, vox, nx, ny, nz, x0, y0, x1, y1, px);
    case TraversalKind::Grid: return MarchTileT<T, GridIter>(f, pairs, vox, nx, ny, nz, x0, y0, x1, y1, px);
    case TraversalKind::GridParts:
      return MarchTileT<T, GridPartsIter>(f, pairs, vox, nx, ny, nz, x0, y0, x1, y1, px);
    case TraversalKind::Tree: return MarchTileT<T, TreeIter>(f, pairs, vox, nx, ny, nz, x0, y0, x1, y1, px);
    case TraversalKind::Hybrid: return MarchTileT<T, HybridIter>(f, pairs, vox, nx, ny, nz, x0, y0, x1, y1, px);
  }
}

void MarchTile(const FrameView& f, const float* pairs, VoxelType type, const void* voxels, int64_t nx, int64_t ny,
               int64_t nz, int x0, int y0, int x1, int y1, vec4f* px) {
  switch (type) {
    case VoxelType::UInt8:
      return MarchTileOf(f, pairs, static_cast<const uint8_t*>(voxels), nx, ny, nz, x0, y0, x1, y1, px);
    case VoxelType::Int8:
      return MarchTileOf(f, pairs, static_cast<const int8_t*>(voxels), nx, ny, nz, x0, y0, x1, y1, px);
    case VoxelType::UInt16:
      return MarchTileOf(f, pairs, static_cast<const uint16_t*>(voxels), nx, ny, nz, x0, y0, x1, y1, px);
    case VoxelType::Int16:
      return MarchTileOf(f, pairs, static_cast<const int16_t*>(voxels), nx, ny, nz, x0, y0, x1, y1, px);
    case VoxelType::Float32:
      return MarchTileOf(f, pairs, static_cast<const float*>(voxels), nx, ny, nz, x0, y0, x1, y1, px);
    case VoxelType::Float64: break;  // packetMarchable refuses it
  }
}

const char* TargetName() { return hwy::TargetName(HWY_TARGET); }

}  // namespace HWY_NAMESPACE
}  // namespace spaceskip
HWY_AFTER_NAMESPACE();
#endif  // SPACESKIP_HAVE_HWY

#if !defined(SPACESKIP_HAVE_HWY) || HWY_ONCE
namespace spaceskip {

#ifdef SPACESKIP_HAVE_HWY
HWY_EXPORT(MarchTile);
HWY_EXPORT(TargetName);
#endif

bool packetMarchable(const FrameView& f, VoxelType type, int components, int64_t nx, int64_t ny, int64_t nz) {
#ifdef SPACESKIP_HAVE_HWY
  if (!march_detail::packetFrame(f) || f.lattice.active || f.alphaIn || f.sampleCount || f.grid.vmin) return false;
  if (f.sampling != 0) return false;  // nearest and label sampling (render/LabelSampler.h)
  if (components != 1 || type == VoxelType::Float64) return false;
  // 32-bit gathers: float32 by index, the others by byte offset (voxel index * size + 1).
  if (nx < 2 || ny < 2 || nz < 2 || nx * ny * nz * int64_t(voxelSize(type)) >= (int64_t(1) << 31) - 4) return false;
  return f.tf.size >= 1 && f.tf.size < (1 << 28) && f.dt > 0.f;
#else
  (void)f, (void)type, (void)components, (void)nx, (void)ny, (void)nz;
  return false;
#endif
}

void packetPairTable(const TransferFunctionView& tf, std::vector<float>& pairs) {
  const size_t n = size_t(tf.size > 0 ? tf.size : 0);
  pairs.resize(8 * n);
  for (int c = 0; c < 4; ++c)
    for (size_t i = 0; i < n; ++i) {
      const vec4f& a = tf.table[i];
      const vec4f& b = tf.table[i + 1 < n ? i + 1 : i];
      pairs[c * 2 * n + 2 * i] = c == 0 ? a.x : c == 1 ? a.y : c == 2 ? a.z : a.w;
      pairs[c * 2 * n + 2 * i + 1] = c == 0 ? b.x : c == 1 ? b.y : c == 2 ? b.z : b.w;
    }
}

void marchPacketTile(const FrameView& f, const float* pairs, VoxelType type, const void* voxels, int64_t nx,
                     int64_t ny, int64_t nz, int x0, int y0, int x1, int y1, vec4f* px) {
#ifdef SPACESKIP_HAVE_HWY
  HWY_DYNAMIC_DISPATCH(MarchTile)(f, pairs, type, voxels, nx, ny, nz, x0, y0, x1, y1, px);
#else
  (void)f, (void)pairs, (void)type, (void)voxels, (void)nx, (void)ny, (void)nz, (void)x0, (void)y0, (void)x1, (void)y1, (void)px;
#endif
}

const char* packetTarget() {
#ifdef SPACESKIP_HAVE_HWY
  return HWY_DYNAMIC_DISPATCH(TargetName)();
#else
  return "none";
#endif
}

}  // namespace spaceskip
#endif

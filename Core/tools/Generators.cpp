// Procedural volumes with the shapes and occupancies of the paper's data sets.
#include "spaceskip/Generators.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

namespace spaceskip {

namespace {

template <class F>
void fill(Volume& v, F f) {
  unsigned char* d = v.mutableData();
  const int64_t nx = v.dims.x, ny = v.dims.y;
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, v.dims.z), [&](const tbb::blocked_range<int64_t>& r) {
    for (int64_t z = r.begin(); z != r.end(); ++z)
      for (int64_t y = 0; y < ny; ++y)
        for (int64_t x = 0; x < nx; ++x) d[x + nx * (y + ny * z)] = f(x, y, z);
  });
}

// Menger sponge of level 3 over the unit cube: a point is removed when, at some level,
// at least two of its base-3 digits equal 1.
Volume menger(vec3l dims) {
  Volume v;
  v.allocate(dims, VoxelType::UInt8);
  fill(v, [&](int64_t x, int64_t y, int64_t z) -> unsigned char {
    int64_t c[3] = {x * 27 / dims.x, y * 27 / dims.y, z * 27 / dims.z};
    for (int l = 0; l < 3; ++l) {
      int ones = 0;
      for (int a = 0; a < 3; ++a) {
        ones += (c[a] % 3) == 1;
        c[a] /= 3;
      }
      if (ones >= 2) return 0;
    }
    return 255;
  });
  return v;
}

// N-body-like: ONE fixed particle set (kNbodyParticles points in the unit cube, independent of
// the resolution), laid out as a cosmic web and splatted into single voxels at any resolution.
//  - 64 nodes (massive halos) uniform in [0.05, 0.95]^3, each joined to its 3 nearest nodes by a
//    filament (a segment);
//  - 6000 halos: the 64 nodes plus halos strewn along the filaments (length-weighted), masses from
//    a Pareto law (exponent 1.9, capped), radius ~ mass^(1/3), a cuspy profile (r = R u^1.5);
//  - 70% of the particles in halos (mass-weighted), 30% along the filaments (Gaussian tubes,
//    sigma 0.008); the voids are empty (a uniform field would stop every k-d split).
// Every random number is a hash of (seed, particle, stream): deterministic per seed and independent
// of the thread count. A voxel's value grows with the particles in it (64 for one, 255 when >= 9).
// Calibrated so that the occupied 8^3 bricks approach the paper's LBVH node counts
// (nodes = 2 bricks - 1; paper ~13.4% at 256^3, 8.0% at 512^3, 3.0% at 1024^3, 1.1% at 2048^3):
// ours 13.0%, 6.9%, 3.6%, 1.1%. So, unlike the old generator (0.15% of voxels at every size), voxel
// occupancy falls with resolution: 0.83% of voxels at 256^3, 0.14%, 0.019%, 0.0025% at 2048^3.
// Small volumes (<= 128^3) receive all the particles too and are comparatively dense.
constexpr int64_t kNbodyParticles = 229376;

inline uint64_t splitmix(uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
/// Uniform in [0,1) from (seed, index, stream).
inline double urand(uint64_t seed, uint64_t i, uint64_t k) {
  return double(splitmix(splitmix(seed * 0x100000001B3ull + k) ^ (i * 0xD6E8FEB86659FD93ull)) >> 11) /
         double(1ull << 53);
}
/// Standard normal (Box-Muller) from streams k and k+1.
inline double grand(uint64_t seed, uint64_t i, uint64_t k) {
  const double u1 = urand(seed, i, k), u2 = urand(seed, i, k + 1);
  return std::sqrt(-2.0 * std::log(1.0 - u1)) * std::cos(6.283185307179586 * u2);
}

struct CosmicWeb {
  std::vector<std::array<double, 3>> node;
  std::vector<std::pair<int, int>> seg;
  std::vector<double> segCum;  // cumulative segment length
  struct Halo { double c[3], r; };
  std::vector<Halo> halo;
  std::vector<double> massCum;  // cumulative halo mass

  int pickSegment(double u) const {
    auto it = std::lower_bound(segCum.begin(), segCum.end(), u * segCum.back());
    return int(std::min<ptrdiff_t>(it - segCum.begin(), ptrdiff_t(seg.size()) - 1));
  }
  void onSegment(int s, double t, double* x) const {
    const auto &a = node[size_t(seg[size_t(s)].first)], &b = node[size_t(seg[size_t(s)].second)];
    for (int k = 0; k < 3; ++k) x[k] = a[size_t(k)] + t * (b[size_t(k)] - a[size_t(k)]);
  }
};

CosmicWeb makeWeb(uint64_t seed) {
  constexpr int nodes = 64, halos = 6000;
  constexpr double alpha = 1.9, r0 = 0.003, tube = 0.008, massCap = 3000, nodeMass = 3000;
  CosmicWeb w;
  w.node.resize(nodes);
  for (int i = 0; i < nodes; ++i)
    for (int a = 0; a < 3; ++a) w.node[size_t(i)][size_t(a)] = 0.05 + 0.9 * urand(seed, uint64_t(i), 10 + uint64_t(a));
  for (int i = 0; i < nodes; ++i) {
    std::vector<std::pair<double, int>> d;
    for (int j = 0; j < nodes; ++j) {
      if (j == i) continue;
      double s = 0;
      for (int a = 0; a < 3; ++a) s += std::pow(w.node[size_t(i)][size_t(a)] - w.node[size_t(j)][size_t(a)], 2);
      d.push_back({s, j});
    }
    std::sort(d.begin(), d.end());
    for (int k = 0; k < 3; ++k) {
      const std::pair<int, int> e{std::min(i, d[size_t(k)].second), std::max(i, d[size_t(k)].second)};
      if (std::find(w.seg.begin(), w.seg.end(), e) == w.seg.end()) w.seg.push_back(e);
    }
  }
  double len = 0;
  for (const auto& e : w.seg) {
    double s = 0;
    for (int a = 0; a < 3; ++a) s += std::pow(w.node[size_t(e.first)][size_t(a)] - w.node[size_t(e.second)][size_t(a)], 2);
    len += std::sqrt(s);
    w.segCum.push_back(len);
  }
  w.halo.resize(halos);
  double mass = 0;
  for (int h = 0; h < halos; ++h) {
    CosmicWeb::Halo& o = w.halo[size_t(h)];
    double m;
    if (h < nodes) {
      for (int a = 0; a < 3; ++a) o.c[a] = w.node[size_t(h)][size_t(a)];
      m = nodeMass * (0.5 + urand(seed, uint64_t(h), 20));
    } else {
      w.onSegment(w.pickSegment(urand(seed, uint64_t(h), 21)), urand(seed, uint64_t(h), 22), o.c);
      for (int a = 0; a < 3; ++a) o.c[a] += 2 * tube * grand(seed, uint64_t(h), 23 + 2 * uint64_t(a));
      m = std::min(massCap, std::pow(1.0 - urand(seed, uint64_t(h), 30), -1.0 / (alpha - 1.0)));
    }
    o.r = r0 * std::cbrt(m);
    mass += m;
    w.massCum.push_back(mass);
  }
  return w;
}

/// Particle i of the fixed set, in [0,1)^3 (reflected at the faces), at time step `step`: each
/// particle drifts along its own random direction, 6e-4 of the box a step in each axis's rms
/// (0.3 voxels at 512^3, 1.2 at 2048^3), so steps differ everywhere and stay as sparse.
void nbodyParticle(const CosmicWeb& w, uint64_t seed, int64_t i, double* x, int step = 0) {
  constexpr double field = 0.0, filament = 0.3, tube = 0.008, profile = 1.5;
  const uint64_t n = uint64_t(i);
  const double u = urand(seed, n, 100);
  if (u < field) {
    for (int a = 0; a < 3; ++a) x[a] = urand(seed, n, 101 + uint64_t(a));
  } else if (u < field + filament) {
    w.onSegment(w.pickSegment(urand(seed, n, 105)), urand(seed, n, 106), x);
    for (int a = 0; a < 3; ++a) x[a] += tube * grand(seed, n, 110 + 2 * uint64_t(a));
  } else {
    auto it = std::lower_bound(w.massCum.begin(), w.massCum.end(), urand(seed, n, 120) * w.massCum.back());
    const auto& h = w.halo[size_t(std::min<ptrdiff_t>(it - w.massCum.begin(), ptrdiff_t(w.halo.size()) - 1))];
    double d[3], norm = 0;
    for (int a = 0; a < 3; ++a) {
      d[a] = grand(seed, n, 130 + 2 * uint64_t(a));
      norm += d[a] * d[a];
    }
    norm = std::sqrt(norm);
    const double r = h.r * std::pow(urand(seed, n, 140), profile);
    for (int a = 0; a < 3; ++a) x[a] = h.c[a] + (norm > 0 ? r * d[a] / norm : 0.0);
  }
  if (step != 0)
    for (int a = 0; a < 3; ++a) x[a] += double(step) * 6e-4 * grand(seed, n, 150 + 2 * uint64_t(a));
  for (int a = 0; a < 3; ++a) {
    double v = std::fabs(x[a]);
    if (v >= 1.0) v = std::max(0.0, 2.0 - v - 1e-12);
    x[a] = std::min(v, std::nextafter(1.0, 0.0));
  }
}

/// Points [z0, z1] of nbody(dims): the particles whose voxel lies in them, in a volume of
/// dims.x x dims.y x (z1 - z0 + 1) (one rank's slab, without the whole volume).
Volume nbodySlab(vec3l dims, int64_t z0, int64_t z1, unsigned seed, int step = 0) {
  Volume v;
  v.allocate(vec3l{dims.x, dims.y, z1 - z0 + 1}, VoxelType::UInt8);
  unsigned char* d = v.mutableData();
  const CosmicWeb web = makeWeb(seed);
  // Voxel of each particle (in parallel; -1 outside the slab), sorted, then one value per run of
  // equal voxels.
  std::vector<int64_t> vox(static_cast<size_t>(kNbodyParticles));
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, kNbodyParticles), [&](const tbb::blocked_range<int64_t>& r) {
    for (int64_t i = r.begin(); i != r.end(); ++i) {
      double x[3];
      nbodyParticle(web, seed, i, x, step);
      const int64_t ix = std::min(dims.x - 1, int64_t(x[0] * double(dims.x)));
      const int64_t iy = std::min(dims.y - 1, int64_t(x[1] * double(dims.y)));
      const int64_t iz = std::min(dims.z - 1, int64_t(x[2] * double(dims.z)));
      vox[size_t(i)] = iz < z0 || iz > z1 ? -1 : ix + dims.x * (iy + dims.y * (iz - z0));
    }
  });
  tbb::parallel_sort(vox.begin(), vox.end());
  for (size_t i = 0; i < vox.size();) {
    size_t j = i;
    while (j < vox.size() && vox[j] == vox[i]) ++j;
    if (vox[i] >= 0) d[vox[i]] = (unsigned char)std::min<size_t>(255, 64 + 24 * (j - i - 1));
    i = j;
  }
  return v;
}

Volume nbody(vec3l dims, unsigned seed) { return nbodySlab(dims, 0, dims.z - 1, seed); }

Volume shell(vec3l dims) {
  Volume v;
  v.allocate(dims, VoxelType::UInt8);
  fill(v, [&](int64_t x, int64_t y, int64_t z) -> unsigned char {
    double p[3] = {(x + 0.5) / dims.x - 0.5, (y + 0.5) / dims.y - 0.5, (z + 0.5) / dims.z - 0.5};
    double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    double s = (r - 0.35) / 0.04;
    return (unsigned char)std::lround(255.0 * std::exp(-s * s));
  });
  return v;
}

double hash3(int64_t x, int64_t y, int64_t z, unsigned seed) {
  uint64_t h = uint64_t(x) * 0x9E3779B97F4A7C15ull ^ uint64_t(y) * 0xC2B2AE3D27D4EB4Full ^
               uint64_t(z) * 0x165667B19E3779F9ull ^ seed;
  h ^= h >> 31;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 29;
  return double(h >> 11) / double(1ull << 53);
}

double valueNoise(double x, double y, double z, unsigned seed) {
  int64_t ix = int64_t(std::floor(x)), iy = int64_t(std::floor(y)), iz = int64_t(std::floor(z));
  double fx = x - ix, fy = y - iy, fz = z - iz;
  auto s = [](double t) { return t * t * (3 - 2 * t); };
  fx = s(fx); fy = s(fy); fz = s(fz);
  double r = 0;
  for (int c = 0; c < 8; ++c) {
    double w = ((c & 1) ? fx : 1 - fx) * ((c & 2) ? fy : 1 - fy) * ((c & 4) ? fz : 1 - fz);
    r += w * hash3(ix + (c & 1), iy + ((c >> 1) & 1), iz + ((c >> 2) & 1), seed);
  }
  return r;
}

double fbm(double x, double y, double z, unsigned seed) {
  double r = 0, a = 0.5;
  for (int o = 0; o < 4; ++o) {
    r += a * valueNoise(x, y, z, seed + unsigned(o));
    x *= 2; y *= 2; z *= 2; a *= 0.5;
  }
  return r / 0.9375;
}

Volume noise(vec3l dims, unsigned seed) {
  Volume v;
  v.allocate(dims, VoxelType::Float32);
  float* d = reinterpret_cast<float*>(v.mutableData());
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, dims.z), [&](const tbb::blocked_range<int64_t>& r) {
    for (int64_t z = r.begin(); z != r.end(); ++z)
      for (int64_t y = 0; y < dims.y; ++y)
        for (int64_t x = 0; x < dims.x; ++x)
          d[x + dims.x * (y + dims.y * z)] =
              float(fbm(8.0 * x / dims.x, 8.0 * y / dims.y, 8.0 * z / dims.z, seed));
  });
  return v;
}

// A mixing layer: a perturbed interface at mid-height; values fall off with the distance
// to the interface and carry turbulent noise, so about half the volume is non-empty.
// `halfWidth`: the layer's half-thickness (0.26 for the stand-in); `drift`: the turbulence
// carried along z (a time step's advection).
Volume rm(vec3l dims, unsigned seed, double halfWidth = 0.26, double drift = 0.0) {
  Volume v;
  v.allocate(dims, VoxelType::UInt8);
  fill(v, [&](int64_t x, int64_t y, int64_t z) -> unsigned char {
    double px = double(x) / dims.x, py = double(y) / dims.y, pz = double(z) / dims.z;
    double h = 0.5 + 0.12 * (fbm(6 * px, 6 * py, 0.5, seed) - 0.5) * 2;
    double dist = std::fabs(pz - h);
    double layer = std::max(0.0, 1.0 - dist / halfWidth);
    double turb = fbm(16 * px, 16 * py, 16 * (pz - drift), seed + 7);
    double val = layer * (0.4 + 0.6 * turb);
    return (unsigned char)std::lround(255.0 * std::clamp(val, 0.0, 1.0));
  });
  return v;
}

// The mixing layer's time step `step` (issue 38's denser stand-in): the layer widens from a
// half-thickness of 0.04 at step 0 to the stand-in's 0.26 at step 24 (held after: a playback
// holding 25 steps sees the whole growth), the turbulence drifting 0.4 % of the box along z a
// step, so each step differs everywhere and the drawn share grows about sixfold.
Volume rmStep(vec3l dims, unsigned seed, int step) {
  const double t = std::min(std::max(step, 0), 24) / 24.0;
  return rm(dims, seed, 0.04 + 0.22 * t, 0.004 * step);
}

// Branching tubes from a random walk (a vessel tree stand-in, ~1% occupied); radii x `thick`.
Volume vessels(vec3l dims, unsigned seed, double thick = 1.0) {
  Volume v;
  v.allocate(dims, VoxelType::UInt8);
  unsigned char* d = v.mutableData();
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0, 1);
  struct Seg { double p[3], dir[3], r; int depth; };
  std::vector<Seg> todo{{{0.5, 0.5, 0.05}, {0, 0, 1}, 0.03 * thick, 0}};
  const double scale = double(std::min({dims.x, dims.y, dims.z}));
  while (!todo.empty()) {
    Seg s = todo.back();
    todo.pop_back();
    int steps = int(0.25 * scale);
    for (int i = 0; i < steps; ++i) {
      for (int a = 0; a < 3; ++a) s.dir[a] += 0.08 * n(rng);
      double l = std::sqrt(s.dir[0] * s.dir[0] + s.dir[1] * s.dir[1] + s.dir[2] * s.dir[2]);
      for (int a = 0; a < 3; ++a) {
        s.dir[a] /= l;
        s.p[a] += s.dir[a] / scale;
      }
      if (s.p[0] < 0 || s.p[1] < 0 || s.p[2] < 0 || s.p[0] > 1 || s.p[1] > 1 || s.p[2] > 1) break;
      double rv = std::max(1.0, s.r * scale);
      int ri = int(std::ceil(rv));
      int64_t c[3] = {int64_t(s.p[0] * dims.x), int64_t(s.p[1] * dims.y), int64_t(s.p[2] * dims.z)};
      for (int dz = -ri; dz <= ri; ++dz)
        for (int dy = -ri; dy <= ri; ++dy)
          for (int dx = -ri; dx <= ri; ++dx) {
            double dd = std::sqrt(double(dx * dx + dy * dy + dz * dz));
            if (dd > rv) continue;
            int64_t x = c[0] + dx, y = c[1] + dy, z = c[2] + dz;
            if (x < 0 || y < 0 || z < 0 || x >= dims.x || y >= dims.y || z >= dims.z) continue;
            unsigned char val = (unsigned char)std::lround(255.0 * (1.0 - 0.5 * dd / rv));
            unsigned char& t = d[x + dims.x * (y + dims.y * z)];
            t = std::max(t, val);
          }
      if (s.depth < 7 && i > 8 && (rng() % 1000) < 25) {
        Seg b = s;
        b.depth = s.depth + 1;
        b.r = s.r * 0.75;
        for (int a = 0; a < 3; ++a) b.dir[a] += 0.8 * n(rng);
        todo.push_back(b);
        s.r *= 0.85;
      }
    }
  }
  return v;
}


// ---- The paper's other data sets (Zellmann, Fig. 1): stand-ins with its dims and occupancy ----
// Every stand-in is uint8 with a background of 0, a 255 voxel and every other non-zero voxel >= 32,
// so under the "ramp" preset over the volume's range (the bench's TF: transparent below 10% of
// the range) exactly the non-zero voxels are visible: the paper's occupancy ("percentage of
// voxels that are visible given a certain transfer function"). Shapes are defined on the unit
// cube (per-axis scaling to the dims; lengths in units of the smallest dim), so the occupancy
// holds at any resolution (TestGenerators.cpp measures it at a small size).

/// A primitive rasterized into the volume (max of values): a capsule (segment a-b, radius r0 at
/// a to r1 at b, value vc at the axis to ve at the surface) or an ellipsoid shell (centre a, radii
/// b, thickness r0), all in voxels. `speckle` in (0,1]: only that fraction of the voxels inside
/// (a per-voxel hash) is set: needles, porous tissue.
struct Prim {
  enum Kind { Capsule, Shell } kind = Capsule;
  double a[3] = {0, 0, 0}, b[3] = {0, 0, 0};
  double r0 = 1, r1 = 1;
  double vc = 255, ve = 160;
  double speckle = 1;
  unsigned seed = 0;
  int64_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};  // voxel bounds (inclusive lo, exclusive hi)

  void bound(vec3l dims) {
    for (int k = 0; k < 3; ++k) {
      double l, h;
      if (kind == Capsule) {
        const double r = std::max(r0, r1) + 1;
        l = std::min(a[k], b[k]) - r;
        h = std::max(a[k], b[k]) + r;
      } else {
        l = a[k] - b[k] - r0 - 1;
        h = a[k] + b[k] + r0 + 1;
      }
      const int64_t n = k == 0 ? dims.x : k == 1 ? dims.y : dims.z;
      lo[k] = std::clamp<int64_t>(int64_t(std::floor(l)), 0, n);
      hi[k] = std::clamp<int64_t>(int64_t(std::ceil(h)) + 1, 0, n);
    }
  }
  /// Value at voxel centre (x, y, z) (voxel units), 0 outside.
  double value(double x, double y, double z) const {
    double f;  // 0 at the core, 1 at the surface, > 1 outside
    if (kind == Capsule) {
      const double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      const double p[3] = {x - a[0], y - a[1], z - a[2]};
      const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      const double t = dd > 0 ? std::clamp((p[0] * d[0] + p[1] * d[1] + p[2] * d[2]) / dd, 0.0, 1.0) : 0.0;
      const double q[3] = {p[0] - t * d[0], p[1] - t * d[1], p[2] - t * d[2]};
      const double r = r0 + t * (r1 - r0);
      f = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]) / std::max(r, 0.5);
    } else {
      const double q[3] = {(x - a[0]) / b[0], (y - a[1]) / b[1], (z - a[2]) / b[2]};
      const double rn = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
      const double rmin = std::min({b[0], b[1], b[2]});
      f = std::fabs(rn - 1.0) * rmin / std::max(0.5 * r0, 0.5);  // distance to the surface / half thickness
    }
    if (f > 1) return 0;
    if (speckle < 1 && hash3(int64_t(x), int64_t(y), int64_t(z), seed) >= speckle) return 0;
    return vc + (ve - vc) * f;
  }
};

/// Rasterizes the primitives (max of their values, each value clamped to [32, 255]): parallel
/// over z, each slice visiting only the primitives whose bounds hold it.
void rasterize(Volume& v, std::vector<Prim>& prims) {
  for (Prim& p : prims) p.bound(v.dims);
  std::vector<std::vector<int>> byZ(size_t(v.dims.z));
  for (size_t i = 0; i < prims.size(); ++i)
    for (int64_t z = prims[i].lo[2]; z < prims[i].hi[2]; ++z) byZ[size_t(z)].push_back(int(i));
  unsigned char* d = v.mutableData();
  const int64_t nx = v.dims.x, ny = v.dims.y;
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, v.dims.z), [&](const tbb::blocked_range<int64_t>& r) {
    for (int64_t z = r.begin(); z != r.end(); ++z)
      for (int i : byZ[size_t(z)]) {
        const Prim& p = prims[size_t(i)];
        for (int64_t y = p.lo[1]; y < p.hi[1]; ++y)
          for (int64_t x = p.lo[0]; x < p.hi[0]; ++x) {
            const double val = p.value(x + 0.5, y + 0.5, z + 0.5);
            if (val <= 0) continue;
            const auto c = (unsigned char)std::lround(std::clamp(val, 32.0, 255.0));
            unsigned char& t = d[x + nx * (y + ny * z)];
            t = std::max(t, c);
          }
      }
  });
}

/// Unit-cube point -> voxel coordinates.
struct Frame {
  vec3l dims;
  double S;  ///< the smallest dim: lengths are in its units
  explicit Frame(vec3l d) : dims(d), S(double(std::min({d.x, d.y, d.z}))) {}
  void at(double u, double v, double w, double* o) const {
    o[0] = u * double(dims.x);
    o[1] = v * double(dims.y);
    o[2] = w * double(dims.z);
  }
  Prim capsule(const double* a, const double* b, double r0, double r1, double vc = 255, double ve = 160) const {
    Prim p;
    at(a[0], a[1], a[2], p.a);
    at(b[0], b[1], b[2], p.b);
    p.r0 = r0 * S;
    p.r1 = r1 * S;
    p.vc = vc;
    p.ve = ve;
    return p;
  }
};

/// Raises the brightest voxel to 255 unless one is (so every stand-in spans [0, 255] and the
/// ramp's threshold sits at 25.5, below every non-zero voxel).
void markMax(Volume& v) {
  unsigned char* d = v.mutableData();
  const int64_t n = v.voxelCount();
  const auto m = std::max_element(d, d + n);
  if (*m == 0) d[n / 2] = 255;  // an empty shape still gets its range
  else *m = 255;
}

// Aneurism (256^3, 1.01%): the vessel tree and a saccular aneurism (a ball) on its trunk.
Volume aneurism(vec3l dims, unsigned seed) {
  Volume v = vessels(dims, seed, 2.12);
  const Frame f(dims);
  const double c[3] = {0.56, 0.5, 0.3};
  std::vector<Prim> sac{f.capsule(c, c, 0.055, 0.055, 255, 200)};
  rasterize(v, sac);
  markMax(v);
  return v;
}

// Xmas tree (512x499x512, 2.90%; height along y): a trunk, 15 tiers of 9 drooping branches
// out to the cone's surface, twigs, needle foliage (speckled tubes) and baubles at the tips. The
// cone's inside is empty between the branches and every branch reaches the hull, so no plane
// removes empty space from the whole tree: the paper's local optimum (Fig. 2, top).
Volume xmasTree(vec3l dims, unsigned seed) {
  Volume v;
  v.allocate(dims, VoxelType::UInt8);
  const Frame f(dims);
  std::vector<Prim> prims;
  const double base[3] = {0.5, 0.02, 0.5}, top[3] = {0.5, 0.97, 0.5};
  prims.push_back(f.capsule(base, top, 0.022, 0.006, 255, 200));
  const int tiers = 15, perTier = 9;
  for (int i = 0; i < tiers; ++i) {
    const double h = 0.12 + 0.8 * i / (tiers - 1);
    const double R = 0.46 * (1.0 - (h - 0.08) / 0.95);
    for (int j = 0; j < perTier; ++j) {
      const double th = 6.283185307179586 * (j + 0.5 * (i & 1) + 0.3 * urand(seed, uint64_t(i * 16 + j), 1)) / perTier;
      const double a[3] = {0.5, h, 0.5};
      const double b[3] = {0.5 + R * std::cos(th), h - 0.05 - 0.04 * urand(seed, uint64_t(i * 16 + j), 2),
                           0.5 + R * std::sin(th)};
      prims.push_back(f.capsule(a, b, 0.006, 0.003, 230, 150));
      Prim fol = f.capsule(a, b, 0.010, 0.026, 120, 60);  // needles: speckled, widening outwards
      fol.speckle = 0.68;
      fol.seed = seed + 17;
      prims.push_back(fol);
      for (int k = 1; k <= 4; ++k) {  // twigs
        const double t = 0.25 + 0.17 * k;
        const double m[3] = {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])};
        const double side = (k & 1) ? 1.0 : -1.0;
        const double e[3] = {m[0] + 0.12 * R * (std::cos(th) - side * std::sin(th)), m[1] - 0.02,
                             m[2] + 0.12 * R * (std::sin(th) + side * std::cos(th))};
        prims.push_back(f.capsule(m, e, 0.004, 0.003, 200, 140));
      }
      if ((i + j) % 2 == 0) prims.push_back(f.capsule(b, b, 0.014, 0.014, 255, 220));  // bauble
    }
  }
  rasterize(v, prims);
  markMax(v);
  return v;
}

// Magnetic reconnection (512^3, 16.6%): smooth turbulent flux structures, value noise above a
// threshold (blobs and sheets strewn through the whole box, empty space interleaved).
Volume magnetic(vec3l dims, unsigned seed) {
  Volume v;
  v.allocate(dims, VoxelType::UInt8);
  constexpr double t = 0.613;  // fbm above this in ~16.6% of the box (TestGenerators)
  fill(v, [&](int64_t x, int64_t y, int64_t z) -> unsigned char {
    const double px = (x + 0.5) / dims.x, py = (y + 0.5) / dims.y, pz = (z + 0.5) / dims.z;
    // Sheared coordinates: structures stretched along x like reconnecting field lines.
    const double n = fbm(4 * px + 2 * py, 10 * py, 10 * pz + 1.5 * px, seed + 31);
    if (n <= t) return 0;
    return (unsigned char)std::lround(std::min(255.0, 40.0 + 215.0 * (n - t) / (1.0 - t)));
  });
  markMax(v);
  return v;
}

// Stag beetle (832x832x494, 4.04%; body along y, up along z): the exoskeleton as ellipsoid
// shells (abdomen, thorax, head), two mandibles, six three-segment legs and two antennae.
Volume stagBeetle(vec3l dims, unsigned seed) {
  (void)seed;
  Volume v;
  v.allocate(dims, VoxelType::UInt8);
  const Frame f(dims);
  std::vector<Prim> prims;
  auto shell = [&](double u, double w, double z, double rx, double ry, double rz, double thick) {
    Prim p;
    p.kind = Prim::Shell;
    f.at(u, w, z, p.a);
    p.b[0] = rx * double(dims.x);
    p.b[1] = ry * double(dims.y);
    p.b[2] = rz * double(dims.z);
    p.r0 = thick * f.S;
    p.vc = 255;
    p.ve = 170;
    prims.push_back(p);
  };
  constexpr double th = 0.0425;  // shell thickness (units of the smallest dim), calibrated
  shell(0.5, 0.34, 0.42, 0.19, 0.22, 0.30, th);   // abdomen (elytra)
  shell(0.5, 0.60, 0.45, 0.15, 0.07, 0.24, th);   // thorax
  shell(0.5, 0.72, 0.45, 0.12, 0.055, 0.18, th);  // head
  for (int s : {-1, 1}) {
    // Mandibles: three segments curving forward and in.
    const double m0[3] = {0.5 + s * 0.07, 0.77, 0.45}, m1[3] = {0.5 + s * 0.13, 0.86, 0.47},
                 m2[3] = {0.5 + s * 0.11, 0.94, 0.49}, m3[3] = {0.5 + s * 0.04, 0.985, 0.5};
    prims.push_back(f.capsule(m0, m1, 0.03, 0.026, 255, 180));
    prims.push_back(f.capsule(m1, m2, 0.026, 0.02, 255, 180));
    prims.push_back(f.capsule(m2, m3, 0.02, 0.01, 255, 180));
    const double a0[3] = {0.5 + s * 0.09, 0.75, 0.55}, a1[3] = {0.5 + s * 0.2, 0.82, 0.62};
    prims.push_back(f.capsule(a0, a1, 0.006, 0.005, 230, 160));  // antenna
    for (int l = 0; l < 3; ++l) {
      const double y = 0.56 - 0.1 * l;
      const double p0[3] = {0.5 + s * 0.12, y, 0.32}, p1[3] = {0.5 + s * 0.26, y + 0.03 * (1 - l), 0.42},
                   p2[3] = {0.5 + s * 0.36, y + 0.05 * (1 - l), 0.18}, p3[3] = {0.5 + s * 0.44, y + 0.07 * (1 - l), 0.03};
      prims.push_back(f.capsule(p0, p1, 0.018, 0.015, 240, 160));
      prims.push_back(f.capsule(p1, p2, 0.015, 0.011, 240, 160));
      prims.push_back(f.capsule(p2, p3, 0.011, 0.007, 240, 160));
    }
  }
  rasterize(v, prims);
  markMax(v);
  return v;
}

// Kingsnake (1024x1024x795, 0.39%): the skeleton of a coiled snake, a spine on a three-turn
// spiral in the xy plane with vertebrae (balls) and a pair of ribs (arcs of three segments) at
// each, thin structures over a large, mostly empty box.
Volume kingsnake(vec3l dims, unsigned seed) {
  (void)seed;
  Volume v;
  v.allocate(dims, VoxelType::UInt8);
  const Frame f(dims);
  std::vector<Prim> prims;
  constexpr double rv = 0.0118, rr = 0.0052, body = 0.035;  // vertebra, rib radius, body radius
  const double turns = 3.0, r0 = 0.08, r1 = 0.42;
  double arc = 0;
  double prev[3] = {0, 0, 0};
  const int steps = 20000;
  for (int i = 0; i <= steps; ++i) {
    const double t = double(i) / steps, ang = 6.283185307179586 * turns * t, r = r0 + (r1 - r0) * t;
    const double p[3] = {0.5 + r * std::cos(ang), 0.5 + r * std::sin(ang),
                         0.35 + 0.04 * std::sin(5 * ang) + (t < 0.04 ? 3.0 * (0.04 - t) : 0.0)};
    if (i > 0) arc += std::hypot(p[0] - prev[0], p[1] - prev[1], p[2] - prev[2]);
    std::copy(p, p + 3, prev);
    if (i > 0 && arc < 0.011) continue;
    arc = 0;
    prims.push_back(f.capsule(p, p, rv, rv, 255, 200));
    // Ribs: around the body in the plane normal to the spiral's tangent (radial, z).
    const double nx = std::cos(ang), ny = std::sin(ang);
    for (int s : {-1, 1}) {
      double q[3] = {p[0], p[1], p[2]};
      for (int k = 1; k <= 3; ++k) {
        const double phi = 3.14159265 * 0.5 * k / 3.0;  // from the top round the side and down
        const double e[3] = {p[0] + s * body * std::sin(phi) * nx, p[1] + s * body * std::sin(phi) * ny,
                             p[2] + body * (std::cos(phi) - 1.0) * 0.9};
        prims.push_back(f.capsule(q, e, rr, rr * 0.8, 230, 150));
        std::copy(e, e + 3, q);
      }
    }
  }
  rasterize(v, prims);
  markMax(v);
  return v;
}

// Richtmyer-Meshkov (2048x2048x1920, 50.6%; the mixing direction along z): the paper's two large
// regions, a totally homogeneous heavy fluid at the bottom and empty space at the top, with a
// turbulent mixing layer between them (bubbles and spikes of varied values) around a perturbed
// interface h(x, y). The homogeneous region is where MLS over-splits (Fig. 2, bottom).
Volume richtmyerMeshkov(vec3l dims, unsigned seed) {
  Volume v;
  v.allocate(dims, VoxelType::UInt8);
  unsigned char* d = v.mutableData();
  const int64_t nx = dims.x, ny = dims.y, nz = dims.z;
  std::vector<double> h(size_t(nx * ny));
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, ny), [&](const tbb::blocked_range<int64_t>& r) {
    for (int64_t y = r.begin(); y != r.end(); ++y)
      for (int64_t x = 0; x < nx; ++x) {
        const double px = (x + 0.5) / nx, py = (y + 0.5) / ny;
        h[size_t(x + nx * y)] = 0.5 + 0.035 * std::sin(6.283185307179586 * 3 * px) * std::sin(6.283185307179586 * 2 * py) +
                                0.06 * (fbm(5 * px, 5 * py, 0.5, seed) - 0.5);
      }
  });
  constexpr double w = 0.1, shift = 0.006;  // mixing half-width; shift calibrates the occupancy
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, nz), [&](const tbb::blocked_range<int64_t>& r) {
    for (int64_t z = r.begin(); z != r.end(); ++z) {
      const double pz = (z + 0.5) / nz;
      for (int64_t y = 0; y < ny; ++y)
        for (int64_t x = 0; x < nx; ++x) {
          const double hc = h[size_t(x + nx * y)] + shift;
          unsigned char val = 0;
          if (pz < hc - w) val = 200;  // homogeneous heavy fluid
          else if (pz < hc + w) {
            const double heavy = (hc + w - pz) / (2 * w);  // 1 at the bottom of the layer, 0 at its top
            const double px = (x + 0.5) / nx, py = (y + 0.5) / ny;
            const double n = 0.65 * valueNoise(28 * px, 28 * py, 28 * pz, seed + 5) +
                             0.35 * valueNoise(71 * px, 71 * py, 71 * pz, seed + 6);
            const double m = 0.5 + 1.6 * (n - 0.5);  // spread towards [0, 1]
            if (m < heavy) val = (unsigned char)std::lround(std::clamp(60.0 + 195.0 * (heavy - m) / 0.35, 60.0, 255.0));
          }
          d[x + nx * (y + ny * z)] = val;
        }
    }
  });
  markMax(v);
  return v;
}

}  // namespace

double visibleVoxelFraction(const Volume& v, const TransferFunction& tf) {
  if (tf.table.empty() || v.voxelCount() == 0) return 0;
  const double lo = tf.rangeMin, hi = tf.rangeMax;
  const double scale = hi > lo ? double(tf.table.size() - 1) / (hi - lo) : 0.0;
  const int64_t n = v.voxelCount();
  return dispatchVoxelType(v.type, [&](auto voxel) {
    using T = decltype(voxel);
    const T* p = reinterpret_cast<const T*>(v.data);
    const int64_t visible = tbb::parallel_reduce(
        tbb::blocked_range<int64_t>(0, n), int64_t(0),
        [&](const tbb::blocked_range<int64_t>& r, int64_t acc) {
          for (int64_t i = r.begin(); i != r.end(); ++i) {
            const double s = double(p[i]);
            if (!(s == s)) continue;  // NaN: transparent
            // Linear interpolation of the table's opacity, as a sample at the voxel sees it.
            const double f = std::clamp((s - lo) * scale, 0.0, double(tf.table.size() - 1));
            const size_t i0 = size_t(f);
            const size_t i1 = std::min(i0 + 1, tf.table.size() - 1);
            const double a = tf.table[i0].w + (f - double(i0)) * (tf.table[i1].w - tf.table[i0].w);
            acc += a > 0;
          }
          return acc;
        },
        std::plus<int64_t>());
    return double(visible) / double(n);
  });
}

const std::vector<PaperDataset>& paperDatasets() {
  // shared/paper/paper_results.csv: name, dims, occupancy (% of voxels); our generator for each.
  static const std::vector<PaperDataset> sets = {
      {"aneurism", "aneurism", {256, 256, 256}, 1.01},
      {"xmas_tree", "xmas_tree", {512, 499, 512}, 2.90},
      {"magnetic", "magnetic", {512, 512, 512}, 16.6},
      {"stag_beetle", "stag_beetle", {832, 832, 494}, 4.04},
      {"kingsnake", "kingsnake", {1024, 1024, 795}, 0.39},
      {"menger_sponge", "menger", {1024, 1024, 1024}, 40.7},
      {"richtmyer_meshkov", "richtmyer_meshkov", {2048, 2048, 1920}, 50.6},
      {"nbody_256", "nbody", {256, 256, 256}, 0.15},
      {"nbody_512", "nbody", {512, 512, 512}, 0.15},
      {"nbody_1024", "nbody", {1024, 1024, 1024}, 0.15},
      {"nbody_2048", "nbody", {2048, 2048, 2048}, 0.15},
  };
  return sets;
}

std::vector<std::string> generatorShapes() {
  return {"menger", "nbody", "shell", "noise", "rm", "vessels", "aneurism", "xmas_tree", "magnetic", "stag_beetle",
          "kingsnake", "richtmyer_meshkov"};
}

Volume generateTimeStep(const std::string& shape, vec3l dims, int step, VoxelType type, unsigned seed) {
  if (shape != "nbody" && shape != "rm")
    throw std::invalid_argument("time series: shape '" + shape + "' has no time steps (nbody and rm have)");
  if (type != VoxelType::UInt8 && type != VoxelType::Float32)
    throw std::invalid_argument(std::string("time series: voxel type ") + voxelTypeName(type) + " (uint8 or float32)");
  Volume v = shape == "rm" ? rmStep(dims, seed, step) : nbodySlab(dims, 0, dims.z - 1, seed, step);
  if (type == VoxelType::UInt8) return v;
  Volume f;
  f.allocate(dims, VoxelType::Float32);
  const unsigned char* in = static_cast<const unsigned char*>(v.data);
  float* out = reinterpret_cast<float*>(f.mutableData());
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, v.voxelCount()), [&](const tbb::blocked_range<int64_t>& r) {
    for (int64_t i = r.begin(); i != r.end(); ++i) out[i] = float(in[i]) * (1.f / 255.f);
  });
  return f;
}

Volume generateSlab(const std::string& shape, vec3l dims, int64_t z0, int64_t z1, unsigned seed) {
  if (z0 < 0 || z1 < z0 || z1 >= dims.z) throw std::invalid_argument("slab outside the volume");
  if (shape == "nbody") return nbodySlab(dims, z0, z1, seed);
  const Volume whole = generateVolume(shape, dims, seed);
  Volume v;
  v.allocate(vec3l{dims.x, dims.y, z1 - z0 + 1}, whole.type);
  const size_t plane = size_t(dims.x * dims.y) * voxelSize(whole.type);
  std::memcpy(v.mutableData(), static_cast<const unsigned char*>(whole.data) + size_t(z0) * plane,
              size_t(z1 - z0 + 1) * plane);
  return v;
}

Volume generateVolume(const std::string& shape, vec3l dims, unsigned seed) {
  if (dims.x <= 0 || dims.y <= 0 || dims.z <= 0) throw std::invalid_argument("dims must be positive");
  if (shape == "menger") return menger(dims);
  if (shape == "nbody") return nbody(dims, seed);
  if (shape == "shell") return shell(dims);
  if (shape == "noise") return noise(dims, seed);
  if (shape == "rm") return rm(dims, seed);
  if (shape == "vessels") return vessels(dims, seed);
  if (shape == "aneurism") return aneurism(dims, seed);
  if (shape == "xmas_tree") return xmasTree(dims, seed);
  if (shape == "magnetic") return magnetic(dims, seed);
  if (shape == "stag_beetle") return stagBeetle(dims, seed);
  if (shape == "kingsnake") return kingsnake(dims, seed);
  if (shape == "richtmyer_meshkov") return richtmyerMeshkov(dims, seed);
  if (const int labels = labelShapeCount(shape)) return generateLabels(dims, labels, seed);  // LabelGenerator.cpp
  std::string known;
  for (const std::string& g : generatorShapes()) known += (known.empty() ? "" : ", ") + g;
  known += ", labels[N]";
  throw std::invalid_argument("unknown shape '" + shape + "' (" + known + ")");
}

}  // namespace spaceskip

// Procedural volumes with the shapes and occupancies of the paper's data sets.
#include "spaceskip/Generators.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <cmath>
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

/// Particle i of the fixed set, in [0,1)^3 (reflected at the faces).
void nbodyParticle(const CosmicWeb& w, uint64_t seed, int64_t i, double* x) {
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
  for (int a = 0; a < 3; ++a) {
    double v = std::fabs(x[a]);
    if (v >= 1.0) v = std::max(0.0, 2.0 - v - 1e-12);
    x[a] = std::min(v, std::nextafter(1.0, 0.0));
  }
}

Volume nbody(vec3l dims, unsigned seed) {
  Volume v;
  v.allocate(dims, VoxelType::UInt8);
  unsigned char* d = v.mutableData();
  const CosmicWeb web = makeWeb(seed);
  // Voxel of each particle (in parallel), sorted, then one value per run of equal voxels.
  std::vector<int64_t> vox(static_cast<size_t>(kNbodyParticles));
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, kNbodyParticles), [&](const tbb::blocked_range<int64_t>& r) {
    for (int64_t i = r.begin(); i != r.end(); ++i) {
      double x[3];
      nbodyParticle(web, seed, i, x);
      const int64_t ix = std::min(dims.x - 1, int64_t(x[0] * double(dims.x)));
      const int64_t iy = std::min(dims.y - 1, int64_t(x[1] * double(dims.y)));
      const int64_t iz = std::min(dims.z - 1, int64_t(x[2] * double(dims.z)));
      vox[size_t(i)] = ix + dims.x * (iy + dims.y * iz);
    }
  });
  tbb::parallel_sort(vox.begin(), vox.end());
  for (size_t i = 0; i < vox.size();) {
    size_t j = i;
    while (j < vox.size() && vox[j] == vox[i]) ++j;
    d[vox[i]] = (unsigned char)std::min<size_t>(255, 64 + 24 * (j - i - 1));
    i = j;
  }
  return v;
}

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
Volume rm(vec3l dims, unsigned seed) {
  Volume v;
  v.allocate(dims, VoxelType::UInt8);
  fill(v, [&](int64_t x, int64_t y, int64_t z) -> unsigned char {
    double px = double(x) / dims.x, py = double(y) / dims.y, pz = double(z) / dims.z;
    double h = 0.5 + 0.12 * (fbm(6 * px, 6 * py, 0.5, seed) - 0.5) * 2;
    double dist = std::fabs(pz - h);
    double layer = std::max(0.0, 1.0 - dist / 0.26);
    double turb = fbm(16 * px, 16 * py, 16 * pz, seed + 7);
    double val = layer * (0.4 + 0.6 * turb);
    return (unsigned char)std::lround(255.0 * std::clamp(val, 0.0, 1.0));
  });
  return v;
}

// Branching tubes from a random walk (a vessel tree stand-in, ~1% occupied).
Volume vessels(vec3l dims, unsigned seed) {
  Volume v;
  v.allocate(dims, VoxelType::UInt8);
  unsigned char* d = v.mutableData();
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0, 1);
  struct Seg { double p[3], dir[3], r; int depth; };
  std::vector<Seg> todo{{{0.5, 0.5, 0.05}, {0, 0, 1}, 0.03, 0}};
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

}  // namespace

std::vector<std::string> generatorShapes() { return {"menger", "nbody", "shell", "noise", "rm", "vessels"}; }

Volume generateVolume(const std::string& shape, vec3l dims, unsigned seed) {
  if (dims.x <= 0 || dims.y <= 0 || dims.z <= 0) throw std::invalid_argument("dims must be positive");
  if (shape == "menger") return menger(dims);
  if (shape == "nbody") return nbody(dims, seed);
  if (shape == "shell") return shell(dims);
  if (shape == "noise") return noise(dims, seed);
  if (shape == "rm") return rm(dims, seed);
  if (shape == "vessels") return vessels(dims, seed);
  throw std::invalid_argument("unknown shape '" + shape + "' (menger, nbody, shell, noise, rm, vessels)");
}

}  // namespace spaceskip

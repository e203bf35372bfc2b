// Procedural volumes with the shapes and occupancies of the paper's data sets.
#include "spaceskip/Generators.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <stdexcept>

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

// N-body-like: particles in Gaussian clusters, each splatted as a small ball.
Volume nbody(vec3l dims, unsigned seed) {
  Volume v;
  v.allocate(dims, VoxelType::UInt8);
  unsigned char* d = v.mutableData();
  std::mt19937_64 rng(seed);
  const double voxels = double(dims.x) * dims.y * dims.z;
  const double target = 0.0015 * voxels;  // voxels to cover
  const int64_t particles = std::max<int64_t>(1, int64_t(target / 7.0));  // ~7 voxels per splat
  const int clusters = std::max(4, int(std::cbrt(double(particles)) * 2));
  std::uniform_real_distribution<double> u(0.1, 0.9);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<std::array<double, 4>> cl(static_cast<size_t>(clusters));
  for (auto& c : cl) c = {u(rng), u(rng), u(rng), 0.01 + 0.05 * u(rng)};
  std::uniform_int_distribution<int> pick(0, clusters - 1);
  std::uniform_int_distribution<int> val(64, 255);
  for (int64_t p = 0; p < particles; ++p) {
    const auto& c = cl[size_t(pick(rng))];
    int64_t px = int64_t((c[0] + n(rng) * c[3]) * double(dims.x));
    int64_t py = int64_t((c[1] + n(rng) * c[3]) * double(dims.y));
    int64_t pz = int64_t((c[2] + n(rng) * c[3]) * double(dims.z));
    unsigned char value = (unsigned char)val(rng);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (std::abs(dx) + std::abs(dy) + std::abs(dz) > 1) continue;  // 7-voxel ball
          int64_t x = px + dx, y = py + dy, z = pz + dz;
          if (x < 0 || y < 0 || z < 0 || x >= dims.x || y >= dims.y || z >= dims.z) continue;
          unsigned char& t = d[x + dims.x * (y + dims.y * z)];
          t = std::max(t, value);
        }
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

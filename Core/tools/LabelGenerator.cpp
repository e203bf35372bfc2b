// A generated label map (segmentation) for the label-map benchmark and tests (issue 37):
// generateLabels, generateVolume's "labels[N]".
#include "spaceskip/Generators.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

namespace spaceskip {

namespace {

inline uint64_t mix(uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
/// Uniform in [0,1) from (seed, index, stream): independent of threads and dims.
inline double unit(uint64_t seed, uint64_t i, uint64_t k) {
  return double(mix(mix(seed * 0x100000001B3ull + k) ^ (i * 0xD6E8FEB86659FD93ull)) >> 11) / double(1ull << 53);
}

/// An axis-aligned ellipsoid in voxel coordinates (voxel x's centre at x + 0.5).
struct Blob {
  double c[3], r[3];
  int64_t lo[3], hi[3];  ///< voxel bounds, hi exclusive
  int id;
};

/// Paints the blobs in index order (a later one overwrites an earlier one where they overlap),
/// parallel over z; each slice visits only the blobs that reach it and each row only the x span
/// inside the ellipsoid, so the work is the painted voxels, not voxels x labels.
template <class T>
void paint(Volume& v, const std::vector<Blob>& blobs) {
  T* d = reinterpret_cast<T*>(v.mutableData());
  const int64_t nx = v.dims.x, ny = v.dims.y;
  std::vector<std::vector<int>> byZ(size_t(v.dims.z));
  for (size_t i = 0; i < blobs.size(); ++i)
    for (int64_t z = blobs[i].lo[2]; z < blobs[i].hi[2]; ++z) byZ[size_t(z)].push_back(int(i));
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, v.dims.z), [&](const tbb::blocked_range<int64_t>& r) {
    for (int64_t z = r.begin(); z != r.end(); ++z)
      for (int i : byZ[size_t(z)]) {
        const Blob& b = blobs[size_t(i)];
        const double qz = (double(z) + 0.5 - b.c[2]) / b.r[2];
        for (int64_t y = b.lo[1]; y < b.hi[1]; ++y) {
          const double qy = (double(y) + 0.5 - b.c[1]) / b.r[1];
          const double rest = 1.0 - qz * qz - qy * qy;
          if (rest < 0) continue;
          const double w = b.r[0] * std::sqrt(rest);
          const int64_t x0 = std::max<int64_t>(0, int64_t(std::ceil(b.c[0] - w - 0.5)));
          const int64_t x1 = std::min<int64_t>(nx - 1, int64_t(std::floor(b.c[0] + w - 0.5)));
          T* row = d + nx * (y + ny * z);
          for (int64_t x = x0; x <= x1; ++x) row[x] = T(b.id);
        }
      }
  });
  // Each blob's centre voxel carries its id whatever overlaps it: every id is present when the
  // cells are at least ~2 voxels wide.
  for (const Blob& b : blobs) {
    const int64_t x = std::clamp<int64_t>(int64_t(b.c[0]), 0, nx - 1);
    const int64_t y = std::clamp<int64_t>(int64_t(b.c[1]), 0, ny - 1);
    const int64_t z = std::clamp<int64_t>(int64_t(b.c[2]), 0, v.dims.z - 1);
    d[x + nx * (y + ny * z)] = T(b.id);
  }
}

}  // namespace

Volume generateLabels(vec3l dims, int labels, unsigned seed) {
  if (dims.x <= 0 || dims.y <= 0 || dims.z <= 0) throw std::invalid_argument("dims must be positive");
  if (labels < 1 || labels > 65535)
    throw std::invalid_argument("labels: " + std::to_string(labels) + " is out of range [1, 65535]");
  // A jittered grid of g^3 cells (~1.3 cells a label), the labels in a shuffled subset of them,
  // so neighbouring blobs have unrelated ids.
  const int g = std::max(1, int(std::ceil(std::cbrt(double(labels) * 1.3) - 1e-9)));
  std::vector<int> cell(size_t(g) * size_t(g) * size_t(g));
  std::iota(cell.begin(), cell.end(), 0);
  for (size_t i = cell.size(); i > 1; --i)  // Fisher-Yates
    std::swap(cell[i - 1], cell[size_t(unit(seed, i, 0) * double(i))]);
  std::vector<Blob> blobs(static_cast<size_t>(labels));
  const double n[3] = {double(dims.x), double(dims.y), double(dims.z)};
  for (int i = 0; i < labels; ++i) {
    Blob& b = blobs[size_t(i)];
    b.id = i + 1;
    const int c = cell[size_t(i)];
    const int ci[3] = {c % g, (c / g) % g, c / (g * g)};
    // Sizes log-uniform over 0.12..0.55 cells (volumes ~100x apart), each axis x0.7..1.3, at most
    // 0.6 cells: a blob reaches at most a neighbour's border, never its centre (centres >= 0.7
    // cells apart with the +-0.15 jitter).
    const double base = 0.12 * std::pow(0.55 / 0.12, unit(seed, uint64_t(i), 1));
    for (int a = 0; a < 3; ++a) {
      const double cu = (ci[a] + 0.5 + 0.3 * (unit(seed, uint64_t(i), 2 + uint64_t(a)) - 0.5)) / g;
      const double ru = std::min(0.6, base * (0.7 + 0.6 * unit(seed, uint64_t(i), 5 + uint64_t(a)))) / g;
      b.c[a] = cu * n[a];
      b.r[a] = std::max(ru * n[a], 1e-3);
      b.lo[a] = std::clamp<int64_t>(int64_t(std::floor(b.c[a] - b.r[a])), 0, int64_t(n[a]));
      b.hi[a] = std::clamp<int64_t>(int64_t(std::ceil(b.c[a] + b.r[a])) + 1, 0, int64_t(n[a]));
    }
  }
  Volume v;
  v.allocate(dims, labels <= 255 ? VoxelType::UInt8 : VoxelType::UInt16);
  if (labels <= 255) paint<uint8_t>(v, blobs);
  else paint<uint16_t>(v, blobs);
  return v;
}

int labelShapeCount(const std::string& shape) {
  if (shape.rfind("labels", 0) != 0) return 0;
  const std::string n = shape.substr(6);
  if (n.empty()) return 256;
  if (n.size() > 5 || n.find_first_not_of("0123456789") != std::string::npos) return 0;
  const int c = std::stoi(n);
  return c >= 1 && c <= 65535 ? c : 0;
}

}  // namespace spaceskip

// Volume metadata helpers.
#include "spaceskip/Volume.h"


#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

namespace spaceskip {

size_t voxelSize(VoxelType t) {
  switch (t) {
    case VoxelType::UInt8:
    case VoxelType::Int8: return 1;
    case VoxelType::UInt16:
    case VoxelType::Int16: return 2;
    case VoxelType::Float32: return 4;
    case VoxelType::Float64: return 8;
  }
  return 1;
}

const char* voxelTypeName(VoxelType t) {
  switch (t) {
    case VoxelType::UInt8: return "uint8";
    case VoxelType::Int8: return "int8";
    case VoxelType::UInt16: return "uint16";
    case VoxelType::Int16: return "int16";
    case VoxelType::Float32: return "float32";
    case VoxelType::Float64: return "float64";
  }
  return "?";
}

bool parseVoxelType(const std::string& in, VoxelType& out) {
  std::string s = in;
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  if (s == "uint8" || s == "uchar" || s == "unsigned char" || s == "uint8_t") out = VoxelType::UInt8;
  else if (s == "int8" || s == "char" || s == "signed char" || s == "int8_t") out = VoxelType::Int8;
  else if (s == "uint16" || s == "ushort" || s == "unsigned short" || s == "uint16_t") out = VoxelType::UInt16;
  else if (s == "int16" || s == "short" || s == "int16_t") out = VoxelType::Int16;
  else if (s == "float32" || s == "float") out = VoxelType::Float32;
  else if (s == "float64" || s == "double") out = VoxelType::Float64;
  else return false;
  return true;
}

vec3i Volume::cellDims() const {
  return vec3i{int(std::max<int64_t>(dims.x - 1, 1)), int(std::max<int64_t>(dims.y - 1, 1)),
               int(std::max<int64_t>(dims.z - 1, 1))};
}

mat4 Volume::indexToWorld() const {
  mat4 r = identity4();
  for (int c = 0; c < 3; ++c) {
    for (int row = 0; row < 3; ++row) r.m[c * 4 + row] = direction[row * 3 + c] * spacing[c];
    r.m[12 + c] = origin[c];
  }
  return r;
}

void Volume::worldBounds(double b[6]) const {
  vec3i cd = cellDims();
  mat4 m = indexToWorld();
  for (int i = 0; i < 3; ++i) {
    b[2 * i] = std::numeric_limits<double>::infinity();
    b[2 * i + 1] = -std::numeric_limits<double>::infinity();
  }
  for (int c = 0; c < 8; ++c) {
    double p[3] = {double((c & 1) ? cd.x : 0), double((c & 2) ? cd.y : 0), double((c & 4) ? cd.z : 0)};
    double w[3];
    transformPoint(m, p, w);
    for (int i = 0; i < 3; ++i) {
      b[2 * i] = std::min(b[2 * i], w[i]);
      b[2 * i + 1] = std::max(b[2 * i + 1], w[i]);
    }
  }
}

namespace {
template <class T>
double at(const void* d, int64_t i) {
  return double(static_cast<const T*>(d)[i]);
}
}  // namespace

double Volume::value(int64_t i, int64_t j, int64_t k) const {
  const int64_t idx = (i + dims.x * (j + dims.y * k)) * components + opacityComponent();
  return dispatchVoxelType(type, [&](auto voxel) { return at<decltype(voxel)>(data, idx); });
}

namespace {
// Voxels per serial chunk of the range pass: large enough that a chunk's loop vectorises and
// the task overhead vanishes, small enough to balance 8 GiB over all cores.
constexpr int64_t kRangeGrain = int64_t(1) << 20;

// Min/max of n voxels of type T, oneTBB parallel (a 2048^3 uint8 volume is 8 Gi voxels:
// the serial per-voxel switch took tens of seconds there): the finite ones, or (!finiteOnly)
// all but NaN. Values p[i * stride] for i < n (stride: the component count when one component
// is wanted).
template <class T>
bool finiteRange(const void* data, int64_t n, double& lo, double& hi, int64_t stride = 1, bool finiteOnly = true) {
  const T* p = static_cast<const T*>(data);
  using MinMax = std::pair<double, double>;
  const MinMax empty{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  const MinMax r = tbb::parallel_reduce(
      tbb::blocked_range<int64_t>(0, n, kRangeGrain), empty,
      [p, stride, finiteOnly](const tbb::blocked_range<int64_t>& br, MinMax acc) {
        if constexpr (std::is_integral_v<T>) {
          (void)finiteOnly;  // integers are finite
          T mn = std::numeric_limits<T>::max(), mx = std::numeric_limits<T>::lowest();
          if (stride == 1) {
            for (int64_t i = br.begin(); i < br.end(); ++i) {
              mn = std::min(mn, p[i]);
              mx = std::max(mx, p[i]);
            }
          } else {
            for (int64_t i = br.begin(); i < br.end(); ++i) {
              mn = std::min(mn, p[i * stride]);
              mx = std::max(mx, p[i * stride]);
            }
          }
          acc.first = std::min(acc.first, double(mn));
          acc.second = std::max(acc.second, double(mx));
        } else {
          for (int64_t i = br.begin(); i < br.end(); ++i) {
            const double v = double(p[i * stride]);
            if (finiteOnly ? !std::isfinite(v) : std::isnan(v)) continue;
            acc.first = std::min(acc.first, v);
            acc.second = std::max(acc.second, v);
          }
        }
        return acc;
      },
      [](const MinMax& a, const MinMax& b) {
        return MinMax{std::min(a.first, b.first), std::max(a.second, b.second)};
      });
  lo = r.first;
  hi = r.second;
  return lo <= hi;
}
}  // namespace

bool valueRange(VoxelType t, const void* data, int64_t count, int64_t stride, bool finiteOnly, double& lo,
                double& hi) {
  return dispatchVoxelType(t, [&](auto voxel) {
    return finiteRange<decltype(voxel)>(data, count, lo, hi, stride, finiteOnly);
  });
}

bool Volume::scalarRange(double& lo, double& hi) const {
  const int64_t n = voxelCount() * components;
  return dispatchVoxelType(type, [&](auto voxel) { return finiteRange<decltype(voxel)>(data, n, lo, hi); });
}

bool Volume::componentRange(int c, double& lo, double& hi) const {
  if (c < 0 || c >= components) throw std::out_of_range("component " + std::to_string(c) + " of a volume of " +
                                                        std::to_string(components));
  const int64_t n = voxelCount();
  return dispatchVoxelType(type, [&](auto voxel) {
    using T = decltype(voxel);
    return finiteRange<T>(static_cast<const T*>(data) + c, n, lo, hi, components);
  });
}

void Volume::allocate(vec3l d, VoxelType t, int nc) {
  if (nc != 1 && nc != 2 && nc != 4)
    throw std::runtime_error("volume: " + std::to_string(nc) + " components (1, 2 or 4 are supported)");
  // Checked first: a wrapped product would allocate a small buffer that later reads overrun.
  const uint64_t bytes = checkedByteSize(d, t, std::numeric_limits<uint64_t>::max(), "volume");
  if (bytes > std::numeric_limits<uint64_t>::max() / uint64_t(nc))
    throw std::runtime_error("volume: byte count overflows 64 bits");
  auto buf = std::make_shared<std::vector<unsigned char>>(size_t(bytes * uint64_t(nc)));
  components = nc;
  dims = d;
  type = t;
  storage = std::move(buf);
  data = storage->data();
}

namespace {
std::string dimsText(vec3l d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}
}  // namespace

uint64_t defaultMaxVolumeBytes() {
  // A volume is read into host memory whole, so more than physical memory cannot succeed.
  uint64_t cap = uint64_t(64) << 30;
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  if (pages > 0 && page > 0 && uint64_t(pages) <= std::numeric_limits<uint64_t>::max() / uint64_t(page))
    cap = std::min(cap, uint64_t(pages) * uint64_t(page));
  return cap;
}

uint64_t checkedByteSize(vec3l d, VoxelType t, uint64_t maxBytes, const std::string& what) {
  if (d.x <= 0 || d.y <= 0 || d.z <= 0)
    throw std::runtime_error(what + ": empty or negative extent " + dimsText(d));
  if (d.x > kMaxAxisVoxels || d.y > kMaxAxisVoxels || d.z > kMaxAxisVoxels)
    throw std::runtime_error(what + ": extent " + dimsText(d) + " has an axis longer than 2^30 voxels");
  uint64_t n = 0, bytes = 0;
  if (__builtin_mul_overflow(uint64_t(d.x), uint64_t(d.y), &n) || __builtin_mul_overflow(n, uint64_t(d.z), &n) ||
      __builtin_mul_overflow(n, uint64_t(voxelSize(t)), &bytes) ||
      bytes > uint64_t(std::numeric_limits<int64_t>::max()))
    throw std::runtime_error(what + ": extent " + dimsText(d) + " of " + voxelTypeName(t) +
                             " overflows a 64-bit byte count");
  if (bytes > maxBytes)
    throw std::runtime_error(what + ": extent " + dimsText(d) + " of " + voxelTypeName(t) + " needs " +
                             std::to_string(bytes) + " bytes, more than the limit of " + std::to_string(maxBytes) +
                             " (raise it with SPACESKIP_MAX_VOLUME_BYTES or --max-volume-bytes)");
  return bytes;
}

void validate(const Volume& v) {
  // Overflow and axis checks, no size cap: the voxels are already in memory.
  checkedByteSize(v.dims, v.type, std::numeric_limits<uint64_t>::max(), "volume");
  if (v.components != 1 && v.components != 2 && v.components != 4)
    throw std::runtime_error("volume has " + std::to_string(v.components) +
                             " components: 1, or dependent components 2 (value + opacity) or 4 (RGB + opacity)");
  if (!v.data) throw std::runtime_error("volume has no voxel data");
  for (int i = 0; i < 3; ++i)
    if (!(v.spacing[i] > 0) || !std::isfinite(v.spacing[i]))
      throw std::runtime_error("volume spacing must be positive and finite");
  if (v.warp) {
    if (v.warp->points(0) != v.dims.x || v.warp->points(1) != v.dims.y || v.warp->points(2) != v.dims.z)
      throw std::runtime_error("rectilinear grid: the coordinate counts differ from the volume's dimensions");
    if (v.components != 1)
      throw std::runtime_error("rectilinear grid: drawn through its coordinates with one component only");
  }
}

}  // namespace spaceskip

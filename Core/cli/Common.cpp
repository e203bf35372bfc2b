// What the CLI's commands share: volumes, transfer functions and cameras from the options.
#include "Commands.h"
#include "spaceskip/Generators.h"
#include "spaceskip/TransferFunctionIO.h"
#include "spaceskip/VolumeIO.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>

namespace spaceskip::cli {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return 0.5 * (v[(v.size() - 1) / 2] + v[v.size() / 2]);
}
double maxOf(const std::vector<double>& v) { return v.empty() ? 0 : *std::max_element(v.begin(), v.end()); }

double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

namespace {
/// --rectilinear: `v`'s points as a rectilinear grid over the same bounds, drawn through its
/// coordinates (AxisWarp.h): x steps growing 1:3 along the axis, y uniform, z steps varying
/// about 1:2 in a sine.
Volume asRectilinear(Volume v) {
  std::vector<double> c[3];
  const int64_t n[3] = {v.dims.x, v.dims.y, v.dims.z};
  for (int a = 0; a < 3; ++a) {
    c[a].resize(size_t(n[a]));
    for (int64_t i = 0; i < n[a]; ++i) {
      const double t = n[a] > 1 ? double(i) / double(n[a] - 1) : 0.0;
      const double s = a == 0 ? 0.5 * t + 0.5 * t * t : (a == 1 ? t : t + 0.2 * std::sin(2.0 * M_PI * t) / M_PI);
      c[a][size_t(i)] = v.origin[a] + v.spacing[a] * double(n[a] - 1) * s;
    }
  }
  const double* at[3] = {c[0].data(), c[1].data(), c[2].data()};
  v.warp = AxisWarp::fromCoordinates(at, n);
  return v;
}
}  // namespace

Volume openVolume(const std::string& spec, const Options& o) {
  const uint64_t cap = maxVolumeBytes(o);
  std::string shape;
  vec3l dims;
  Volume v;
  if (parseGeneratorSpec(spec, cap, shape, dims)) {
    v = allocating("generating " + spec + " (" + dimsText(dims) + ")", checkGeneratorSize(shape, dims, cap),
                   [&] { return generateVolume(shape, dims); });
  } else {
    ReadLimits limits;
    limits.maxBytes = cap;
    v = loadVolume(spec, limits);
  }
  return o.has("--rectilinear") ? asRectilinear(std::move(v)) : v;
}

TransferFunction makeTF(const Options& o, const Volume& v) {
  double lo, hi;
  if (!v.scalarRange(lo, hi)) lo = 0, hi = 1;
  std::string t = o.get("--tf", "ramp");
  // A preset name unless a file of that name exists (loadTransferFunction refuses devices).
  std::error_code ec;
  TransferFunction tf =
      std::filesystem::exists(t, ec) ? loadTransferFunction(t, lo, hi) : TransferFunction::preset(t, lo, hi);
  if (o.has("--tf2d")) {
    // A boundary-emphasising 2-D transfer function (value x gradient magnitude): each column the
    // 1-D table's colour, its opacity times a ramp over the normalised gradient magnitude, 0 at
    // g = 0 up to 1 from g = 1/2; 256 columns, ROWS rows.
    const int rows = int(o.getInt("--tf2d", 64, 2, 4096));
    const int cols = 256;
    tf.width2D = cols;
    tf.height2D = rows;
    tf.table2D.assign(size_t(cols) * size_t(rows), vec4f{0, 0, 0, 0});
    const size_t n = tf.table.size();
    for (int c = 0; c < cols; ++c) {
      const vec4f e = tf.table[std::min(n - 1, size_t((double(c) + 0.5) / cols * double(n)))];
      for (int r = 0; r < rows; ++r) {
        const float g = (float(r) + 0.5f) / float(rows);
        tf.table2D[size_t(r) * cols + size_t(c)] = vec4f{e.x, e.y, e.z, e.w * std::min(1.f, 2.f * g)};
      }
    }
  }
  return tf;
}

Camera makeCamera(const Options& o, const Volume& v, int w, int h, double azDefault, double elDefault) {
  double az = azDefault, el = elDefault, zoom = 1;
  if (o.has("--camera")) {
    parseCamera(o.get("--camera", ""), az, el, zoom);
  }
  double b[6];
  v.worldBounds(b);
  return orbitCamera(b, az, el, zoom, o.has("--perspective"), double(w) / h);
}


void printResidency(const ResidencyStats& r) {
  if (!r.sparse) return;
  std::printf("residency sparse: pool bricks of %d cells, %lld needed, %lld resident of %lld (%lld slots, %.1f MiB "
              "pool, budget %.1f MiB)\n",
              r.poolBrick, (long long)r.needed, (long long)r.resident, (long long)r.bricks, (long long)r.capacity,
              double(r.poolBytes) / 1048576.0, double(r.budgetBytes) / 1048576.0);
}


std::string jsonEscape(const std::string& s) {
  std::string o;
  for (const char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 0x20) o += ' ';
    else o += c;
  }
  return o;
}

std::string dimsText(vec3l d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

std::string outOfMemory(const std::string& what, uint64_t bytes) {
  char b[64];
  std::snprintf(b, sizeof b, " (%llu bytes, %.2f GiB)", (unsigned long long)bytes, double(bytes) / 1073741824.0);
  return "out of memory " + what + b;
}

std::string frameText(int w, int h) {
  return "drawing a " + std::to_string(w) + "x" + std::to_string(h) + " frame (its image alone)";
}

std::unique_ptr<OutputFile> outputOption(const Options& o, const std::string& option) {
  if (!o.has(option)) return nullptr;
  try {
    return std::make_unique<OutputFile>(o.get(option, ""));
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(option + " " + e.what());
  }
}

}  // namespace spaceskip::cli

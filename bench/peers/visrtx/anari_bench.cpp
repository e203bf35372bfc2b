// anari_bench: SpaceSkip's peer benchmark through ANARI (issue 39). One volume
// (an Open-SciVis-named raw file), a 1-D transfer function, an orthographic
// camera orbiting the volume's centre as `spaceskip bench` does, and timings:
// device init, first frame (scene creation + commits + frame), fps over the
// orbit (each frame waited for), the same with the colour buffer mapped, the
// GPU time the device reports, and opacity edits -> next frame. Writes the
// first frame as a PNG (straight alpha, top row first: what `spaceskip render
// --compare` reads) and optionally as raw float RGBA (premultiplied, bottom row
// first).
#include <anari/anari.h>
#include <anari/frontend/type_utility.h>

#include "spaceskip/TransferFunction.h"
#include "spaceskip/TransferFunctionIO.h"
#include "spaceskip/ImageIO.h"
#include "spaceskip/VolumeIO.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

const char *kUsage = R"(usage: anari_bench VOLUME.raw [options]
       anari_bench --list [--library NAME]

VOLUME: NAME_XxYxZ_TYPE.raw (TYPE uint8, int8, uint16, int16, float32, float64) or
a .nrrd, read by SpaceSkip's own loader (float64 is converted to float32).

  --library NAME        ANARI library: visrtx (default), helide (CPU), sink
  --device NAME         device subtype (default "default")
  --renderer NAME       renderer subtype (default: "default"; --settings fast: "raycast"
                        when the device has it)
  --settings default|fast
                        default: the device's renderer defaults (sample rate set below);
                        fast: pixelSamples 1, ambientSamples 0, denoise off,
                        checkerboarding off, and the "raycast" renderer if offered
  --set NAME=VALUE      extra renderer parameter (bool true/false, int, or float),
                        may be repeated
  --list                print the device's renderer subtypes and their parameters
  --tf FILE|PRESET      transfer function (default ramp): SpaceSkip's presets (ramp,
                        grayscale, coolwarm, band, spike, opaque, zero; 1024 entries over
                        the volume's finite value range) or a file of SpaceSkip's
                        "value r g b a" control points (optional "range LO HI",
                        "size N", "unit U"): read by SpaceSkip's own code
  --range LO HI         value range of the table (default: the file's, else the
                        volume's finite min/max, as SpaceSkip)
  --unit U              opacity unit distance in world units (default 1, as SpaceSkip)
  --spacing X,Y,Z       voxel spacing (default 1,1,1); the volume spans [0,(dims-1)*spacing]
  --sample-distance D   world units between samples (default: half the smallest
                        spacing, SpaceSkip's default). Sets the renderer's
                        "volumeSamplingRate" = (min spacing / 2) / D
  --size WxH            image size (default 1024x1024)
  --frames N            frames of the orbit (default 8)
  --azimuth-step DEG    azimuth step per frame (default 360/N)
  --elevation DEG       camera elevation (default 15, as spaceskip bench)
  --zoom Z              orthographic zoom (default 1)
  --edits N             opacity edits at the still view (default 4): odd ones zero the
                        opacity of the lowest --edit-cut share of the table (default 0.3,
                        as spaceskip bench --edits), even ones restore it
  --accumulate N        before saving, N more frames at the first view (converged image)
  --background R,G,B,A  background (default 0,0,0,0: alpha = opacity, as SpaceSkip)
  --color float32|ufixed8
                        frame colour format (default float32)
  -o FILE.png           write the first frame as PNG
  --raw FILE            write the first frame as raw float32 RGBA (premultiplied, row 0
                        at the bottom, WxH from --size)
  --csv FILE            append one result row (header written when the file is new)
  --label TEXT          label for the CSV row (default: library/renderer/settings)
  --help
)";

[[noreturn]] void fail(const std::string &m)
{
  std::fprintf(stderr, "anari_bench: %s\n", m.c_str());
  std::exit(1);
}

int g_errors = 0;
void statusFunc(const void *, ANARIDevice, ANARIObject, ANARIDataType,
    ANARIStatusSeverity severity, ANARIStatusCode, const char *message)
{
  const char *kind = severity == ANARI_SEVERITY_FATAL_ERROR ? "FATAL"
      : severity == ANARI_SEVERITY_ERROR                    ? "ERROR"
      : severity == ANARI_SEVERITY_WARNING                  ? "WARNING"
      : severity == ANARI_SEVERITY_PERFORMANCE_WARNING      ? "PERF"
                                                            : nullptr;
  if (!kind)
    return; // info and debug
  if (severity <= ANARI_SEVERITY_ERROR)
    ++g_errors;
  std::fprintf(stderr, "[anari %s] %s\n", kind, message);
}

// ---- options --------------------------------------------------------------

struct Args
{
  std::vector<std::string> pos;
  std::vector<std::pair<std::string, std::string>> kv;
  bool has(const std::string &k) const
  {
    for (auto &p : kv)
      if (p.first == k)
        return true;
    return false;
  }
  std::string get(const std::string &k, const std::string &d = "") const
  {
    std::string v = d;
    for (auto &p : kv)
      if (p.first == k)
        v = p.second;
    return v;
  }
};

double num(const std::string &s, const std::string &what)
{
  char *end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end || !std::isfinite(v))
    fail("bad number '" + s + "' for " + what);
  return v;
}

std::vector<double> nums(const std::string &s, char sep, size_t n, const std::string &what)
{
  std::vector<double> r;
  std::stringstream ss(s);
  std::string t;
  while (std::getline(ss, t, sep))
    r.push_back(num(t, what));
  if (r.size() != n)
    fail(what + " needs " + std::to_string(n) + " values, got '" + s + "'");
  return r;
}

// ---- volume: read by SpaceSkip's own loader (Core/tools/VolumeIO.cpp, compiled in) ------------

// A SpaceSkip volume as ANARI takes it: fixed-point voxels are read normalised (value / norm);
// float64 is converted to float32 (VisRTX samples no doubles).
struct AnariVolume
{
  spaceskip::Volume v;
  ANARIDataType type = ANARI_UNKNOWN;
  double norm = 1;
  std::vector<float> asFloat; // float64 volumes only
  const void *data() const { return asFloat.empty() ? v.data : asFloat.data(); }
};

AnariVolume loadForAnari(const std::string &path)
{
  AnariVolume a;
  a.v = spaceskip::loadVolume(path);
  if (a.v.components != 1)
    fail(path + ": one component only");
  switch (a.v.type) {
    case spaceskip::VoxelType::UInt8: a.type = ANARI_UFIXED8, a.norm = 255; break;
    case spaceskip::VoxelType::Int8: a.type = ANARI_FIXED8, a.norm = 127; break;
    case spaceskip::VoxelType::UInt16: a.type = ANARI_UFIXED16, a.norm = 65535; break;
    case spaceskip::VoxelType::Int16: a.type = ANARI_FIXED16, a.norm = 32767; break;
    case spaceskip::VoxelType::Float32: a.type = ANARI_FLOAT32; break;
    case spaceskip::VoxelType::Float64: {
      a.type = ANARI_FLOAT32;
      const double *d = static_cast<const double *>(a.v.data);
      a.asFloat.assign(d, d + a.v.voxelCount());
      break;
    }
  }
  return a;
}

// ---- transfer function: SpaceSkip's own presets and file reader (Core/src/TransferFunction.cpp
// and Core/tools/TransferFunctionIO.cpp are compiled into this program), so both renderers get
// the same table.

spaceskip::TransferFunction makeTF(const std::string &spec, double lo, double hi)
{
  std::error_code ec;
  if (std::filesystem::exists(spec, ec))
    return spaceskip::loadTransferFunction(spec, lo, hi);
  return spaceskip::TransferFunction::preset(spec, lo, hi);
}

// ---- ANARI helpers --------------------------------------------------------

struct Anari
{
  ANARIDevice d = nullptr;
  void set(ANARIObject o, const char *n, ANARIDataType t, const void *v) { anariSetParameter(d, o, n, t, v); }
  void setF(ANARIObject o, const char *n, float v) { set(o, n, ANARI_FLOAT32, &v); }
  void setI(ANARIObject o, const char *n, int v) { set(o, n, ANARI_INT32, &v); }
  void setB(ANARIObject o, const char *n, bool v)
  {
    const uint32_t b = v;
    set(o, n, ANARI_BOOL, &b);
  }
  void set3(ANARIObject o, const char *n, const float *v) { set(o, n, ANARI_FLOAT32_VEC3, v); }
  void setObj(ANARIObject o, const char *n, ANARIDataType t, ANARIObject v) { set(o, n, t, &v); }
  void commit(ANARIObject o) { anariCommitParameters(d, o); }
  ANARIArray1D array1D(ANARIDataType t, const void *src, size_t n, size_t elemBytes)
  {
    ANARIArray1D a = anariNewArray1D(d, nullptr, nullptr, nullptr, t, n);
    std::memcpy(anariMapArray(d, a), src, n * elemBytes);
    anariUnmapArray(d, a);
    return a;
  }
};

void listRenderers(ANARIDevice d)
{
  const char **subtypes = anariGetObjectSubtypes(d, ANARI_RENDERER);
  if (!subtypes) {
    std::printf("renderers: (none listed)\n");
    return;
  }
  for (const char **s = subtypes; *s; ++s) {
    std::printf("renderer \"%s\"\n", *s);
    auto *params = static_cast<const ANARIParameter *>(
        anariGetObjectInfo(d, ANARI_RENDERER, *s, "parameter", ANARI_PARAMETER_LIST));
    for (; params && params->name; ++params) {
      auto *desc = static_cast<const char *>(anariGetParameterInfo(
          d, ANARI_RENDERER, *s, params->name, params->type, "description", ANARI_STRING));
      std::printf("  %-28s %-22s %s\n", params->name, anari::toString(params->type), desc ? desc : "");
    }
  }
}

bool hasSubtype(ANARIDevice d, ANARIDataType t, const std::string &name)
{
  const char **subtypes = anariGetObjectSubtypes(d, t);
  for (const char **s = subtypes; s && *s; ++s)
    if (name == *s)
      return true;
  return false;
}

double median(std::vector<double> v)
{
  if (v.empty())
    return 0;
  std::sort(v.begin(), v.end());
  return 0.5 * (v[(v.size() - 1) / 2] + v[v.size() / 2]);
}

} // namespace

int main(int argc, char **argv)
{
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    if (s == "--help" || s == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (s == "--list")
      a.kv.push_back({s, "1"});
    else if (s == "--range") {
      if (i + 2 >= argc)
        fail("--range needs LO HI");
      a.kv.push_back({s, std::string(argv[i + 1]) + "," + argv[i + 2]});
      i += 2;
    } else if (s == "--set") {
      if (i + 1 >= argc)
        fail("--set needs NAME=VALUE");
      a.kv.push_back({"+set", argv[++i]});
    } else if (s.size() > 1 && s[0] == '-') {
      if (i + 1 >= argc)
        fail(s + " needs a value (see --help)");
      a.kv.push_back({s, argv[++i]});
    } else
      a.pos.push_back(s);
  }
  static const char *known[] = {"--list", "--range", "--library", "--device", "--renderer", "--settings",
      "--tf", "--unit", "--spacing", "--sample-distance", "--size", "--frames", "--azimuth-step",
      "--elevation", "--zoom", "--edits", "--edit-cut", "--accumulate", "--background", "--color", "-o",
      "--raw", "--csv", "--label"};
  for (auto &p : a.kv)
    if (p.first != "+set"
        && std::find_if(std::begin(known), std::end(known), [&](const char *k) { return p.first == k; })
            == std::end(known))
      fail("unknown option " + p.first + " (see --help)");

  const std::string libName = a.get("--library", "visrtx");
  const bool visrtx = libName == "visrtx";
  const auto tInit = Clock::now();
  ANARILibrary lib = anariLoadLibrary(libName.c_str(), statusFunc, nullptr);
  if (!lib)
    fail("cannot load ANARI library '" + libName + "' (libanari_library_" + libName
        + ".so on LD_LIBRARY_PATH?)");
  Anari x;
  x.d = anariNewDevice(lib, a.get("--device", "default").c_str());
  if (!x.d)
    fail("cannot create device");
  if (visrtx) { // compile the OptiX modules now, not in the first frame
    x.setB(x.d, "forceInit", true);
  }
  x.commit(x.d);
  const double initS = since(tInit);
  if (a.has("--list")) {
    listRenderers(x.d);
    anariRelease(x.d, x.d);
    anariUnloadLibrary(lib);
    return 0;
  }
  if (a.pos.size() != 1)
    fail("need exactly one VOLUME.raw (see --help)");

  // Options.
  const std::string settings = a.get("--settings", "default");
  if (settings != "default" && settings != "fast")
    fail("--settings is default or fast");
  std::string rendererName = a.get("--renderer", "");
  if (rendererName.empty())
    rendererName = settings == "fast" && hasSubtype(x.d, ANARI_RENDERER, "raycast") ? "raycast" : "default";
  int W = 1024, H = 1024;
  {
    const auto s = nums(a.get("--size", "1024x1024"), 'x', 2, "--size");
    W = int(s[0]), H = int(s[1]);
    if (W < 1 || H < 1 || W > 16384 || H > 16384)
      fail("bad --size");
  }
  const int frames = std::max(1, int(num(a.get("--frames", "8"), "--frames")));
  const double azStep = a.has("--azimuth-step") ? num(a.get("--azimuth-step"), "--azimuth-step") : 360.0 / frames;
  const double elev = num(a.get("--elevation", "15"), "--elevation");
  const double zoom = num(a.get("--zoom", "1"), "--zoom");
  const int edits = std::max(0, int(num(a.get("--edits", "4"), "--edits")));
  const double cut = std::clamp(num(a.get("--edit-cut", "0.3"), "--edit-cut"), 0.0, 1.0);
  const int accumulate = std::max(0, int(num(a.get("--accumulate", "0"), "--accumulate")));
  const auto spacingD = nums(a.get("--spacing", "1,1,1"), ',', 3, "--spacing");
  const float spacing[3] = {float(spacingD[0]), float(spacingD[1]), float(spacingD[2])};
  const auto bgD = nums(a.get("--background", "0,0,0,0"), ',', 4, "--background");
  const float bg[4] = {float(bgD[0]), float(bgD[1]), float(bgD[2]), float(bgD[3])};
  const std::string colorFmt = a.get("--color", "float32");
  if (colorFmt != "float32" && colorFmt != "ufixed8")
    fail("--color is float32 or ufixed8");
  const ANARIDataType colorType = colorFmt == "float32" ? ANARI_FLOAT32_VEC4 : ANARI_UFIXED8_VEC4;
  const double minSpacing = std::min({spacingD[0], spacingD[1], spacingD[2]});
  const double sampleDistance = a.has("--sample-distance")
      ? num(a.get("--sample-distance"), "--sample-distance")
      : 0.5 * minSpacing;
  if (!(sampleDistance > 0) || !(minSpacing > 0))
    fail("sample distance and spacing must be > 0");
  // VisRTX and helide step = min(spacing)/2 / volumeSamplingRate
  // (StructuredRegularField::stepSize, Renderer::commitParameters).
  const float samplingRate = float(0.5 * minSpacing / sampleDistance);
  if (visrtx && (samplingRate < 1e-3f || samplingRate > 10.f))
    std::fprintf(stderr, "anari_bench: warning: VisRTX clamps volumeSamplingRate %g to [0.001, 10]\n",
        samplingRate);

  // Volume and transfer function (host side, not timed).
  const std::string volPath = a.pos[0];
  auto t0 = Clock::now();
  const AnariVolume vol = loadForAnari(volPath);
  const double loadS = since(t0);
  double lo = 0, hi = 1;
  if (!vol.v.scalarRange(lo, hi))
    lo = 0, hi = 1;
  if (a.has("--range")) {
    const auto r = nums(a.get("--range"), ',', 2, "--range");
    lo = r[0], hi = r[1];
  }
  const std::string tfSpec = a.get("--tf", "ramp");
  spaceskip::TransferFunction tf = makeTF(tfSpec, lo, hi);
  if (a.has("--range")) // the option wins over the file's range line
    tf.rangeMin = lo, tf.rangeMax = hi;
  if (a.has("--unit"))
    tf.unitDistance = num(a.get("--unit"), "--unit");
  const size_t n = tf.table.size();
  std::vector<float> color(n * 3), opacity(n), cutOpacity(n);
  for (size_t i = 0; i < n; ++i) {
    const spaceskip::vec4f e = tf.table[i];
    color[i * 3 + 0] = std::clamp(e.x, 0.f, 1.f);
    color[i * 3 + 1] = std::clamp(e.y, 0.f, 1.f);
    color[i * 3 + 2] = std::clamp(e.z, 0.f, 1.f);
    opacity[i] = std::clamp(e.w, 0.f, 1.f);
    cutOpacity[i] = i < size_t(cut * double(n)) ? 0.f : opacity[i];
  }
  // The device reads fixed-point voxels normalised (value / norm): the range follows.
  const float valueRange[2] = {float(tf.rangeMin / vol.norm), float(tf.rangeMax / vol.norm)};

  // Camera: spaceskip's orbitCamera (Core/src/Camera.cpp), orthographic.
  const uint64_t dims[3] = {uint64_t(vol.v.dims.x), uint64_t(vol.v.dims.y), uint64_t(vol.v.dims.z)};
  const double ext[3] = {double(dims[0] > 1 ? dims[0] - 1 : 1) * spacing[0],
      double(dims[1] > 1 ? dims[1] - 1 : 1) * spacing[1], double(dims[2] > 1 ? dims[2] - 1 : 1) * spacing[2]};
  const double ctr[3] = {ext[0] / 2, ext[1] / 2, ext[2] / 2};
  double radius = 0.5 * std::sqrt(ext[0] * ext[0] + ext[1] * ext[1] + ext[2] * ext[2]);
  if (!(radius > 0))
    radius = 1;
  const double aspect = double(W) / H;
  const double height = aspect < 1 ? 2 * radius / zoom / aspect : 2 * radius / zoom;

  // Scene: field, volume, world, camera, renderer, frame (timed to the first frame).
  t0 = Clock::now();
  ANARIArray3D data = anariNewArray3D(x.d, vol.data(), nullptr, nullptr, vol.type, dims[0], dims[1], dims[2]);
  ANARISpatialField field = anariNewSpatialField(x.d, "structuredRegular");
  x.setObj(field, "data", ANARI_ARRAY3D, data);
  const float origin[3] = {0, 0, 0};
  x.set3(field, "origin", origin);
  x.set3(field, "spacing", spacing);
  x.commit(field);
  ANARIVolume volume = anariNewVolume(x.d, "transferFunction1D");
  x.setObj(volume, "value", ANARI_SPATIAL_FIELD, field);
  ANARIArray1D colorArr = x.array1D(ANARI_FLOAT32_VEC3, color.data(), n, 12);
  ANARIArray1D opacityArr = x.array1D(ANARI_FLOAT32, opacity.data(), n, 4);
  x.setObj(volume, "color", ANARI_ARRAY1D, colorArr);
  x.setObj(volume, "opacity", ANARI_ARRAY1D, opacityArr);
  x.set(volume, "valueRange", ANARI_FLOAT32_BOX1, valueRange);
  x.setF(volume, "unitDistance", float(tf.unitDistance));
  x.commit(volume);
  ANARIWorld world = anariNewWorld(x.d);
  ANARIArray1D volumes = anariNewArray1D(x.d, nullptr, nullptr, nullptr, ANARI_VOLUME, 1);
  *static_cast<ANARIVolume *>(anariMapArray(x.d, volumes)) = volume;
  anariUnmapArray(x.d, volumes);
  x.setObj(world, "volume", ANARI_ARRAY1D, volumes);
  x.commit(world);

  ANARICamera camera = anariNewCamera(x.d, "orthographic");
  auto setView = [&](double azDeg, double elDeg) {
    const double az = azDeg * M_PI / 180, el = elDeg * M_PI / 180;
    const double dir[3] = {std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el)};
    const double dist = 3 * radius;
    const float pos[3] = {float(ctr[0] + dir[0] * dist), float(ctr[1] + dir[1] * dist),
        float(ctr[2] + dir[2] * dist)};
    const float look[3] = {float(-dir[0]), float(-dir[1]), float(-dir[2])};
    float up[3] = {0, 1, 0};
    if (std::fabs(std::cos(el)) < 1e-6)
      up[1] = 0, up[2] = -1;
    x.set3(camera, "position", pos);
    x.set3(camera, "direction", look);
    x.set3(camera, "up", up);
    x.setF(camera, "height", float(height));
    x.setF(camera, "aspect", float(aspect));
    x.commit(camera);
  };
  setView(0, elev);

  ANARIRenderer renderer = anariNewRenderer(x.d, rendererName.c_str());
  x.set(renderer, "background", ANARI_FLOAT32_VEC4, bg);
  x.setF(renderer, "volumeSamplingRate", samplingRate);
  if (settings == "fast") {
    x.setI(renderer, "pixelSamples", 1);
    x.setI(renderer, "ambientSamples", 0);
    x.setB(renderer, "denoise", false);
    x.setB(renderer, "checkerboarding", false);
  }
  if (visrtx && accumulate + 2 > 128)
    x.setI(renderer, "sampleLimit", 0); // no cap on progressive frames
  std::string extra;
  for (auto &p : a.kv) {
    if (p.first != "+set")
      continue;
    const size_t eq = p.second.find('=');
    if (eq == std::string::npos)
      fail("--set needs NAME=VALUE");
    const std::string name = p.second.substr(0, eq), val = p.second.substr(eq + 1);
    if (val == "true" || val == "false")
      x.setB(renderer, name.c_str(), val == "true");
    else if (val.find_first_of(".eE") == std::string::npos)
      x.setI(renderer, name.c_str(), int(num(val, name)));
    else
      x.setF(renderer, name.c_str(), float(num(val, name)));
    extra += " " + p.second;
  }
  x.commit(renderer);

  ANARIFrame frame = anariNewFrame(x.d);
  const uint32_t size[2] = {uint32_t(W), uint32_t(H)};
  x.set(frame, "size", ANARI_UINT32_VEC2, size);
  const ANARIDataType ct = colorType;
  x.set(frame, "channel.color", ANARI_DATA_TYPE, &ct);
  x.setObj(frame, "renderer", ANARI_RENDERER, renderer);
  x.setObj(frame, "camera", ANARI_CAMERA, camera);
  x.setObj(frame, "world", ANARI_WORLD, world);
  x.commit(frame);

  auto render = [&]() {
    anariRenderFrame(x.d, frame);
    anariFrameReady(x.d, frame, ANARI_WAIT);
  };
  auto gpuSeconds = [&]() {
    float s = 0;
    if (!anariGetProperty(x.d, frame, "duration", ANARI_FLOAT32, &s, sizeof s, ANARI_WAIT))
      return -1.0;
    return double(s);
  };
  render();
  const double firstS = since(t0);

  // The first frame's image (straight alpha, as SpaceSkip's encodePng).
  auto saveImage = [&]() {
    uint32_t fw = 0, fh = 0;
    ANARIDataType pt = ANARI_UNKNOWN;
    const void *px = anariMapFrame(x.d, frame, "channel.color", &fw, &fh, &pt);
    if (!px || int(fw) != W || int(fh) != H)
      fail("cannot map the colour buffer");
    std::vector<float> f(size_t(W) * H * 4);
    if (pt == ANARI_FLOAT32_VEC4)
      std::memcpy(f.data(), px, f.size() * 4);
    else if (pt == ANARI_UFIXED8_VEC4 || pt == ANARI_UFIXED8_RGBA_SRGB)
      for (size_t i = 0; i < f.size(); ++i)
        f[i] = static_cast<const uint8_t *>(px)[i] / 255.f;
    else
      fail(std::string("unexpected colour format ") + anari::toString(pt));
    anariUnmapFrame(x.d, frame, "channel.color");
    if (a.has("--raw")) {
      std::ofstream r(a.get("--raw"), std::ios::binary);
      r.write(reinterpret_cast<const char *>(f.data()), std::streamsize(f.size() * 4));
      if (!r)
        fail(a.get("--raw") + ": cannot write");
      std::printf("wrote %s (float32 RGBA %dx%d, premultiplied, bottom row first)\n", a.get("--raw").c_str(), W, H);
    }
    if (a.has("-o")) { // premultiplied, bottom row first: SpaceSkip's Image, written by its savePng
      spaceskip::Image img;
      img.width = W, img.height = H;
      img.rgba.resize(size_t(W) * H);
      std::memcpy(img.rgba.data(), f.data(), img.rgba.size() * sizeof(spaceskip::vec4f));
      spaceskip::savePng(img, a.get("-o"));
      std::printf("wrote %s\n", a.get("-o").c_str());
    }
  };
  if (accumulate == 0)
    saveImage();
  else {
    for (int i = 0; i < accumulate; ++i)
      render();
    saveImage();
  }

  // The orbit: camera commit + frame, each waited for; then again with the colour mapped.
  double gpuTotal = 0;
  bool haveGpu = true;
  auto orbit = [&](bool map) {
    const auto t = Clock::now();
    for (int f = 0; f < frames; ++f) {
      setView(azStep * f, elev);
      render();
      if (map) {
        uint32_t fw, fh;
        ANARIDataType pt;
        anariMapFrame(x.d, frame, "channel.color", &fw, &fh, &pt);
        anariUnmapFrame(x.d, frame, "channel.color");
      } else {
        const double g = gpuSeconds();
        if (g < 0)
          haveGpu = false;
        gpuTotal += g;
      }
    }
    return frames / since(t);
  };
  const double fps = orbit(false);
  const double gpuFps = haveGpu && gpuTotal > 0 ? frames / gpuTotal : 0;
  const double fpsMapped = orbit(true);

  // Opacity edits at the still view: new opacity array + volume commit -> frame waited for.
  setView(0, elev);
  render();
  std::vector<double> editMs, nextMs;
  for (int e = 0; e < edits; ++e) {
    const auto t = Clock::now();
    ANARIArray1D o = x.array1D(ANARI_FLOAT32, e % 2 == 0 ? cutOpacity.data() : opacity.data(), n, 4);
    x.setObj(volume, "opacity", ANARI_ARRAY1D, o);
    x.commit(volume);
    render();
    editMs.push_back(1e3 * since(t));
    anariRelease(x.d, o);
    const auto t1 = Clock::now();
    render();
    nextMs.push_back(1e3 * since(t1));
  }

  const std::string volName = volPath.substr(volPath.find_last_of('/') + 1);
  const std::string label = a.get("--label", libName + "/" + rendererName + "/" + settings);
  std::printf("volume %s: %llux%llux%llu %s, load %.3f s, value range [%g, %g], TF %s (%zu entries, unit %g)\n",
      volName.c_str(), (unsigned long long)dims[0], (unsigned long long)dims[1],
      (unsigned long long)dims[2], spaceskip::voxelTypeName(vol.v.type), loadS, tf.rangeMin, tf.rangeMax, tfSpec.c_str(), n, tf.unitDistance);
  std::printf("%s: renderer \"%s\" (settings %s%s), %dx%d, sample distance %g (volumeSamplingRate %g), "
              "elevation %g, azimuth step %g\n",
      libName.c_str(), rendererName.c_str(), settings.c_str(), extra.c_str(), W, H, sampleDistance, samplingRate,
      elev, azStep);
  std::printf("device init %.3f s; first frame %.3f s (arrays, commits, upload, frame)\n", initS, firstS);
  std::printf("fps %.2f (waited, %d frames), device-reported %.2f, with colour mapped %.2f\n", fps, frames, gpuFps,
      fpsMapped);
  if (edits)
    std::printf("TF edit -> frame: median %.3f ms (first %.3f, max %.3f); next frame median %.3f ms\n",
        median(editMs), editMs[0], *std::max_element(editMs.begin(), editMs.end()), median(nextMs));
  if (g_errors)
    std::printf("ANARI reported %d error(s)\n", g_errors);
  if (a.has("--csv")) {
    const std::string path = a.get("--csv");
    const bool fresh = !std::ifstream(path).good();
    std::ofstream c(path, std::ios::app);
    if (fresh)
      c << "label,library,renderer,settings,volume,dims,type,width,height,tf,sample_distance,sampling_rate,frames,"
           "load_s,init_s,first_frame_s,fps,fps_device,fps_mapped,edit_ms_median,edit_ms_first,next_ms_median,errors\n";
    c << label << "," << libName << "," << rendererName << "," << settings << "," << volName << ","
      << dims[0] << "x" << dims[1] << "x" << dims[2] << "," << spaceskip::voxelTypeName(vol.v.type) << "," << W << "," << H << ","
      << tfSpec << "," << sampleDistance << "," << samplingRate << "," << frames << "," << loadS << "," << initS
      << "," << firstS << "," << fps << "," << gpuFps << "," << fpsMapped << "," << median(editMs) << ","
      << (editMs.empty() ? 0 : editMs[0]) << "," << median(nextMs) << "," << g_errors << "\n";
    if (!c)
      fail(path + ": cannot write");
  }

  for (ANARIObject o : {(ANARIObject)frame, (ANARIObject)renderer, (ANARIObject)camera, (ANARIObject)world,
           (ANARIObject)volumes, (ANARIObject)volume, (ANARIObject)colorArr, (ANARIObject)opacityArr,
           (ANARIObject)field, (ANARIObject)data})
    anariRelease(x.d, o);
  anariRelease(x.d, x.d);
  anariUnloadLibrary(lib);
  return g_errors ? 2 : 0;
}

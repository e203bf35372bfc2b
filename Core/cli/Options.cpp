// Command-line parsing for the spaceskip CLI (see Options.h): every value is parsed whole and
// range-checked, so a typo gives a message naming the option instead of a crash or garbage.
#include "Options.h"

#include "Environment.h"

#include "spaceskip/Generators.h"
#include "spaceskip/render/Integrator.h"
#include "spaceskip/Parse.h"
#include "spaceskip/VolumeIO.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

namespace spaceskip::cli {

namespace {
std::invalid_argument bad(const std::string& what, const std::string& text, const std::string& why) {
  // Values are echoed shortened: a fuzzer or a pasted file must not flood the terminal.
  std::string shown = text.size() > 60 ? text.substr(0, 60) + "..." : text;
  return std::invalid_argument(what + ": '" + shown + "' " + why);
}

const std::set<std::string>& valueOptions() {
  static const std::set<std::string> s = {
      "-o", "--dims", "--seed", "--builder", "--builders", "--leaf", "--mls", "--bins", "--brick", "--backend",
      "--threads", "--tf", "--size", "--camera", "--sample-distance", "--ert", "--filter", "--compare",
      "--max-diff", "--frames", "--build-reps", "--json", "--csv", "--max-volume-bytes", "--blend", "--iso",
      "--shade", "--cuda-block", "--scale", "--datasets", "--time-limit", "--memory-budget",
      "--pool-brick", "--edit-tf", "--edits", "--edit-cut", "--max-image-bytes", "--label-map", "--hide-labels",
      "--toggles", "--visible-every", "--time-series", "--steps-held", "--step-type", "--step-memory", "--scatter", "--tf2d"};
  return s;
}
const std::set<std::string>& flagOptions() {
  static const std::set<std::string> s = {"--perspective", "--jitter", "--paper", "--no-in-core", "--nearest", "--check", "--rectilinear"};
  return s;
}

/// `s` cut at every `sep`, empty pieces kept ("4,,5" -> "4", "", "5").
std::vector<std::string> splitAt(const std::string& s, char sep) {
  std::vector<std::string> parts;
  size_t pos = 0;
  for (;;) {
    const size_t x = s.find(sep, pos);
    parts.push_back(s.substr(pos, x == std::string::npos ? std::string::npos : x - pos));
    if (x == std::string::npos) return parts;
    pos = x + 1;
  }
}
}  // namespace

int64_t parseIntArg(const std::string& text, const std::string& what, int64_t lo, int64_t hi) {
  int64_t v = 0;
  if (!parseInt64(text, v)) throw bad(what, text, "is not an integer");
  if (v < lo || v > hi)
    throw bad(what, text, "is out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

double parseDoubleArg(const std::string& text, const std::string& what, double lo, double hi) {
  double v = 0;
  if (!parseDouble(text, v)) throw bad(what, text, "is not a finite number");
  if (v < lo || v > hi) {
    std::ostringstream r;
    r << "is out of range [" << lo << ", " << hi << "]";
    throw bad(what, text, r.str());
  }
  return v;
}

int64_t Options::getInt(const std::string& k, int64_t def, int64_t lo, int64_t hi) const {
  return has(k) ? parseIntArg(get(k, ""), k, lo, hi) : def;
}

double Options::getDouble(const std::string& k, double def, double lo, double hi) const {
  return has(k) ? parseDoubleArg(get(k, ""), k, lo, hi) : def;
}

Options parseArgs(int argc, const char* const* argv, int first) {
  Options o;
  for (int i = first; i < argc; ++i) {
    std::string a = argv[i];
    if (a.rfind("--", 0) == 0 || a == "-o") {
      if (flagOptions().count(a)) {
        o.kv[a] = "1";
        continue;
      }
      if (!valueOptions().count(a))
        throw bad("command line", a, "is not an option (see spaceskip --help)");
      if (a == "--dims") {
        if (i + 3 >= argc) throw std::invalid_argument("--dims needs X Y Z");
        o.kv[a] = std::string(argv[i + 1]) + "x" + argv[i + 2] + "x" + argv[i + 3];
        i += 3;
        continue;
      }
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      o.kv[a] = argv[++i];
    } else {
      o.positional.push_back(a);
    }
  }
  return o;
}

vec3l parseDims(const std::string& s, const std::string& what) {
  const std::vector<std::string> parts = splitAt(s, 'x');
  if (parts.size() != 1 && parts.size() != 3) throw bad(what, s, "is not N or XxYxZ");
  int64_t v[3];
  for (size_t i = 0; i < parts.size(); ++i) v[i] = parseIntArg(parts[i], what + " (dims)", 1, kMaxAxisVoxels);
  return parts.size() == 1 ? vec3l{v[0], v[0], v[0]} : vec3l{v[0], v[1], v[2]};
}

void parseSize(const std::string& s, int& w, int& h) {
  const size_t x = s.find('x');
  if (x == std::string::npos) throw bad("--size", s, "is not WxH");
  w = int(parseIntArg(s.substr(0, x), "--size (width)", 1, kMaxImageSide));
  h = int(parseIntArg(s.substr(x + 1), "--size (height)", 1, kMaxImageSide));
}

uint64_t maxImageBytes(const Options& o) {
  if (!o.has("--max-image-bytes")) return kDefaultMaxImageBytes;
  uint64_t v = 0;
  const std::string s = o.get("--max-image-bytes", "");
  if (!parseByteCount(s, v) || v == 0)
    throw bad("--max-image-bytes", s, "is not a positive byte count (e.g. 1073741824 or 1G)");
  return v;
}

void imageSize(const Options& o, int& w, int& h) {
  if (o.has("--size")) parseSize(o.get("--size", ""), w, h);
  const uint64_t bytes = uint64_t(w) * uint64_t(h) * kImageBytesPerPixel, cap = maxImageBytes(o);
  if (bytes > cap) {
    char msg[320];
    std::snprintf(msg, sizeof msg,
                  "--size %dx%d: the image takes %llu bytes (%.2f GiB at %d bytes a pixel), more than the image "
                  "budget of %llu bytes (%.2f GiB); raise it with --max-image-bytes",
                  w, h, (unsigned long long)bytes, double(bytes) / 1073741824.0, int(kImageBytesPerPixel),
                  (unsigned long long)cap, double(cap) / 1073741824.0);
    throw std::invalid_argument(msg);
  }
}

void parseCamera(const std::string& s, double& az, double& el, double& zoom) {
  const std::vector<std::string> p = splitAt(s, ',');
  if (p.size() < 2 || p.size() > 3) throw bad("--camera", s, "is not AZ,EL[,ZOOM]");
  // Angles wrap; the bound only keeps them meaningful in float. Zoom > 0 keeps the view finite.
  az = parseDoubleArg(p[0], "--camera (azimuth)", -1e6, 1e6);
  el = parseDoubleArg(p[1], "--camera (elevation)", -1e6, 1e6);
  zoom = p.size() == 3 ? parseDoubleArg(p[2], "--camera (zoom)", 1e-6, 1e6) : 1.0;
}

uint64_t checkGeneratorSize(const std::string& shape, vec3l dims, uint64_t maxBytes) {
  // The generators emit uint8 except "noise" (float32) and "labels" of more than 255 labels
  // (uint16): Generators.h.
  const VoxelType t = shape == "noise"                ? VoxelType::Float32
                      : labelShapeCount(shape) > 255 ? VoxelType::UInt16
                                                      : VoxelType::UInt8;
  return checkedByteSize(dims, t, maxBytes, "generated volume '" + shape + "'");
}

bool parseGeneratorSpec(const std::string& spec, uint64_t maxBytes, std::string& shape, vec3l& dims) {
  if (spec.rfind("gen:", 0) != 0) return false;
  const std::string rest = spec.substr(4);
  const size_t c = rest.find(':');
  if (c == std::string::npos) throw bad("volume", spec, "is not gen:SHAPE:N or gen:SHAPE:XxYxZ");
  shape = rest.substr(0, c);
  dims = parseDims(rest.substr(c + 1), "volume " + spec.substr(0, 60));
  checkGeneratorSize(shape, dims, maxBytes);
  return true;
}

uint64_t maxVolumeBytes(const Options& o) {
  if (!o.has("--max-volume-bytes")) return maxVolumeBytesFromEnvironment(defaultMaxVolumeBytes());
  uint64_t v = 0;
  const std::string s = o.get("--max-volume-bytes", "");
  if (!parseByteCount(s, v) || v == 0)
    throw bad("--max-volume-bytes", s, "is not a positive byte count (e.g. 68719476736 or 64G)");
  return v;
}

int64_t memoryBudget(const Options& o) {
  if (!o.has("--memory-budget")) return 0;
  uint64_t v = 0;
  const std::string s = o.get("--memory-budget", "");
  if (!parseByteCount(s, v) || v == 0 || v > uint64_t(INT64_MAX))
    throw bad("--memory-budget", s, "is not a positive byte count (e.g. 1073741824 or 1G)");
  return int64_t(v);
}

int poolBrick(const Options& o) { return int(o.getInt("--pool-brick", 16, 1, 1024)); }

std::vector<std::string> split(const std::string& s, char c) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, c))
    if (!item.empty()) out.push_back(item);
  return out;
}

namespace {
// Limits shared by the options and the builder suffixes (the plugin's domains are tighter).
constexpr int64_t kMaxMls = int64_t(1) << 30, kMaxBins = 1 << 16, kMaxBrick = 1024;

int suffixNumber(const std::string& item, const std::string& key, const std::string& spec, int64_t lo, int64_t hi) {
  return int(parseIntArg(item.substr(key.size()), "builder suffix '" + key + "' in '" + spec.substr(0, 60) + "'", lo, hi));
}
}  // namespace

BuildParams buildParams(const Options& o, const std::string& spec) {
  BuildParams p;
  std::vector<std::string> parts = split(spec, ':');
  const std::string builder = parts.empty() ? spec : parts[0];
  if (!parseBuilder(builder, p.builder)) throw bad("builder", builder, "is not a builder");
  std::string leaf = o.get("--leaf", "deep");
  if (leaf == "shallow") p.leaf = LeafCriterion::Shallow;
  else if (leaf == "deep") p.leaf = LeafCriterion::Deep;
  else if (leaf == "empty") p.leaf = LeafCriterion::Empty;
  else throw bad("--leaf", leaf, "is not shallow, deep or empty");
  p.maxLeafSize = int(o.getInt("--mls", 0, 0, kMaxMls));
  p.bins = int(o.getInt("--bins", 4, 0, kMaxBins));
  p.brick = int(o.getInt("--brick", 8, 1, kMaxBrick));
  for (size_t i = 1; i < parts.size(); ++i) {
    const std::string& it = parts[i];
    if (it == "shallow") p.leaf = LeafCriterion::Shallow;
    else if (it == "deep") p.leaf = LeafCriterion::Deep;
    else if (it == "empty") p.leaf = LeafCriterion::Empty;
    else if (it.rfind("mls", 0) == 0) p.maxLeafSize = suffixNumber(it, "mls", spec, 0, kMaxMls);
    else if (it.rfind("bins", 0) == 0) p.bins = suffixNumber(it, "bins", spec, 0, kMaxBins);
    else if (it.rfind("brick", 0) == 0) p.brick = suffixNumber(it, "brick", spec, 1, kMaxBrick);
    else throw bad("builder suffix", it, "in '" + spec.substr(0, 60) + "' is not one of shallow deep empty mlsN binsN brickN");
  }
  try {
    validate(p);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("bad bins " + std::to_string(p.bins) + " in '" + spec.substr(0, 60) + "': " + e.what());
  }
  return p;
}

RenderParams renderParams(const Options& o) {
  RenderParams r;
  // 0 = the default (half the smallest spacing); the engine clamps tiny positive values.
  r.sampleDistance = o.getDouble("--sample-distance", 0, 0, 1e300);
  r.ertThreshold = o.getDouble("--ert", 2, 0, 1e300);
  r.jitter = o.has("--jitter");
  r.nearest = o.has("--nearest");
  if (o.has("--label-map")) {
    const std::string m = o.get("--label-map", "blend");
    if (m != "nearest" && m != "blend") throw bad("--label-map", m, "is not nearest or blend");
    r.labelMap = true;
    r.labelSampling = m == "nearest" ? LabelSampling::Nearest : LabelSampling::Blend;
  }
  std::string f = o.get("--filter", "exact");
  if (f == "exact") r.filter = FilterMode::Exact;
  else if (f == "hardware") r.filter = FilterMode::Hardware;
  else throw bad("--filter", f, "is not exact or hardware");
  const std::string blend = o.get("--blend", "composite");
  const std::pair<const char*, BlendMode> modes[] = {
      {"composite", BlendMode::Composite}, {"mip", BlendMode::MaximumIntensity},
      {"minip", BlendMode::MinimumIntensity}, {"average", BlendMode::AverageIntensity},
      {"additive", BlendMode::Additive}, {"iso", BlendMode::Isosurface}};
  bool known = false;
  for (const auto& m : modes)
    if (blend == m.first) {
      r.blend = m.second;
      known = true;
    }
  if (!known) throw bad("--blend", blend, "is not composite, mip, minip, average, additive or iso");
  if (o.has("--iso"))
    for (const std::string& v : split(o.get("--iso", ""), ','))
      r.isoValues.push_back(parseDoubleArg(v, "--iso", -1e300, 1e300));
  if (r.blend == BlendMode::Isosurface && r.isoValues.empty())
    throw bad("--blend", blend, "needs --iso V1,V2,...");
  if (r.isoValues.size() > size_t(kMaxIsoValues))
    throw bad("--iso", o.get("--iso", ""), "has more than " + std::to_string(kMaxIsoValues) + " values");
  if (o.has("--shade")) {  // "on" (VTK's coefficients) or AMBIENT,DIFFUSE,SPECULAR,POWER
    r.shade = true;
    const std::string sh = o.get("--shade", "on");
    if (sh != "on") {
      std::vector<std::string> c = split(sh, ',');
      if (c.size() != 4) throw bad("--shade", sh, "is not on or AMBIENT,DIFFUSE,SPECULAR,POWER");
      r.ambient = parseDoubleArg(c[0], "--shade (ambient)", 0, 1);
      r.diffuse = parseDoubleArg(c[1], "--shade (diffuse)", 0, 1);
      r.specular = parseDoubleArg(c[2], "--shade (specular)", 0, 1);
      r.specularPower = parseDoubleArg(c[3], "--shade (specular power)", 0, 128);
    }
  }
  if (o.has("--scatter")) {  // BLENDING,REACH,ANISOTROPY: volumetric shadows and scattering (shades)
    const std::string sc = o.get("--scatter", "");
    std::vector<std::string> c = split(sc, ',');
    if (c.size() != 3) throw bad("--scatter", sc, "is not BLENDING,REACH,ANISOTROPY");
    r.scatteringBlending = parseDoubleArg(c[0], "--scatter (blending)", 0, 2);
    r.globalIlluminationReach = parseDoubleArg(c[1], "--scatter (reach)", 0, 1);
    r.scatteringAnisotropy = parseDoubleArg(c[2], "--scatter (anisotropy)", -1, 1);
    r.shade = true;
  }
  return r;
}

LabelTable labelTable(const Options& o, const Volume& v) {
  LabelTable t;
  double lo = 0, hi = -1;
  if (!isLabelType(v.type) || v.components != 1 || !v.scalarRange(lo, hi)) return t;
  std::set<int64_t> hidden;
  if (o.has("--hide-labels"))
    for (const std::string& id : split(o.get("--hide-labels", ""), ','))
      hidden.insert(parseIntArg(id, "--hide-labels", -32768, 65535));
  for (int id = int(lo); id <= int(hi); ++id) {
    if (id == 0) continue;  // the background
    Label l;
    l.id = id;
    // Hues by the golden ratio: neighbouring ids far apart in colour.
    const double h = std::fmod(id * 0.618033988749895, 1.0) * 6.0;
    const double x = 1.0 - std::fabs(std::fmod(h, 2.0) - 1.0);
    const double rgb[6][3] = {{1, x, 0}, {x, 1, 0}, {0, 1, x}, {0, x, 1}, {x, 0, 1}, {1, 0, x}};
    const double* c = rgb[int(h) % 6];
    l.r = float(0.2 + 0.8 * c[0]);
    l.g = float(0.2 + 0.8 * c[1]);
    l.b = float(0.2 + 0.8 * c[2]);
    l.opacity = 0.5f;
    l.visible = hidden.count(id) == 0;
    t.labels.push_back(l);
  }
  return t;
}

BackendKind backendKind(const Options& o) {
  std::string b = o.get("--backend", "auto");
  if (b == "auto") return BackendKind::Auto;
  if (b == "cpu") return BackendKind::CPU;
  if (b == "cuda") return BackendKind::CUDA;
  throw bad("--backend", b, "is not auto, cpu or cuda");
}

Tuning tuning(const Options& o) {
  Tuning p = tuningFromEnvironment();
  if (o.has("--cuda-block")) {
    const std::string b = o.get("--cuda-block", "");
    const size_t x = b.find('x');
    if (x == std::string::npos) throw bad("--cuda-block", b, "is not WxH");
    p.blockX = int(parseIntArg(b.substr(0, x), "--cuda-block (width)", 1, 256));
    p.blockY = int(parseIntArg(b.substr(x + 1), "--cuda-block (height)", 1, 256));
    if (p.blockX * p.blockY < 32 || p.blockX * p.blockY > 256) throw bad("--cuda-block", b, "is not 32..256 threads");
  }
  return p;
}

BenchItem benchItem(const std::string& item) {
  BenchItem it;
  for (const std::string& part : split(item, ':')) {
    if (part == "hw") it.filter = int(FilterMode::Hardware);
    else if (part == "exact") it.filter = int(FilterMode::Exact);
    else if (part == "cold") it.cold = true;
    else if (part == "whole") it.parts = -1;
    else if (part.size() > 5 && part.rfind("parts", 0) == 0 && part.find_first_not_of("0123456789", 5) == std::string::npos)
      it.parts = int(parseIntArg(part.substr(5), "bench suffix 'parts'", 0, 64));
    else if (part.size() > 3 && part.rfind("res", 0) == 0 && part.find_first_not_of("0123456789", 3) == std::string::npos)
      it.resident = int(parseIntArg(part.substr(3), "bench suffix 'res'", 0, 1024));
    else it.spec += (it.spec.empty() ? "" : ":") + part;
  }
  return it;
}

}  // namespace spaceskip::cli

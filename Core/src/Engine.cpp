// Engine: keeps scene state, decides what a change requires, and falls back from CUDA to CPU.
#include "spaceskip/Engine.h"

#include "spaceskip/Backend.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>

namespace spaceskip {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct BuilderName {
  BuilderKind kind;
  const char* vtk;
  const char* cli;
};
constexpr BuilderName kBuilders[] = {
    {BuilderKind::Naive, "Naive", "naive"},
    {BuilderKind::Grid, "Grid", "grid"},
    {BuilderKind::LBVH, "LBVH", "lbvh"},
    {BuilderKind::LBVHCPU, "LBVHCPU", "lbvh-cpu"},
    {BuilderKind::KdTreeCPU, "KdTreeCPU", "kdtree-cpu"},
    {BuilderKind::KdTreeGPU, "KdTreeGPU", "kdtree-gpu"},
    {BuilderKind::KdTreeGPUFast, "KdTreeGPUFast", "kdtree-gpu-fast"},
    {BuilderKind::Hybrid, "Hybrid", "hybrid"},
    {BuilderKind::DistanceGrid, "DistanceGrid", "distance-grid"},
};

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}
}  // namespace

const char* builderName(BuilderKind b) {
  for (const auto& n : kBuilders)
    if (n.kind == b) return n.vtk;
  return "?";
}

bool parseBuilder(const std::string& s, BuilderKind& out) {
  std::string l = lower(s);
  for (const auto& n : kBuilders)
    if (l == n.cli || l == lower(n.vtk)) {
      out = n.kind;
      return true;
    }
  if (l == "macrocellgrid") { out = BuilderKind::Grid; return true; }
  return false;
}

struct Engine::Impl {
  BackendKind requested;
  std::unique_ptr<Backend> backend;
  std::function<void(const std::string&)> log = [](const std::string& m) { std::cerr << "spaceskip: " << m << "\n"; };

  Volume volume;
  bool haveVolume = false;
  TransferFunction tf;
  bool haveTF = false;
  BuildParams build;
  RenderParams render;

  bool rangesDirty = true, opacityDirty = true, colorDirty = true, buildDirty = true, tableDirty = true;
  BuildStats stats;
  FrameStats frame;
  Counters counters;

  void chooseBackend() {
    if (requested == BackendKind::CPU) {
      backend = makeCpuBackend();
      return;
    }
    try {
      backend = makeCudaBackend();
    } catch (const BackendError& e) {
      if (requested == BackendKind::CUDA) log(std::string("CUDA backend unavailable (") + e.what() + "); using the CPU backend");
      backend = makeCpuBackend();
    }
  }

  void fallBackToCpu(const std::string& why) {
    log("CUDA backend failed (" + why + "); falling back to the CPU backend");
    backend = makeCpuBackend();
    rangesDirty = opacityDirty = buildDirty = tableDirty = true;
  }

  double dt() const {
    if (render.sampleDistance > 0) return render.sampleDistance;
    double s = std::min({volume.spacing[0], volume.spacing[1], volume.spacing[2]});
    return 0.5 * (s > 0 ? s : 1.0);
  }

  void update() {
    if (!haveVolume) throw std::runtime_error("no volume set");
    if (!haveTF) throw std::runtime_error("no transfer function set");
    if (rangesDirty) {
      backend->setVolume(volume, build.brick);
      ++counters.rangeGrids;
      rangesDirty = false;
      opacityDirty = true;
      buildDirty = true;
    }
    if (opacityDirty) {
      auto t0 = Clock::now();
      bool changed = backend->classify(tf);
      stats.classifySeconds = since(t0);
      ++counters.classifications;
      opacityDirty = false;
      tableDirty = true;
      if (changed) buildDirty = true;
    }
    if (tableDirty || colorDirty) {
      if (!tableDirty) ++counters.colorUpdates;
      const float lo = float(tf.rangeMin);
      const float scale = float(double(tf.table.size() - 1) / std::max(tf.rangeMax - tf.rangeMin, 1e-30));
      backend->setTransferTable(tableForBlend(tf, float(dt()), render.blend), lo, scale);
      tableDirty = colorDirty = false;
    }
    if (buildDirty) {
      BuildParams p = build;
      bool gpuOnly = p.builder == BuilderKind::KdTreeGPU || p.builder == BuilderKind::KdTreeGPUFast;
      if (gpuOnly && backend->kind() != BackendKind::CUDA) {
        log(std::string("builder ") + builderName(p.builder) + " needs the CUDA backend; building KdTreeCPU with the same parameters");
        p.builder = BuilderKind::KdTreeCPU;
      }
      BuildStats s;
      try {
        backend->build(p, s);
      } catch (const BackendError& e) {
        if (backend->kind() == BackendKind::CUDA) throw;
        log(std::string(e.what()) + "; using the Grid traversal");
        p.builder = BuilderKind::Grid;
        backend->build(p, s);
      }
      s.builder = p.builder;
      s.classifySeconds = stats.classifySeconds;
      s.occupancy = backend->occupancy().occupancy();
      stats = s;
      ++counters.builds;
      buildDirty = false;
    }
  }
};

Engine::Engine(BackendKind backend) : impl_(new Impl) {
  impl_->requested = backend;
  impl_->chooseBackend();
}
Engine::Engine(BackendKind backend, std::function<void(const std::string&)> log) : impl_(new Impl) {
  impl_->requested = backend;
  if (log) impl_->log = std::move(log);
  impl_->chooseBackend();
}
Engine::~Engine() = default;

BackendKind Engine::backendKind() const { return impl_->backend->kind(); }
const char* Engine::backendName() const { return impl_->backend->name(); }
void Engine::setLogger(std::function<void(const std::string&)> log) { impl_->log = std::move(log); }

void Engine::setVolume(const Volume& v) {
  validate(v);
  impl_->volume = v;
  impl_->haveVolume = true;
  impl_->rangesDirty = true;
  impl_->tableDirty = true;  // the default sample distance follows the spacing
}

void Engine::setTransferFunction(const TransferFunction& tf) {
  if (tf.table.empty()) throw std::invalid_argument("empty transfer-function table");
  Impl& d = *impl_;
  if (!d.haveTF || !tf.sameOpacity(d.tf)) d.opacityDirty = true;
  else if (!tf.sameColor(d.tf)) d.colorDirty = true;
  d.tf = tf;
  d.haveTF = true;
}

void Engine::setBuildParams(const BuildParams& p) {
  // bins 1 would mean no candidate plane at all; rejected rather than silently clamped, since 0
  // (the sweep) is now a meaningful value next to it.
  if (p.bins < 0 || p.bins == 1)
    throw std::invalid_argument("bins must be 0 (sweep every brick boundary) or >= 2, got " + std::to_string(p.bins));
  Impl& d = *impl_;
  if (p.brick != d.build.brick) d.rangesDirty = true;
  if (p != d.build) d.buildDirty = true;
  d.build = p;
  d.build.brick = std::max(1, p.brick);
}

void Engine::setRenderParams(const RenderParams& p) {
  if (p.sampleDistance != impl_->render.sampleDistance || p.blend != impl_->render.blend) impl_->tableDirty = true;
  impl_->render = p;
}

const BuildParams& Engine::buildParams() const { return impl_->build; }
const RenderParams& Engine::renderParams() const { return impl_->render; }

void Engine::update() {
  Impl& d = *impl_;
  try {
    d.update();
  } catch (const BackendError& e) {
    if (d.backend->kind() != BackendKind::CUDA) throw;
    d.fallBackToCpu(e.what());
    d.update();
  }
}

namespace {
/// The blend-mode and shading part of the frame from the render parameters.
template <class Impl>
void fillBlend(Impl& d, FrameView& f) {
  const RenderParams& r = d.render;
  f.blend = r.blend;
  double lo = r.scalarRange[0], hi = r.scalarRange[1];
  if (!(lo < hi)) {
    lo = d.tf.rangeMin;
    hi = d.tf.rangeMax;
  }
  f.normLo = float(lo);
  f.normScale = hi > lo ? float(1.0 / (hi - lo)) : 0.f;
  f.avgLo = float(std::max(r.averageRange[0], -double(HUGE_VALF)));
  f.avgHi = float(std::min(r.averageRange[1], double(HUGE_VALF)));
  std::vector<double> iso = r.isoValues;
  std::sort(iso.begin(), iso.end());
  if (iso.size() > size_t(kMaxIsoValues)) {
    d.log("isosurface: " + std::to_string(iso.size()) + " iso values, using the lowest " +
          std::to_string(kMaxIsoValues));
    iso.resize(size_t(kMaxIsoValues));
  }
  f.numIso = int(iso.size());
  for (int i = 0; i < f.numIso; ++i) f.iso[i] = float(iso[size_t(i)]);
  f.shade = r.shade && (r.blend == BlendMode::Composite || r.blend == BlendMode::Isosurface) ? 1 : 0;
  f.ambient = float(r.ambient);
  f.diffuse = float(r.diffuse);
  f.specular = float(r.specular);
  f.specularPower = float(r.specularPower);
  f.lightDir = vec3f{float(r.lightDirection[0]), float(r.lightDirection[1]), float(r.lightDirection[2])};
}
}  // namespace

void Engine::render(const Camera& cam, int width, int height, Image& out, const float* depth) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("render size must be positive");
  update();
  Impl& d = *impl_;
  FrameView f{};
  mat4 vp = multiply(cam.proj, cam.view), ivp;
  if (!invert(vp, ivp)) throw std::invalid_argument("camera matrix is singular");
  for (int i = 0; i < 16; ++i) f.invViewProj[i] = float(ivp.m[i]);
  mat4 w2i;
  if (!invert(d.volume.indexToWorld(), w2i)) throw std::invalid_argument("volume direction/spacing is singular");
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) f.worldToIndex[r * 4 + c] = float(w2i.m[c * 4 + r]);
  f.width = width;
  f.height = height;
  vec3i cd = d.volume.cellDims();
  f.boxHi = vec3f{float(cd.x), float(cd.y), float(cd.z)};
  f.dt = float(d.dt());
  f.ertThreshold = d.render.ertThreshold > 1.0 ? 2.f : float(d.render.ertThreshold);
  f.jitter = d.render.jitter ? 1 : 0;
  f.jitterSeed = d.render.jitterSeed;
  f.firstSample = float(std::max(0.0, d.render.firstSampleOffset));
  mat4 iv;
  if (!invert(cam.view, iv)) throw std::invalid_argument("camera view matrix is singular");
  f.eyeW = vec3f{float(iv.m[12]), float(iv.m[13]), float(iv.m[14])};
  fillBlend(d, f);
  std::vector<unsigned> counts;
  if (d.render.countSamples) {
    counts.assign(size_t(width) * size_t(height), 0u);
    f.sampleCount = counts.data();
  }
  auto t0 = Clock::now();
  try {
    d.backend->render(f, d.render.filter, depth, out);
  } catch (const BackendError& e) {
    if (d.backend->kind() != BackendKind::CUDA) throw;
    d.fallBackToCpu(e.what());
    d.update();
    d.backend->render(f, d.render.filter, depth, out);
  }
  d.frame.seconds = since(t0);
  d.frame.deviceSeconds = d.backend->lastFrameDeviceSeconds();
  d.frame.samples = -1;
  if (d.render.countSamples) {
    d.frame.samples = 0;
    for (unsigned c : counts) d.frame.samples += c;
  }
  d.frame.backend = d.backend->name();
  ++d.counters.frames;
}

const BuildStats& Engine::buildStats() const { return impl_->stats; }
const FrameStats& Engine::frameStats() const { return impl_->frame; }
const Counters& Engine::counters() const { return impl_->counters; }
const OccupancyGrid& Engine::occupancy() {
  update();
  return impl_->backend->occupancy();
}
Tree Engine::tree() {
  update();
  return impl_->backend->tree();
}
double Engine::sampleDistance() const { return impl_->dt(); }

}  // namespace spaceskip

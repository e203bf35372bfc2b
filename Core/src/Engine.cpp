// Engine: keeps scene state, decides what a change requires, and falls back from CUDA to CPU.
#include "spaceskip/Engine.h"

#include "spaceskip/AutoBuilder.h"
#include "spaceskip/Backend.h"
#include "spaceskip/Builders.h"
#include "spaceskip/GradientBound.h"
#include "spaceskip/StepMemory.h"

#include <algorithm>
#include <chrono>
#include <cfloat>
#include <cmath>
#include <iostream>
#include <cstdio>
#include <cstring>
#include <limits>
#include <set>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace spaceskip {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// out[i] = in[i] * 2^exponent in float, in parallel (ldexp: exact, NaN and +-Inf kept).
template <class T>
void scaleToFloat(const T* in, float* out, int64_t n, int exponent) {
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, n, int64_t(1) << 16), [=](const tbb::blocked_range<int64_t>& r) {
    for (int64_t i = r.begin(); i < r.end(); ++i) out[i] = float(std::ldexp(double(in[i]), exponent));
  });
}
}  // namespace

double effectiveSampleDistance(const Volume& v, double requested, std::string* note) {
  const double minSpacing = std::min({v.spacing[0], v.spacing[1], v.spacing[2]});
  const double voxel = minSpacing > 0 && std::isfinite(minSpacing) ? minSpacing : 1.0;
  const bool automatic = !(requested > 0) || !std::isfinite(requested);
  double dt = automatic ? 0.5 * voxel : requested;
  const vec3i cd = v.cellDims();
  // hypot: no overflow for spacings near double's end (1e300 * cells).
  const double diagonal = std::hypot(cd.x * v.spacing[0], cd.y * v.spacing[1], cd.z * v.spacing[2]);
  // A ray crosses at most cd.x + cd.y + cd.z cells (+1) whatever the spacings.
  const double cellsCrossed = double(cd.x) + double(cd.y) + double(cd.z);
  const double maxSamples = std::min(kMaxSamplesPerRay, kMaxSamplesPerCell * cellsCrossed);
  const double floorDt = voxel / kMinStepsPerVoxel, capDt = diagonal / maxSamples, maxDt = 0.5 * diagonal;
  std::string why;
  char buf[512];
  if (dt > maxDt && maxDt > 0) {
    dt = maxDt;
    std::snprintf(buf, sizeof buf, "larger than half the volume's diagonal (%g world units)", diagonal);
    why = buf;
  }
  if (dt < floorDt) {
    dt = floorDt;
    why = "below the floor of 1/" + std::to_string(int(kMinStepsPerVoxel)) + " of the smallest voxel spacing";
  }
  if (dt < capDt) {
    dt = capDt;
    std::snprintf(buf, sizeof buf,
                  "more than %.0f samples a ray through the volume: at most %g per cell a ray can cross "
                  "(%.0f cells along x + y + z) and at most %.0f",
                  maxSamples, kMaxSamplesPerCell, cellsCrossed, kMaxSamplesPerRay);
    why = buf;
  }
  if (note) {
    note->clear();
    if (!why.empty()) {
      if (automatic)
        std::snprintf(buf, sizeof buf, "the automatic sample distance (half the smallest spacing, %g) clamped: using %g world units (%s)",
                      0.5 * voxel, dt, why.c_str());
      else
        std::snprintf(buf, sizeof buf, "sample distance %g clamped: using %g world units (%s)", requested, dt,
                      why.c_str());
      *note = buf;
    }
  }
  return dt;
}

struct Engine::Impl {
  BackendKind requested;
  std::unique_ptr<Backend> backend;
  std::function<void(const std::string&)> log = [](const std::string& m) { std::cerr << "spaceskip: " << m << "\n"; };
  std::function<void(double, const char*)> progress;  ///< setProgress
  void report(double fraction, const char* step) const {
    if (progress) progress(std::clamp(fraction, 0.0, 1.0), step);
  }
  /// The backend's hook: its fraction of a frame as the last fifth of the engine's work.
  std::function<void(double)> backendProgress() {
    if (!progress) return {};
    return [this](double f) { report(0.8 + 0.2 * f, "frame"); };
  }

  Volume volume;
  int valueExponent = 0;  ///< voxel values (and so the TF range) times 2^this; see setVolume
  Volume sourceShape;     ///< the last setVolume's volume as given (no voxels): time steps
  bool magnitudePending = false;  ///< float32 magnitudes to check at the next ranges (setVolume)
  bool haveVolume = false;
  TransferFunction tf;
  bool haveTF = false;
  // Label maps (RenderParams::labelMap, LabelMap.h). While `labelOn`, `tf` is the label table's
  // (labelTransferFunction) and the caller's transfer function waits in `userTF`.
  LabelTable labels;
  bool labelOn = false, labelSetsDirty = true, labelTFDirty = true, labelTFValid = false;
  LabelSets labelSets;
  std::vector<uint8_t> drawn;  ///< per value of labelSets' range: a visible label of opacity > 0
  TransferFunction userTF;
  bool haveUserTF = false;

  bool wantsLabels() const {
    return render.labelMap && haveVolume && volume.components == 1 && isLabelType(volume.type);
  }
  /// Enters or leaves label-map drawing as RenderParams::labelMap and the volume ask.
  void syncLabelMode() {
    if (render.labelMap && haveVolume && !wantsLabels())
      warn("label map: needs one component of 8- or 16-bit integers; drawn as an ordinary volume");
    const bool want = wantsLabels();
    if (want == labelOn) return;
    if (want) {
      userTF = tf;
      haveUserTF = haveTF;
      labelTFValid = false;
      labelTFDirty = true;
    } else {
      tf = userTF;
      haveTF = haveUserTF;
    }
    labelOn = want;
    opacityDirty = tableDirty = true;
  }
  /// The label table as a transfer function, and what its edit needs: a change of which labels
  /// are drawn re-classifies (over the label sets), an opacity change re-makes the table only, a
  /// colour change updates it.
  void refreshLabelTF() {
    if (!labelOn) return;
    if (labelSetsDirty) {
      report(0.2, "label sets");
      labelSets = computeLabelSets(volume, build.brick);
      ++counters.labelSets;
      ++counters.voxelPasses;
      labelSetsDirty = false;
      labelTFValid = false;
      labelTFDirty = true;
    }
    if (!labelTFDirty) return;
    TransferFunction t = labelTransferFunction(labels, labelSets.lo, labelSets.hi);
    std::vector<uint8_t> dr = drawnLabels(labels, labelSets.lo, labelSets.hi);
    if (!labelTFValid || dr != drawn || t.table.size() != tf.table.size() || t.rangeMin != tf.rangeMin)
      opacityDirty = true;
    else if (!t.sameOpacity(tf))
      tableDirty = true;
    else if (!t.sameColor(tf))
      colorDirty = true;
    tf = std::move(t);
    haveTF = true;
    drawn = std::move(dr);
    labelTFDirty = false;
    labelTFValid = true;
  }
  BuildParams build;
  RenderParams render;
  int64_t memoryBudget = 0;  ///< setMemoryBudget (0: the backend's default)
  int poolBrick = 16;
  Tuning tuning;      ///< setTuning, handed to every backend made
  VolumePiece piece;  ///< inactive: the volume is whole

  bool rangesDirty = true, opacityDirty = true, colorDirty = true, buildDirty = true, tableDirty = true;
  /// What cropping and clipping leave drawn, in index space: the FrameView's planes and what the
  /// occupancy was last classified against (a change re-classifies; a camera change does not).
  CropClip cropClip;
  bool cropClipDirty = false;
  BuildStats stats;
  FrameStats frame;
  /// frame.deviceSeconds is still to be read from the backend (it waits for a frame left on the
  /// device, so only a caller who asks for it waits: frameStats()).
  bool deviceSecondsPending = false;
  Counters counters;

  double frameDeviceSeconds() {
    if (deviceSecondsPending) {
      deviceSecondsPending = false;
      frame.deviceSeconds = backend->lastFrameDeviceSeconds();
      frame.queuedShadowRays = backend->lastFrameQueuedShadowRays();
      frame.longestBlockSeconds = backend->lastFrameLongestBlockSeconds();
    }
    return frame.deviceSeconds;
  }

  AutoBuilder autoBuilder;  ///< Builder Auto's measuring (AutoBuilder.h)

  AutoBuilder::ViewKey viewKey(const Camera& cam) const {
    double b[6];
    volume.worldBounds(b);
    return AutoBuilder::viewKey(cam, b);
  }
  void startAuto(bool afterEdit = false) { autoBuilder.start(build, backend->kind(), afterEdit); }
  std::function<double()> occupied() const {
    return [this] { return backend->occupiedFraction(); };
  }
  /// Auto on probes (AutoBuilder::measureOnProbes) before the user's frame `full` is drawn: each
  /// probe is `full` reduced, drawn with the candidate the AutoBuilder asks for.
  void measureOnProbes(const FrameView& full, int width, int height, const AutoBuilder::ViewKey& view) {
    FrameView p = full;
    p.depth = nullptr;  // per pixel of the user's frame
    p.alphaIn = nullptr;
    p.sampleCount = nullptr;
    Image img;
    auto drawProbe = [&](int pw, int ph) {
      p.width = pw;
      p.height = ph;
      update();  // builds the candidate to measure
      const auto t0 = Clock::now();
      backend->render(p, render.filter, nullptr, img);
      ++counters.autoProbeFrames;
      return backend->lastFrameDeviceSeconds() > 0 ? backend->lastFrameDeviceSeconds() : since(t0);
    };
    auto progress = [this](double f) { report(0.5 + 0.3 * f, "measuring"); };
    bool decided = false;
    if (!autoBuilder.measureOnProbes(width, height, view, drawProbe, progress, occupied(), decided)) return;
    if (decided) stats.choice = autoBuilder.choice();
    ++counters.autoProbeMeasurings;
  }

  void chooseBackend() {
    if (requested == BackendKind::CPU) {
      backend = makeCpuBackend();
      backend->setMemoryBudget(memoryBudget, poolBrick);
      backend->setTuning(tuning);
      return;
    }
    try {
      backend = makeCudaBackend();
      backend->setMemoryBudget(memoryBudget, poolBrick);
      backend->setTuning(tuning);
    } catch (const BackendError& e) {
      if (requested == BackendKind::CUDA) warn(std::string("CUDA backend unavailable (") + e.what() + "); using the CPU backend");
      backend = makeCpuBackend();
      backend->setTuning(tuning);
    }
  }

  // Each distinct message is said once per engine: a soak of TF edits or builder switches must
  // not repeat the same fallback hundreds of times in ParaView's output window.
  std::set<std::string> said;
  void warn(const std::string& m) {
    if (said.insert(m).second) log(m);
  }

  void fallBackToCpu(const std::string& why) {
    warn("CUDA backend failed (" + why + "); falling back to the CPU backend");
    backend = makeCpuBackend();
    backend->setProgress(backendProgress());
    backend->setTuning(tuning);
    rangesDirty = opacityDirty = buildDirty = tableDirty = true;
    autoBuilder.reset();
  }

  /// 4 dependent components: the colour channels' finite ranges (of the sampled values).
  double rgbRange[3][2] = {{0, 1}, {0, 1}, {0, 1}};
  /// When `m` (the largest finite |value|) is beyond 2^+-60: `volume` becomes a float copy of
  /// the caller's voxels scaled by 2^-e (m * 2^-e in [0.5, 1); ldexp is exact and reaches
  /// denormal scales a factor can't), valueExponent -e; the TF range is scaled alike, so the
  /// image is the one of the unscaled data. NaN stays NaN and +-Inf stays +-Inf. True if scaled.
  bool scaleExtremeFloats(double m) {
    if (!(m > 0 && (m > 0x1p60 || m < 0x1p-60))) return false;
    const Volume v = volume;  // the caller's voxels (called once per setVolume, before any scaling)
    const int64_t n = v.voxelCount() * v.components;
    int e = 0;
    std::frexp(m, &e);
    auto copy = std::make_shared<std::vector<unsigned char>>(size_t(n) * sizeof(float));
    float* out = reinterpret_cast<float*>(copy->data());
    if (v.type == VoxelType::Float32) scaleToFloat(static_cast<const float*>(v.data), out, n, -e);
    else scaleToFloat(static_cast<const double*>(v.data), out, n, -e);
    volume.type = VoxelType::Float32;
    volume.storage = copy;
    volume.data = copy->data();
    valueExponent = -e;
    return true;
  }

  /// The float32 magnitude check setVolume left to the ranges: from the backend's brick ranges
  /// (or, where it has none or they are not finite, the host's range pass); a volume that needs
  /// scaling is set on the backend again as its scaled copy.
  void checkMagnitudes() {
    if (!magnitudePending) return;
    magnitudePending = false;
    double lo = 0, hi = 0;
    bool known = backend->brickValueRange(lo, hi) && std::isfinite(lo) && std::isfinite(hi);
    if (!known) {
      ++counters.voxelPasses;
      known = volume.scalarRange(lo, hi);
    }
    if (known && scaleExtremeFloats(std::max(std::fabs(lo), std::fabs(hi)))) backend->setVolume(volume, build.brick);
  }

  void componentRanges() {
    if (volume.components != 4) return;
    for (int c = 0; c < 3; ++c)
      if (!volume.componentRange(c, rgbRange[c][0], rgbRange[c][1])) rgbRange[c][0] = 0, rgbRange[c][1] = 1;
  }

  /// Dependent components composite (the only mode vtkGPUVolumeRayCastMapper defines colour and
  /// opacity for from several components): other blend modes are drawn composite, with a warning.
  BlendMode blendMode() {
    if (labelOn && render.blend != BlendMode::Composite) {
      warn("blend mode " + std::to_string(int(render.blend)) + " with a label map is not supported: drawn as composite");
      return BlendMode::Composite;
    }
    if (volume.components > 1 && render.blend != BlendMode::Composite) {
      warn("blend mode " + std::to_string(int(render.blend)) + " with " + std::to_string(volume.components) +
           " dependent components is not supported: drawn as composite");
      return BlendMode::Composite;
    }
    return render.blend;
  }

  /// The TF's 2-D table or gradient opacity is used: composite blending of one-component
  /// volumes, or a 2-D table over two components (its x and y values); otherwise the 1-D tables
  /// draw, said once by fillGradientTF. Classification follows it (classificationTF), so a
  /// change of it re-classifies (setRenderParams).
  bool gradientTablesUsed() const {
    if (render.blend != BlendMode::Composite) return false;
    return volume.components == 1 ? tf.uses2D() || tf.usesGradientOpacity() : volume.components == 2 && tf.uses2D();
  }
  /// The 2-D table's and the gradient opacity's first entries in the uploaded table (updateTable).
  int gradOffset2D = -1, gradOffsetGO = -1;

  /// scaledTF without a 2-D table (one that is not drawn: the backends classify with any they get).
  TransferFunction oneDTF() const {
    TransferFunction t = scaledTF();
    t.table2D.clear();
    t.width2D = t.height2D = 0;
    return t;
  }

  TransferFunction scaledTF() const {
    if (valueExponent == 0) return tf;
    TransferFunction t = tf;
    t.rangeMin = std::ldexp(t.rangeMin, valueExponent);
    t.rangeMax = std::ldexp(t.rangeMax, valueExponent);
    t.opacityRangeMin = std::ldexp(t.opacityRangeMin, valueExponent);
    t.opacityRangeMax = std::ldexp(t.opacityRangeMax, valueExponent);
    return t;
  }

  double dt() const { return effectiveSampleDistance(latticeShape(), render.sampleDistance); }

  /// The volume whose box the rays cross, for the sample-distance bounds: the whole volume's
  /// when this is a piece of it (every rank then steps alike), else the volume itself.
  Volume latticeShape() const {
    if (!piece.active()) return volume;
    Volume v = volume;
    v.dims = piece.wholeDims;
    return v;
  }

  /// The piece, when it fits the volume (said once otherwise, and rendered whole).
  const VolumePiece* fittingPiece() {
    if (!piece.active()) return nullptr;
    const vec3i cd = volume.cellDims();
    bool ok = true;
    for (int a = 0; a < 3; ++a) {
      const int64_t wholeCells = std::max<int64_t>(piece.wholeDims[a] - 1, 1);
      ok = ok && piece.offset[a] >= 0 && piece.offset[a] + volume.dims[a] <= piece.wholeDims[a] &&
           piece.ownedLo[a] >= piece.offset[a] && piece.ownedHi[a] <= piece.offset[a] + cd[a] &&
           piece.ownedHi[a] <= wholeCells && std::isfinite(piece.wholeOrigin[a]);
    }
    if (!ok) warn("the volume piece does not fit the volume (offset, owned cells or whole dimensions): rendering the volume as a whole");
    return ok ? &piece : nullptr;
  }

  /// The clipping and cropping planes of `render` in the integrator's index space (in double);
  /// with cropping off the cropping planes are left out, so moving them changes nothing.
  CropClip cropClipFor() { return cropClipFor(volume.origin); }
  /// The same with index space starting at `origin` (a piece: the whole volume's voxel 0).
  CropClip cropClipFor(const double* origin) {
    CropClip c;
    const mat4 indexToWorld = volume.indexToWorld();
    const double* L = indexToWorld.m;  // column-major: index axis k is column k (the origin is column 3)
    if (int(render.clipPlanes.size()) > kMaxClipPlanes)
      warn("more than " + std::to_string(kMaxClipPlanes) + " clipping planes: using the first " +
           std::to_string(kMaxClipPlanes));
    for (const auto& pl : render.clipPlanes) {
      if (c.numClipPlanes == kMaxClipPlanes) break;
      if (!(std::isfinite(pl[0]) && std::isfinite(pl[1]) && std::isfinite(pl[2]) && std::isfinite(pl[3]))) {
        warn("a clipping plane with a non-finite normal or offset is ignored");
        continue;
      }
      float* p = c.clip[c.numClipPlanes++];
      for (int k = 0; k < 3; ++k) p[k] = float(pl[0] * L[k * 4] + pl[1] * L[k * 4 + 1] + pl[2] * L[k * 4 + 2]);
      p[3] = float(pl[0] * origin[0] + pl[1] * origin[1] + pl[2] * origin[2] + pl[3]);
    }
    if (render.cropping) {
      c.cropping = 1;
      c.cropFlags = render.croppingFlags & 0x7ffffff;
      for (int a = 0; a < 3; ++a) {
        double lo = render.croppingPlanes[2 * a], hi = render.croppingPlanes[2 * a + 1];
        if (lo > hi) std::swap(lo, hi);
        const double o = origin[a], sp = volume.spacing[a];
        c.crop[2 * a] = float(std::clamp((lo - o) / sp, -1e30, 1e30));
        c.crop[2 * a + 1] = float(std::clamp((hi - o) / sp, -1e30, 1e30));
      }
    }
    return c;
  }

  /// The volume set to the backend (its upload, or the prefetched step) and its value ranges,
  /// when a setVolume is pending: update()'s first part, which prefetchVolume runs early so the
  /// next step's upload overlaps this step's classification, build and frame.
  void uploadIfNeeded() {
    if (!rangesDirty) return;
    report(0.0, "value ranges");
    backend->setVolume(volume, build.brick);
    if (backend->lastVolumePrefetched()) ++counters.prefetchedSteps;
    checkMagnitudes();
    ++counters.rangeGrids;
    ++counters.voxelPasses;
    rangesDirty = false;
    newVolumeUploaded = true;  // for update(): the structures held belong to another volume
    labelSetsDirty = true;  // computed when a label map is drawn (refreshLabelTF)
    opacityDirty = true;
    buildDirty = true;
  }
  bool newVolumeUploaded = false;

  /// Value ranges and classification, as far as they are stale. Returns whether the
  /// classification changed the occupancy (an edit).
  bool classifyIfNeeded() {
    const CropClip cc = cropClipFor();
    if (cc != cropClip) {
      cropClip = cc;
      cropClipDirty = true;
    }
    uploadIfNeeded();
    refreshLabelTF();
    // A TF (or crop/clip) edit: no contender is built on the frame that shows it.
    if (opacityDirty || colorDirty || cropClipDirty) autoBuilder.edited();
    if (!opacityDirty && !cropClipDirty) return false;
    report(0.3, "classification");
    auto t0 = Clock::now();
    const bool changed = labelOn ? backend->classifyLabels(labelSets, drawn, cropClip)
                                 : backend->classify(gradientTablesUsed() ? classificationTF(scaledTF(), volume.components) : oneDTF(), cropClip);
    if (backend->lastClassifyReadVoxels()) ++counters.voxelPasses;
    stats.classifySeconds = since(t0);
    stats.classifyWaitSeconds = backend->lastClassifyWaitSeconds();
    ++counters.classifications;
    if (opacityDirty) tableDirty = true;  // planes alone leave the table as it is
    opacityDirty = cropClipDirty = false;
    if (changed) buildDirty = true;
    if (changed && build.builder == BuilderKind::Auto && autoBuilder.occupancyMoved(backend->occupiedFraction()))
      startAuto(true);
    return changed;
  }

  /// The transfer table for the sample distance and blend mode, when stale.
  void updateTable() {
    if (!tableDirty && !colorDirty) return;
    if (!tableDirty) ++counters.colorUpdates;
    std::string note;
    const double step = effectiveSampleDistance(latticeShape(), render.sampleDistance, &note);
    if (!note.empty()) warn(note);
    float lo, scale;
    tableMapping(scaledTF(), static_cast<int>(tf.table.size()), lo, scale);
    // The opacity correction needs dt / unitDistance only: formed in double, so a step of
    // 1e-40 or 1e21 world units keeps its ratio to a unit distance of the same scale.
    TransferFunction unit = tf;
    unit.unitDistance = 1;
    const double ratio = tf.unitDistance > 0 && std::isfinite(tf.unitDistance) ? step / tf.unitDistance : step;
    std::vector<vec4f> table = tableForBlend(unit, float(std::min(ratio, 1e30)), blendMode());
    appendGradientTables(tf, table, gradOffset2D, gradOffsetGO);  // after the 1-D entries
    backend->setTransferTable(table, lo, scale);
    tableDirty = colorDirty = false;
  }

  /// Builds `p` (or its fallback where this backend cannot) and keeps its statistics.
  void buildStructure(BuildParams p, int autoCandidate) {
    const BuilderInfo& info = builderInfo(p.builder);
    if (!runsOnCpu(info) && backend->kind() != BackendKind::CUDA) {
      warn(std::string("builder ") + info.name + " needs the CUDA backend; building " + builderName(info.fallback) +
           " with the same parameters");
      p.builder = info.fallback;
    }
    BuildStats s;
    if (!autoBuilder.exploring()) report(0.4, "build");
    try {
      backend->build(p, s);
    } catch (const BackendError& e) {
      if (backend->kind() == BackendKind::CUDA) throw;
      warn(std::string(e.what()) + "; using the Grid traversal");
      p.builder = BuilderKind::Grid;
      backend->build(p, s);
    }
    s.builder = p.builder;
    s.classifySeconds = stats.classifySeconds;
    s.classifyWaitSeconds = stats.classifyWaitSeconds;
    s.occupancy = backend->occupiedFraction();
    if (autoCandidate >= 0) s.choice = autoBuilder.builtCandidate(autoCandidate, s.seconds);
    stats = s;
    ++counters.builds;
    buildDirty = false;
  }

  void update() {
    if (!haveVolume) throw std::runtime_error("no volume set");
    syncLabelMode();
    if (!haveTF && !labelOn) throw std::runtime_error("no transfer function set");
    const bool isAuto = build.builder == BuilderKind::Auto;
    const bool refineNow = autoBuilder.standingIn();  // the last frame stood in: build the kept one now
    const bool edited = classifyIfNeeded();  // this update's classification changed the occupancy
    const bool newRanges = newVolumeUploaded;  // since the last update (prefetchVolume may upload early)
    newVolumeUploaded = false;
    if (isAuto && !autoBuilder.started()) startAuto();
    updateTable();
    if (refineNow && !buildDirty) buildDirty = true;
    // Progressive refinement without any build: an edit that only emptied bricks leaves the
    // structure Auto holds covering every occupied brick, so the edit's frame draws with it
    // (lossless: it only visits some bricks that are empty now, whose sub-brick masks are 0)
    // and the next frame rebuilds it.
    std::string note;
    if (buildDirty && edited && !newRanges && isAuto && build.autoQuickBuildSeconds >= 0 &&
        backend->lastClassifyOnlyEmptied() && autoBuilder.drawStale(note)) {
      buildDirty = false;
      stats.seconds = 0;
      stats.occupancy = backend->occupiedFraction();
      stats.choice = note;
      ++counters.staleFrames;
    }
    // Auto: the structure to draw with is built when the backend holds another (measuring moves
    // the current candidate; a cancelled re-check whose contender was never built rebuilds nothing).
    if (isAuto && autoBuilder.needsBuild()) buildDirty = true;
    if (!buildDirty) return;
    if (!isAuto) return buildStructure(build, -1);
    // Progressive refinement: right after an edit, a kept structure that is slow to build gives
    // way to Grid (its occupancy grid is classification's output) for one frame; the image is the
    // same (lossless), only that frame's speed differs.
    const int use = autoBuilder.chooseBuild(edited, refineNow, build.autoQuickBuildSeconds);
    buildStructure(autoBuilder.candidate(use), use);
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
void Engine::setProgress(std::function<void(double, const char*)> progress) {
  impl_->progress = std::move(progress);
  impl_->backend->setProgress(impl_->backendProgress());
}

namespace {
/// Whether `b` has `a`'s shape: the same grid in the same place with the same voxel layout (the
/// voxels may differ): the next time step of a simulation.
bool sameShape(const Volume& a, const Volume& b) {
  if (a.dims.x != b.dims.x || a.dims.y != b.dims.y || a.dims.z != b.dims.z || a.type != b.type || a.components != b.components) return false;
  for (int i = 0; i < 3; ++i)
    if (a.spacing[i] != b.spacing[i] || a.origin[i] != b.origin[i]) return false;
  for (int i = 0; i < 9; ++i)
    if (a.direction[i] != b.direction[i]) return false;
  return true;
}
}  // namespace

UploadRates Engine::measureUpload(size_t bytes) { return impl_->backend->measureUpload(bytes); }
std::shared_ptr<unsigned char> Engine::allocateStepMemory(size_t bytes) {
  if (impl_->backend->kind() == BackendKind::CUDA)
    if (std::shared_ptr<unsigned char> p = allocatePageLocked(bytes)) return p;
  // The CPU reads voxels in place; on CUDA without page-locked memory the upload stages as before.
  return std::shared_ptr<unsigned char>(new unsigned char[bytes > 0 ? bytes : 1], std::default_delete<unsigned char[]>());
}

bool Engine::prefetchVolume(const Volume& next) {
  Impl& d = *impl_;
  if (!d.haveVolume || !next.data || !sameShape(d.sourceShape, next)) return false;
  // Steps drawn from a scaled copy (extreme float magnitudes; doubles and several float
  // components, whose check reads the host's voxels) are uploaded by setVolume as before.
  if (d.valueExponent != 0 || next.type == VoxelType::Float64 || (next.type == VoxelType::Float32 && next.components != 1))
    return false;
  // The step set before goes to the backend first (its prefetched voxels swapped in): the next
  // one's upload then overlaps this one's classification, build and frame.
  // The step set before, when it was prefetched, is swapped in and `next`'s copy starts right
  // then, before that step's value ranges: the copies run back to back.
  try {
    if (d.rangesDirty) d.backend->setNextVolume(&next);
    try {
      d.uploadIfNeeded();
    } catch (...) {
      d.backend->setNextVolume(nullptr);  // never carried over to a later setVolume
      throw;
    }
    d.backend->setNextVolume(nullptr);
  } catch (const BackendError& e) {
    if (d.backend->kind() != BackendKind::CUDA) throw;
    d.fallBackToCpu(e.what());
    return false;
  }
  return d.backend->prefetchVolume(next);
}

void Engine::setVolume(const Volume& v) {
  validate(v);
  // A time step (the same shape, new voxels) keeps Builder Auto's choice: the structures draw the
  // step as they drew the one before, so the kept one is rebuilt for the new occupancy as after
  // an opacity edit (Grid standing in for one frame when it is slow to build), and Auto measures
  // again only when the occupancy moves by more than kReexplore (classifyIfNeeded). Any other
  // volume measures from the start.
  const bool step = impl_->haveVolume && sameShape(impl_->sourceShape, v);
  impl_->sourceShape = v;
  impl_->sourceShape.data = nullptr;
  impl_->sourceShape.storage.reset();
  impl_->volume = v;
  impl_->valueExponent = 0;
  impl_->magnitudePending = false;
  if (step) ++impl_->counters.timeSteps;
  else impl_->autoBuilder.reset();
  // The integrator samples in float: magnitudes near the ends of double's (or float's) range
  // would overflow trilinear interpolation or the table mapping (+-1e308 gave a blank image),
  // and denormal-scale data would collapse to one table entry. Such volumes are sampled from a
  // float copy scaled by an exact power of two (scaleExtremeFloats). One float32 component is
  // checked from the brick ranges the backend computes anyway (update(); no pass over the voxels
  // here: on the time-step path that pass was most of a float step's host time); doubles (whose
  // range in float may underflow) and several components here, by the host's range pass.
  if (v.type == VoxelType::Float32 && v.components == 1) {
    impl_->magnitudePending = true;
  } else if (v.type == VoxelType::Float32 || v.type == VoxelType::Float64) {
    double lo = 0, hi = 0;  // the parallel finite range pass (NaN and +-Inf skipped)
    if (v.scalarRange(lo, hi)) impl_->scaleExtremeFloats(std::max(std::fabs(lo), std::fabs(hi)));
  }
  impl_->componentRanges();
  impl_->haveVolume = true;
  impl_->rangesDirty = true;
  impl_->tableDirty = true;  // the default sample distance follows the spacing
}

void Engine::setTransferFunction(TransferFunction tf, bool colorMayDiffer, bool opacityMayDiffer) {
  if (tf.table.empty()) throw std::invalid_argument("empty transfer-function table");
  Impl& d = *impl_;
  if (d.labelOn) {  // drawing a label map: kept for when that ends (syncLabelMode)
    d.userTF = std::move(tf);
    d.haveUserTF = true;
    return;
  }
  // A table of another size, or the first one, is new as a whole whatever the caller says.
  const bool whole = !d.haveTF || tf.table.size() != d.tf.table.size();
  bool opacity = whole;
  if (!opacity && opacityMayDiffer) {
    ++d.counters.opacityCompares;
    opacity = !tf.sameOpacity(d.tf);
  }
  // A 2-D table or gradient-opacity edit re-classifies (the marginal may change) and re-uploads.
  if (!opacity && !tf.sameGradientTables(d.tf)) opacity = true;
  if (opacity) {
    d.opacityDirty = true;  // re-classified, and the whole table set again
  } else if (colorMayDiffer) {
    ++d.counters.colorCompares;
    if (!tf.sameColor(d.tf)) d.colorDirty = true;
  }
  d.tf = std::move(tf);
  d.haveTF = true;
}

void Engine::setLabelTable(const LabelTable& t) {
  if (t == impl_->labels) return;
  impl_->labels = t;
  impl_->labelTFDirty = true;
}
const LabelTable& Engine::labelTable() const { return impl_->labels; }
bool Engine::labelMapActive() const { return impl_->labelOn; }

void Engine::setBuildParams(const BuildParams& p) {
  // bins 1 would mean no candidate plane at all; rejected rather than silently clamped, since 0
  // (the sweep) is now a meaningful value next to it.
  validate(p);
  Impl& d = *impl_;
  if (p.brick != d.build.brick) d.rangesDirty = true;
  if (p != d.build) {
    d.buildDirty = true;
    d.autoBuilder.reset();  // Auto measures again with the new parameters
  }
  d.build = p;
  d.build.brick = std::max(1, p.brick);
}

void Engine::setRenderParams(const RenderParams& p) {
  if (p.sampleDistance != impl_->render.sampleDistance || p.blend != impl_->render.blend) impl_->tableDirty = true;
  const bool gradientTables = impl_->gradientTablesUsed();
  impl_->render = p;
  if (impl_->gradientTablesUsed() != gradientTables) impl_->opacityDirty = true;  // classificationTF or not
}

void Engine::setPiece(const VolumePiece& p) {
  if (p.wholeDims.x != impl_->piece.wholeDims.x || p.wholeDims.y != impl_->piece.wholeDims.y ||
      p.wholeDims.z != impl_->piece.wholeDims.z)
    impl_->tableDirty = true;  // the sample distance's bounds follow the whole box
  impl_->piece = p;
}

const BuildParams& Engine::buildParams() const { return impl_->build; }
const RenderParams& Engine::renderParams() const { return impl_->render; }

namespace {
/// Runs `f` on `d`; where the CUDA backend fails (BackendError), falls back to the CPU backend and
/// runs it again there.
template <class Impl, class F>
void withCpuFallback(Impl& d, F f) {
  try {
    f();
  } catch (const BackendError& e) {
    if (d.backend->kind() != BackendKind::CUDA) throw;
    d.fallBackToCpu(e.what());
    f();
  }
}
}  // namespace

bool Engine::valueRange(double& lo, double& hi) {
  Impl& d = *impl_;
  if (!d.haveVolume || d.volume.components != 1 || d.volume.type == VoxelType::Float64) return false;
  withCpuFallback(d, [&] { d.uploadIfNeeded(); });
  double a = 0, b = 0;
  if (d.valueExponent != 0 || !d.backend->brickValueRange(a, b) || !std::isfinite(a) || !std::isfinite(b) || a > b)
    return false;
  lo = a;
  hi = b;
  return true;
}

void Engine::update() {
  Impl& d = *impl_;
  withCpuFallback(d, [&] { d.update(); });
}

namespace {
/// The frame the kernels march in (float): world coordinates relative to `origin`, times
/// 2^-exponent, so the volume's box is O(1) whatever its spacing (1e-30 and 1e21 alike) and
/// origin (1e15). Every matrix, point and distance the kernels get is composed here in double and
/// rounded to float once; a power of two keeps the scaling exact, so spacing 1 draws the same bits
/// as in world units, and directions, shading and dt/unitDistance are unchanged by it.
/// `v` in float, saturated at +-FLT_MAX (a plain conversion of a larger double is undefined).
float saturatedFloat(double v) {
  const double big = std::numeric_limits<float>::max();
  return float(v > big ? big : (v < -big ? -big : v));
}

struct MarchFrame {
  double origin[3];
  int exponent = 0;
  /// The volume as the march sees it: origin 0, spacing in frame units, axes thinner than
  /// 2^-kMaxAxisRatioLog2 of the longest extent widened to that (`flattened` says which).
  Volume shape;
  std::string flattened;

  double length(double world) const { return std::ldexp(world, -exponent); }
  vec3f point(const double* world) const {
    return vec3f{saturatedFloat(length(world[0] - origin[0])), saturatedFloat(length(world[1] - origin[1])),
                 saturatedFloat(length(world[2] - origin[2]))};
  }
};

/// The march frame of volume `v` (the whole volume's dims for a piece) anchored at `origin`.
MarchFrame marchFrame(const Volume& v, const double* origin) {
  MarchFrame m;
  for (int i = 0; i < 3; ++i) m.origin[i] = origin[i];
  m.shape = v;
  const vec3i cd = v.cellDims();
  const int cells[3] = {cd.x, cd.y, cd.z};
  double axis[3];  // world length of one index step along each axis
  for (int c = 0; c < 3; ++c)
    axis[c] = std::hypot(v.direction[c], v.direction[3 + c], v.direction[6 + c]) * v.spacing[c];
  const double longestStep = std::max({axis[0], axis[1], axis[2]});
  if (!(longestStep > 0) || !std::isfinite(longestStep)) {  // setVolume refuses these; no scaling
    for (int i = 0; i < 3; ++i) m.shape.origin[i] = 0;
    return m;
  }
  const int e0 = std::ilogb(longestStep);
  double extent[3];  // per axis, times 2^-e0 (finite for any finite spacing)
  for (int c = 0; c < 3; ++c) extent[c] = std::ldexp(axis[c], -e0) * cells[c];
  const double longest = std::max({extent[0], extent[1], extent[2]});
  m.exponent = e0 + std::ilogb(longest) + 1;  // the longest extent in [0.5, 1) frame units
  const double thinnest = std::ldexp(longest, -kMaxAxisRatioLog2);
  static const char* names = "xyz";
  for (int c = 0; c < 3; ++c) {
    double s = std::ldexp(v.spacing[c], -m.exponent);
    if (extent[c] < thinnest) {
      s *= thinnest / extent[c];
      char buf[256];
      std::snprintf(buf, sizeof buf, "%sspacing %g along %c is below 2^-%d of the volume's extent: drawn that thin",
                    m.flattened.empty() ? "" : "; ", v.spacing[c], names[c], kMaxAxisRatioLog2);
      m.flattened += buf;
    }
    m.shape.spacing[c] = s;
    m.shape.origin[c] = 0;
  }
  if (!m.flattened.empty()) m.flattened += " (float cannot resolve a thinner axis next to the others)";
  return m;
}

/// The light list (RenderParams::lights) into the frame, in the march frame (MarchFrame).
template <class Impl>
void fillLights(Impl& d, FrameView& f, const MarchFrame& frame) {
  const RenderParams& r = d.render;
  f.useLights = r.useLights ? 1 : 0;
  f.twoSided = r.twoSidedLighting ? 1 : 0;
  f.numLights = 0;
  f.lightAmbient = vec3f{0, 0, 0};
  if (!r.useLights) return;
  if (r.lights.size() > size_t(kMaxLights))
    d.warn("shading with " + std::to_string(r.lights.size()) + " lights: using the first " +
           std::to_string(kMaxLights));
  for (const Light& l : r.lights) {
    if (f.numLights == kMaxLights) break;
    double dir[3], len = 0;
    for (int k = 0; k < 3; ++k) {
      dir[k] = l.focalPoint[k] - l.position[k];
      len += dir[k] * dir[k];
    }
    len = std::sqrt(len);
    if (!(len > 0) || !std::isfinite(len)) {
      d.warn("a light whose position equals its focal point (or is not finite) is ignored");
      continue;
    }
    LightView& v = f.lights[f.numLights++];
    v.dir = vec3f{float(dir[0] / len), float(dir[1] / len), float(dir[2] / len)};
    v.pos = frame.point(l.position);
    v.diffuse = vec3f{float(l.diffuse[0]), float(l.diffuse[1]), float(l.diffuse[2])};
    v.specular = vec3f{float(l.specular[0]), float(l.specular[1]), float(l.specular[2])};
    // 1 / (c + l d + q d^2) of the world distance d = 2^exponent times the frame's.
    v.atten = vec3f{saturatedFloat(l.attenuation[0]), saturatedFloat(std::ldexp(l.attenuation[1], frame.exponent)),
                    saturatedFloat(std::ldexp(l.attenuation[2], 2 * frame.exponent))};
    v.positional = l.positional ? 1 : 0;
    v.cosCone = l.coneAngle <= 90.0 ? float(std::cos(l.coneAngle * 3.14159265358979323846 / 180.0)) : -2.f;
    v.exponent = float(l.exponent);
    f.lightAmbient = f.lightAmbient + vec3f{float(l.ambient[0]), float(l.ambient[1]), float(l.ambient[2])};
  }
}

/// The slice plane (RenderParams::sliceOrigin/sliceNormal, world) in index space: n.(X - o) = 0
/// with X = origin + A i becomes (A^T n).i + n.(origin - o) = 0.
template <class Impl>
void fillSlice(Impl& d, FrameView& f) {
  const RenderParams& r = d.render;
  const Volume& vol = d.volume;
  double n[3] = {r.sliceNormal[0], r.sliceNormal[1], r.sliceNormal[2]};
  double o[3] = {r.sliceOrigin[0], r.sliceOrigin[1], r.sliceOrigin[2]};
  const double nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
  const bool bad = !(nn > 0) || !std::isfinite(nn) || !std::isfinite(o[0] + o[1] + o[2]);
  if (bad) {
    if (r.blend == BlendMode::Slice)
      d.warn("slice blend mode: the slice plane has a zero or non-finite normal or origin; slicing "
             "through the centre of the volume, normal to z");
    double b[6];
    vol.worldBounds(b);
    for (int k = 0; k < 3; ++k) o[k] = 0.5 * (b[2 * k] + b[2 * k + 1]);
    n[0] = n[1] = 0;
    n[2] = 1;
  }
  const mat4 indexToWorld = vol.indexToWorld();
  const double* L = indexToWorld.m;  // column-major: index axis k is column k
  for (int k = 0; k < 3; ++k) f.slicePlane[k] = float(n[0] * L[k * 4] + n[1] * L[k * 4 + 1] + n[2] * L[k * 4 + 2]);
  f.sliceAsVTK = r.sliceAsVTK ? 1 : 0;
  f.slicePlane[3] = float(n[0] * (vol.origin[0] - o[0]) + n[1] * (vol.origin[1] - o[1]) + n[2] * (vol.origin[2] - o[2]));
}

/// The blend-mode and shading part of the frame from the render parameters.
template <class Impl>
void fillBlend(Impl& d, FrameView& f, const MarchFrame& frame) {
  const RenderParams& r = d.render;
  f.blend = d.blendMode();
  // Scalar values in the frame are in the sampled units: times 2^valueExponent (setVolume).
  auto scaled = [&](double v) { return std::ldexp(v, d.valueExponent); };
  double lo = r.scalarRange[0], hi = r.scalarRange[1];
  if (!(lo < hi)) {
    lo = d.tf.rangeMin;
    hi = d.tf.rangeMax;
  }
  lo = scaled(lo);
  hi = scaled(hi);
  f.normLo = float(lo);
  // At most float's largest: a range narrower than 1/FLT_MAX (values near 1e-308) gave an
  // infinite scale and NaN pixels ((v - lo) * inf with v == lo).
  f.normScale = hi > lo ? float(std::min(1.0 / (hi - lo), double(FLT_MAX))) : 0.f;
  f.avgLo = float(std::max(scaled(r.averageRange[0]), -double(HUGE_VALF)));
  f.avgHi = float(std::min(scaled(r.averageRange[1]), double(HUGE_VALF)));
  std::vector<double> iso = r.isoValues;
  std::sort(iso.begin(), iso.end());
  if (iso.size() > size_t(kMaxIsoValues)) {
    d.warn("isosurface: " + std::to_string(iso.size()) + " iso values, using the lowest " +
           std::to_string(kMaxIsoValues));
    iso.resize(size_t(kMaxIsoValues));
  }
  f.numIso = int(iso.size());
  for (int i = 0; i < f.numIso; ++i) f.iso[i] = float(scaled(iso[size_t(i)]));
  f.shade = r.shade && (r.blend == BlendMode::Composite || r.blend == BlendMode::Isosurface ||
                        r.blend == BlendMode::Slice) ? 1 : 0;
  f.ambient = float(r.ambient);
  f.diffuse = float(r.diffuse);
  f.specular = float(r.specular);
  f.specularPower = float(r.specularPower);
  f.lightDir = vec3f{float(r.lightDirection[0]), float(r.lightDirection[1]), float(r.lightDirection[2])};
  fillLights(d, f, frame);
  fillSlice(d, f);
}

/// Dependent components (render/Components.h): the opacity channel's table mapping, the direct
/// colour channels' normalisation and the component shading differentiates.
template <class Impl>
void fillComponents(Impl& d, FrameView& f) {
  const Volume& v = d.volume;
  TransferFunction alpha = d.scaledTF();
  alpha.rangeMin = alpha.alphaMin();
  alpha.rangeMax = alpha.alphaMax();
  tableMapping(alpha, static_cast<int>(d.tf.table.size()), f.alphaLo, f.alphaScale);
  // vtkVolumeTexture's scale and bias map each component's finite range to [0, 1]. (Newer VTK
  // scales integer ranges by 1/(max+1) against the texture's v/max, a factor (max+1)/max on
  // colour; ParaView 5.11's VTK does not: measured on TestSpaceSkippingVolumeRGBA (uint8), 54.6 dB
  // without that factor, 52.4 dB with it.)
  for (int c = 0; c < 3; ++c) {
    const double lo = d.rgbRange[c][0], hi = d.rgbRange[c][1];
    f.rgbLo[c] = float(lo);
    f.rgbScale[c] = hi > lo ? float(1.0 / (hi - lo)) : 0.f;
  }
  // VTK 9.2's vtkVolumeShaderComposer lights both modes with component 0's gradient
  // (computeLighting(color, 0)); VTK 9.4 and later light 4 components by component 3's
  // (RenderParams::rgbaLightingComponent, set by the VTK mapper for the VTK it is built with).
  // Measured against ParaView 5.11's vtkGPUVolumeRayCastMapper on TestSpaceSkippingVolumeRGBA
  // shaded: 59.9 dB with component 0, 25.7 dB with component 3.
  f.gradientComponent = v.components == 4 ? std::clamp(d.render.rgbaLightingComponent, 0, 3) : 0;
  if (v.components > 1 && d.render.filter == FilterMode::Hardware)
    d.warn("hardware filtering with dependent components: sampling exactly");
}

/// 2-D transfer function / gradient opacity (render/GradientTF.h): where its entries are, the
/// column mapping (classificationTF's) and VTK's gradient normalisation for this volume.
template <class Impl>
void fillGradientTF(Impl& d, FrameView& f) {
  const TransferFunction& tf = d.tf;
  if (!tf.uses2D() && !tf.usesGradientOpacity()) return;
  const char* what = tf.uses2D() ? "2-D transfer function" : "gradient opacity";
  const bool secondAxis = tf.uses2D() && d.volume.components == 2;  // x and y values (Transfer2DYAxisArray)
  if (d.volume.components != 1 && !secondAxis) {
    d.warn(std::string(what) + " with dependent components is not supported: drawn with the 1-D tables");
    return;
  }
  if (f.blend != BlendMode::Composite) {
    d.warn(std::string(what) + " is used with composite blending only: blend mode " +
           std::to_string(int(f.blend)) + " draws with the 1-D tables");
    return;
  }
  const TransferFunction s = d.scaledTF();
  GradientTFView& g = f.gtf;
  if (tf.uses2D() && d.gradOffset2D >= 0) {
    g.mode = secondAxis ? 3 : 2;
    g.offset = d.gradOffset2D;
    g.width = tf.width2D;
    g.height = tf.height2D;
    gradientColumnMapping(s, g.xLo, g.xScale);
    if (secondAxis) secondAxisRowMapping(s, g.yLo, g.yScale);
  } else if (tf.usesGradientOpacity() && d.gradOffsetGO >= 0) {
    g.mode = 1;
    g.offset = d.gradOffsetGO;
    g.width = int(tf.gradientOpacity.size());
  } else {
    return;
  }
  // vtkVolumeShaderComposer (computeGradient with gradient opacity): (f(p+e) - f(p-e)) divided
  // by 2 spacing / average spacing per axis, the length over a quarter of the scalar range; the
  // classification's gradient bound uses the same factors (GradientBound.h).
  gradientScale(d.volume.spacing, s.rangeMin, s.rangeMax, g.gradScale);
}
/// Volumetric shadows and scattering (render/Scattering.h): VTK's texture space for this
/// volume, the lights there, the reach as VTK maps GlobalIlluminationReach, the blend's gradient
/// scale. After fillBlend (shading, lights, the scalar normalisation) and fillGradientTF.
template <class Impl>
void fillScatter(Impl& d, FrameView& f, const MarchFrame& frame, bool piece) {
  const RenderParams& r = d.render;
  ScatterView& S = f.scatter;
  S.on = 0;
  const double b = r.scatteringBlending;
  if (!(b > 0) || !f.shade || !(f.blend == BlendMode::Composite || f.blend == BlendMode::Isosurface)) return;
  if (piece) {
    d.warn("volumetric scattering is not drawn in pieces (MPI): a shadow ray would need the other ranks' voxels; "
           "drawn with gradient shading only");
    return;
  }
  if (f.useLights && f.numLights == 0) return;  // no light: VTK generates no scattering either
  S.on = 1;
  S.blending = float(std::min(b, 2.0));
  // |g| near 1 makes the phase function a spike of height ~1/(1-|g|)^2; clamped where float holds it.
  S.g = float(std::max(-0.99, std::min(0.99, std::isfinite(r.scatteringAnisotropy) ? r.scatteringAnisotropy : 0.0)));
  S.cutoff = 1.f / 4096.f;
  const vec3f cells = f.boxHi;
  S.texN = vec3f{cells.x + 1.f, cells.y + 1.f, cells.z + 1.f};
  S.dirScale = vec3f{cells.x > 0.f ? 1.f / cells.x : 1.f, cells.y > 0.f ? 1.f / cells.y : 1.f,
                     cells.z > 0.f ? 1.f / cells.z : 1.f};
  // VTK: reach = (minExtent - sqrt 3) (1 - r)^0.33 + sqrt 3, minExtent = the sample distance in
  // texture units along the longest axis.
  const mat4 i2w = frame.shape.indexToWorld();
  double longest = 0;
  const float cd[3] = {cells.x, cells.y, cells.z};
  for (int a = 0; a < 3; ++a)
    longest = std::max(longest, std::hypot(i2w.m[a * 4], i2w.m[a * 4 + 1], i2w.m[a * 4 + 2]) * double(cd[a]));
  const double minExtent = longest > 0 ? double(f.dt) / longest : 0.0;
  const double reach = std::max(0.0, std::min(1.0, std::isfinite(r.globalIlluminationReach) ? r.globalIlluminationReach : 0.0));
  const double sqrt3 = 1.73205;
  S.reach = float((minExtent - sqrt3) * std::pow(1.0 - reach, 0.33) + sqrt3);
  // VTK's gradient for the blend: the scalar normalised over the array's range, per world length
  // (the data set's spacing), from central differences.
  for (int a = 0; a < 3; ++a) {
    const double h = std::fabs(d.volume.spacing[a]);
    S.gradScale[a] = h > 0 ? saturatedFloat(double(f.normScale) / h) : 0.f;
  }
  const float* W = f.worldToIndex;
  auto toIndexDir = [&](vec3f v) {
    return vec3f{W[0] * v.x + W[1] * v.y + W[2] * v.z, W[4] * v.x + W[5] * v.y + W[6] * v.z,
                 W[8] * v.x + W[9] * v.y + W[10] * v.z};
  };
  auto toIndexPoint = [&](vec3f v) { return toIndexDir(v) + vec3f{W[3], W[7], W[11]}; };
  auto unadjusted = [&](vec3f i) { return vec3f{i.x * S.dirScale.x, i.y * S.dirScale.y, i.z * S.dirScale.z}; };
  S.eyeIdx = toIndexPoint(f.eyeW);
  if (f.useLights) {
    for (int i = 0; i < f.numLights; ++i) {
      const LightView& L = f.lights[i];
      S.lightU[i] = L.positional ? unadjusted(toIndexPoint(L.pos)) : unadjusted(toIndexDir(L.dir * -1.f));
    }
  } else {
    const bool head = f.lightDir.x == 0.f && f.lightDir.y == 0.f && f.lightDir.z == 0.f;
    S.headPositional = head ? 1 : 0;
    S.lightU[0] = head ? unadjusted(S.eyeIdx) : unadjusted(toIndexDir(normalize(f.lightDir)));
  }
}
}  // namespace

void Engine::render(const Camera& cam, int width, int height, Image& out, const float* depth,
                    const float* alphaIn) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("render size must be positive");
  update();
  Impl& d = *impl_;
  FrameView f{};
  // The kernels march in float in the MarchFrame: relative to the volume's origin and scaled so
  // its box is O(1). The camera is moved into that frame before anything is inverted: the view
  // times the frame's inverse (origin shift in long double, then an exact power-of-two scale),
  // inverted as view^-1 * proj^-1 (inverting proj*view with a 1e15 translation in it lost up to
  // 229/255 of a pixel's value at origin 1e15).
  // A piece of a larger volume (MPI): rays, box and planes are the whole volume's, relative to
  // its voxel 0, the same bits on every rank; the lattice part of the frame says what it draws.
  const VolumePiece* piece = d.fittingPiece();
  const double* origin = piece ? piece->wholeOrigin : d.volume.origin;
  const MarchFrame frame = marchFrame(d.latticeShape(), origin);
  if (!frame.flattened.empty()) d.warn(frame.flattened);
  mat4 viewRel = cam.view;  // frame (unscaled, origin-relative) -> eye
  for (int r = 0; r < 4; ++r) {
    long double t = cam.view.m[12 + r];
    for (int c = 0; c < 3; ++c) t += (long double)cam.view.m[c * 4 + r] * (long double)origin[c];
    viewRel.m[12 + r] = double(t);
  }
  mat4 invView, invProj;
  if (!invert(viewRel, invView)) throw std::invalid_argument("camera view matrix is singular");
  if (!invert(cam.proj, invProj)) throw std::invalid_argument("camera matrix is singular");
  for (int c = 0; c < 4; ++c)  // rows 0..2 (positions) into frame units
    for (int r = 0; r < 3; ++r) invView.m[c * 4 + r] = frame.length(invView.m[c * 4 + r]);
  mat4 ivp = multiply(invView, invProj);  // NDC -> frame (homogeneous)
  // A perspective projection of near distance n has a w row of ~1/n world units (1e100 for a
  // volume of spacing 1e-100): the whole matrix times a power of two brings its largest entry
  // to O(1) without changing a ray (x/w is unchanged, exactly).
  double largest = 0;
  for (double v : ivp.m) largest = std::max(largest, std::fabs(v));
  if (largest > 0 && std::isfinite(largest)) {
    const int shift = -std::ilogb(largest);
    for (double& v : ivp.m) v = std::ldexp(v, shift);
  }
  bool finite = true;
  for (int i = 0; i < 16; ++i) {
    f.invViewProj[i] = float(ivp.m[i]);
    finite = finite && std::isfinite(f.invViewProj[i]);
  }
  if (!finite) d.warn("the camera is not finite in float in the volume's frame: its rays draw nothing");
  mat4 w2i;
  if (!invert(frame.shape.indexToWorld(), w2i)) throw std::invalid_argument("volume direction/spacing is singular");
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) f.worldToIndex[r * 4 + c] = float(w2i.m[c * 4 + r]);
  f.width = width;
  f.height = height;
  f.alphaIn = alphaIn;
  vec3i cd = piece ? d.latticeShape().cellDims() : d.volume.cellDims();
  f.boxHi = vec3f{float(cd.x), float(cd.y), float(cd.z)};
  if (piece) {
    f.lattice.active = 1;
    for (int a = 0; a < 3; ++a) {
      f.lattice.pieceLo[a] = float(piece->offset[a]);
      f.lattice.ownLo[a] = float(piece->ownedLo[a]);
      f.lattice.ownHi[a] = float(piece->ownedHi[a]);
    }
    f.lattice.followBias = piece->followBias;
  }
  f.dt = float(frame.length(d.dt()));
  f.ertThreshold = d.render.ertThreshold > 1.0 ? 2.f : float(d.render.ertThreshold);
  f.cut = piece ? d.cropClipFor(origin) : d.cropClip;  // the planes classification used (shifted)
  f.jitter = d.render.jitter ? 1 : 0;
  f.jitterSeed = d.render.jitterSeed;
  f.firstSample = float(std::max(0.0, d.render.firstSampleOffset));
  // The eye in the same frame as the rays (invView's translation: already relative and scaled).
  f.eyeW = vec3f{saturatedFloat(invView.m[12]), saturatedFloat(invView.m[13]), saturatedFloat(invView.m[14])};
  fillBlend(d, f, frame);
  fillComponents(d, f);
  fillGradientTF(d, f);
  fillScatter(d, f, frame, piece != nullptr);
  // Nearest and label-map sampling (render/LabelSampler.h).
  if (d.labelOn)
    f.sampling = d.render.labelSampling == LabelSampling::Nearest ? kLabelNearest : kLabelBlend;
  else if (d.render.nearest && d.volume.components == 1)
    f.sampling = kSampleNearest;
  else if (d.render.nearest)
    d.warn("nearest sampling with dependent components is not supported: sampled trilinearly");
  std::vector<unsigned> counts;
  if (d.render.countSamples) {
    counts.assign(size_t(width) * size_t(height), 0u);
    f.sampleCount = counts.data();
  }
  const bool autoProbes =
      d.build.builder == BuilderKind::Auto && AutoBuilder::usesProbes(d.build, d.backend->kind());
  if (autoProbes) {
    d.measureOnProbes(f, width, height, d.viewKey(cam));
    d.update();  // the kept structure, when measuring ended on another
  }
  d.report(0.8, "frame");
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
  d.frame.deviceSeconds = -1;
  d.deviceSecondsPending = true;
  d.frame.samples = -1;
  if (d.render.countSamples) {
    d.frame.samples = 0;
    for (unsigned c : counts) d.frame.samples += c;
  }
  d.frame.backend = d.backend->name();
  // Every frame: without part ranges the CUDA backend computes the masks on the frame after a
  // classification's.
  d.stats.partsShare = d.backend->subMaskShare();
  d.frame.residency = d.backend->residency();
  if (d.frame.residency.sparse && d.render.filter == FilterMode::Hardware)
    d.warn("sparse residency samples exactly (hardware filtering needs the whole volume in one texture)");
  if (d.frame.residency.overflow)
    d.warn("the bricks this view needs exceed the memory budget: sampled from the whole volume in host memory");
  ++d.counters.frames;
  if (autoProbes && d.autoBuilder.keptFrameDrawn(d.frame.seconds)) d.stats.choice = d.autoBuilder.choice();
  if (d.build.builder == BuilderKind::Auto && !autoProbes)
    if (d.autoBuilder.frameDone([&d] { return d.frameDeviceSeconds() > 0 ? d.frame.deviceSeconds : d.frame.seconds; },
                                width, height, d.viewKey(cam), d.occupied()))
      d.stats.choice = d.autoBuilder.choice();
}

bool Engine::setImageOnDevice(bool on) { return impl_->backend->setImageOnDevice(on); }
const void* Engine::deviceImage() const { return impl_->backend->deviceImage(); }
DeviceImageView Engine::deviceImageView() const { return impl_->backend->deviceImageView(); }
void* Engine::deviceImageStream() const { return impl_->backend->deviceImageStream(); }
void Engine::setTuning(const Tuning& t) {
  impl_->tuning = t;
  impl_->backend->setTuning(t);
}
const Tuning& Engine::tuning() const { return impl_->tuning; }
void Engine::setMemoryBudget(int64_t bytes, int poolBrick) {
  bytes = bytes > 0 ? bytes : 0;
  poolBrick = std::clamp(poolBrick, 1, 1024);
  if (bytes == impl_->memoryBudget && poolBrick == impl_->poolBrick) return;
  impl_->memoryBudget = bytes;
  impl_->poolBrick = poolBrick;
  impl_->backend->setMemoryBudget(bytes, poolBrick);
  impl_->rangesDirty = true;  // in core or sparse is decided when the volume is set
}

const BuildStats& Engine::buildStats() const { return impl_->stats; }
bool Engine::exploring() const {
  const AutoBuilder& a = impl_->autoBuilder;
  return impl_->build.builder == BuilderKind::Auto && (a.exploring() || !a.started());
}
const FrameStats& Engine::frameStats(bool waitForDevice) const {
  if (waitForDevice) impl_->frameDeviceSeconds();
  return impl_->frame;
}
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
int Engine::valueExponent() const { return impl_->valueExponent; }

}  // namespace spaceskip

// Engine: keeps scene state, decides what a change requires, and falls back from CUDA to CPU.
#include "spaceskip/Engine.h"

#include "spaceskip/Backend.h"
#include "spaceskip/Builders.h"

#include <algorithm>
#include <chrono>
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
  const double ex = cd.x * v.spacing[0], ey = cd.y * v.spacing[1], ez = cd.z * v.spacing[2];
  const double diagonal = std::sqrt(ex * ex + ey * ey + ez * ez);
  const double floorDt = voxel / kMinStepsPerVoxel, capDt = diagonal / kMaxSamplesPerRay;
  std::string why;
  if (dt < floorDt) {
    dt = floorDt;
    why = "below the floor of 1/" + std::to_string(int(kMinStepsPerVoxel)) + " of the smallest voxel spacing";
  }
  if (dt < capDt) {
    dt = capDt;
    why = "more than " + std::to_string(int64_t(kMaxSamplesPerRay)) + " samples along the volume's diagonal";
  }
  if (note) {
    note->clear();
    if (!why.empty()) {
      char buf[256];
      std::snprintf(buf, sizeof buf, "sample distance %g %s: using %g world units (%s)", requested,
                    "clamped", dt, why.c_str());
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
  bool haveVolume = false;
  TransferFunction tf;
  bool haveTF = false;
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
    }
    return frame.deviceSeconds;
  }

  // Builder Auto ("never slower than naive"): skipping is lossless, so every candidate draws the
  // same image and only its speed differs. Measuring: every candidate renders a frame, in turn
  // (round 1); those within kAutoPrune of round 1's cheapest render again, in the reverse order
  // (round 2: A B C D, then D C B A, so a drift of the machine's load favours none and the last
  // structure of round 1 needs no rebuild), short frames several times in a row (until
  // kAutoMinMeasureSeconds, at most kAutoMaxRepeats frames: one sub-millisecond frame is at the
  // mercy of a launch's jitter); a candidate's frame time is the minimum of its frames (other
  // work only ever adds time). Its cost is that frame time plus its build time spread over
  // kAutoFramesPerBuild frames (autoCost): a structure that draws a few percent faster at the
  // measured view but takes milliseconds to rebuild on every opacity edit loses to one nearly as
  // fast that rebuilds at once. The cheapest is kept, over Naive only when kAutoMargin cheaper.
  // The candidates are measured again when the occupancy moves by more than kAutoReexplore or
  // the image size changes, otherwise an occupancy change rebuilds the chosen one only.
  // Frame times depend on the view, so measurements are compared only when taken at one view:
  // once the camera has moved far (kAutoFarDegrees, or a zoom of kAutoFarZoom) from where the
  // choice was measured and then stays still, the kept structure is re-checked there against the
  // contenders (those within kAutoPrune of it when it was measured, at least the runner-up), two
  // frames each; a moving camera (an orbit) never triggers a re-check, and one that moves during
  // it cancels it. A frame that carries a TF or crop/clip change never builds a contender: it
  // cancels a re-check under way and starts none, so an edit under Auto costs what the kept
  // structure's edit costs (a user editing at a resting view would otherwise pay a contender's
  // build on the frames that show the edits).
  struct ViewKey {
    double dir[3] = {0, 0, 0};  ///< the camera's backward axis in world space
    double zoom = 0;            ///< |proj[0][0]|
    double distance = 0;        ///< the eye's distance from the volume's centre (perspective)
    bool valid = false;
  };
  struct AutoState {
    std::vector<BuildParams> candidates;
    std::vector<double> seconds;  ///< measured frame time per candidate (minimum), < 0: not yet
    std::vector<double> buildSeconds;  ///< last build time per candidate, < 0: not yet
    std::vector<int> frames;      ///< frames measured per candidate in the current measuring
    std::vector<int> queue;       ///< the candidates still to render in this measuring, in order
    bool standIn = false;         ///< this frame draws Grid while the kept one waits (refinement)
    bool tfEdit = false;          ///< this frame carries a transfer-function (or crop/clip) change
    bool refined = false;         ///< the kept structure was rebuilt after a stand-in frame
    int current = -1;             ///< the candidate to draw with (built when it differs from `built`)
    int built = -1;               ///< the candidate the backend holds, -1: none (or stale)
    int kept = -1;                ///< the kept structure (during a re-check: the one before it)
    bool exploring = false;       ///< measuring (all candidates, or a re-check)
    bool rechecking = false;      ///< this measuring is a re-check of the kept one at a new view
    int round = 0;                ///< 1 or 2 while measuring all candidates
    double occupancy = -1;        ///< when the choice was made
    int width = 0, height = 0;
    ViewKey measuredAt;           ///< the view of the last measuring
    ViewKey lastView;             ///< the previous frame's view
    ViewKey recheckAt;            ///< the view a re-check started at
    int rechecks = 0;             ///< re-checks at a new view since the measuring
    int switches = 0;             ///< changes of the kept structure by a re-check
    int fullWidth = 0, fullHeight = 0;  ///< the user's frame size (probes: `width` is the probe's)
    double timeScale = 1;         ///< probes: the user's frame pixels over a probe's
    std::string choice;
  } autoState;
  static constexpr double kAutoReexplore = 0.1;
  /// Round 2 (and a re-check) measures only candidates within this factor of the cheapest.
  static constexpr double kAutoPrune = 1.5;
  /// Round 2 renders a candidate until its frames there add up to this, at most kAutoMaxRepeats.
  static constexpr double kAutoMinMeasureSeconds = 2e-3;
  static constexpr int kAutoMaxRepeats = 3;
  /// A candidate's build time counts as if spread over this many frames (autoCost): an opacity
  /// edit about every second at 30 frames/s, as when a user drags a TF point. On the H100 (round
  /// 7, docs/results/round7-h100/auto) the k-d tree drew the first, axis-aligned view of aneurism,
  /// stag beetle and kingsnake 3-8% faster than DistanceGrid and the orbit 5-11% slower, with
  /// builds of 0.9-2.2 ms against 0.03-0.33 ms: this weight keeps DistanceGrid there, and the
  /// k-d tree where it is 17-58% faster (Menger, Richtmyer-Meshkov).
  static constexpr double kAutoFramesPerBuild = 30;
  /// A structure is kept over Naive (or over the kept one in a re-check) only when this much faster.
  static constexpr double kAutoMargin = 1.05;
  /// A view this far from the measured one (degrees between view directions, or zoom ratio) is
  /// another view; consecutive frames within kAutoStill* of each other are a still camera.
  static constexpr double kAutoFarDegrees = 25.0, kAutoFarZoom = 1.25;
  static constexpr double kAutoStillDegrees = 2.0, kAutoStillZoom = 1.02;
  /// A re-check is cancelled when the camera moves this far from where it started.
  static constexpr double kAutoRecheckDrift = 5.0;

  ViewKey viewKey(const Camera& cam) const {
    ViewKey k;
    const double* v = cam.view.m;  // column-major: row 2 of the rotation is the backward axis
    const double n = std::sqrt(v[2] * v[2] + v[6] * v[6] + v[10] * v[10]);
    mat4 iv;
    if (!(n > 0) || !invert(cam.view, iv)) return k;
    for (int i = 0; i < 3; ++i) k.dir[i] = v[2 + 4 * i] / n;
    k.zoom = std::fabs(cam.proj.m[0]);
    double b[6];
    volume.worldBounds(b);
    double d2 = 0;
    for (int i = 0; i < 3; ++i) {
      const double d = iv.m[12 + i] - 0.5 * (b[2 * i] + b[2 * i + 1]);
      d2 += d * d;
    }
    k.distance = std::sqrt(d2);
    k.valid = std::isfinite(k.zoom) && std::isfinite(k.distance);
    return k;
  }
  /// Whether two views are within `degrees` and a factor `zoom` (in scale and, for perspective
  /// cameras, eye distance) of each other; an invalid one is near nothing.
  static bool near(const ViewKey& a, const ViewKey& b, double degrees, double zoom) {
    if (!a.valid || !b.valid) return false;
    const double c = a.dir[0] * b.dir[0] + a.dir[1] * b.dir[1] + a.dir[2] * b.dir[2];
    const double angle = std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / 3.14159265358979323846;
    auto ratio = [](double x, double y) { return x > 0 && y > 0 ? std::max(x / y, y / x) : (x == y ? 1.0 : 1e30); };
    return angle <= degrees && ratio(a.zoom, b.zoom) <= zoom && ratio(a.distance, b.distance) <= zoom;
  }

  std::vector<BuildParams> autoCandidates() const {
    auto with = [&](BuilderKind k, int mls) {
      BuildParams p = build;
      p.builder = k;
      p.leaf = LeafCriterion::Deep;
      p.maxLeafSize = mls;
      return p;
    };
    if (backend->kind() == BackendKind::CUDA) {
      // The k-d tree with the Empty split rule (sweep): faster than MLS 128 on 7 of the paper's
      // 9 GPU rows and by 13% on the Menger sponge (docs/results/paper-bench, H100).
      BuildParams kd = with(BuilderKind::KdTreeGPUFast, 0);
      kd.leaf = LeafCriterion::Empty;
      kd.bins = 0;
      return {with(BuilderKind::Naive, 0), with(BuilderKind::Grid, 0), with(BuilderKind::DistanceGrid, 0), kd,
              with(BuilderKind::LBVH, 0)};
    }
    return {with(BuilderKind::Naive, 0), with(BuilderKind::Grid, 0), with(BuilderKind::DistanceGrid, 0),
            with(BuilderKind::KdTreeCPU, 32)};
  }

  /// The Grid candidate's index, -1 when there is none.
  int gridCandidate() const {
    for (size_t i = 0; i < autoState.candidates.size(); ++i)
      if (autoState.candidates[i].builder == BuilderKind::Grid) return int(i);
    return -1;
  }

  /// Starts measuring: every candidate (round 1), or, for a re-check, the kept one and its
  /// contenders; the first in the queue is built next.
  void beginMeasuring(std::vector<int> queue, bool recheck) {
    AutoState& a = autoState;
    a.frames.assign(a.candidates.size(), 0);
    a.queue = std::move(queue);
    a.exploring = true;
    a.rechecking = recheck;
    a.round = recheck ? 0 : 1;
    a.current = a.queue.front();
  }

  /// Measures every candidate from the start. `afterEdit`: an opacity edit moved the occupancy,
  /// and the frame that shows it is the first measured: Grid (no build beyond the
  /// classification) draws it instead of Naive, so the edit costs what Grid's frame costs.
  void startAutoExploration(bool afterEdit = false) {
    AutoState& a = autoState;
    a.candidates = autoCandidates();
    a.seconds.assign(a.candidates.size(), -1.0);
    a.buildSeconds.assign(a.candidates.size(), -1.0);
    a.kept = -1;
    a.current = -1;
    a.rechecks = a.switches = 0;
    std::vector<int> all(a.candidates.size());
    for (size_t i = 0; i < all.size(); ++i) all[i] = int(i);
    const int grid = gridCandidate();
    if (afterEdit && grid > 0) std::rotate(all.begin(), all.begin() + grid, all.begin() + grid + 1);
    beginMeasuring(all, false);
    a.choice = "Auto: measuring " + std::to_string(a.candidates.size()) + " structures";
    a.built = -1;  // the candidates are new: build whatever is current
  }

  /// Ends a re-check without a decision: the kept structure draws the next frame.
  void cancelRecheck() {
    AutoState& a = autoState;
    if (!a.rechecking) return;
    a.exploring = a.rechecking = false;
    a.queue.clear();
    a.current = a.kept;
  }

  /// A candidate's cost per frame: its measured frame time plus its last build time spread over
  /// kAutoFramesPerBuild frames; < 0 when it has no frame time yet.
  double autoCost(size_t i) const {
    const AutoState& a = autoState;
    if (!(a.seconds[i] > 0)) return -1.0;
    const double b = i < a.buildSeconds.size() && a.buildSeconds[i] > 0 ? a.buildSeconds[i] : 0.0;
    return a.seconds[i] + b / kAutoFramesPerBuild;
  }

  /// Records a measured frame of the current candidate (the minimum of its frames so far).
  void record(double seconds) {
    AutoState& a = autoState;
    double& t = a.seconds[size_t(a.current)];
    t = a.frames[size_t(a.current)]++ == 0 ? seconds : std::min(t, seconds);
  }

  /// Starts a re-check of the kept structure at `view` against its contenders: those within
  /// kAutoPrune of it when it was measured, at least the runner-up (the likeliest to overtake it
  /// at another view); the queue is the kept one, the contenders, them again reversed, the kept
  /// one. False (nothing started) with a single candidate.
  bool startRecheck(const ViewKey& view) {
    AutoState& a = autoState;
    std::vector<int> q;
    int runnerUp = -1;
    for (size_t i = 0; i < a.candidates.size(); ++i) {
      if (int(i) == a.kept || !(a.seconds[i] > 0)) continue;
      if (autoCost(i) < kAutoPrune * autoCost(size_t(a.kept))) q.push_back(int(i));
      if (runnerUp < 0 || autoCost(i) < autoCost(size_t(runnerUp))) runnerUp = int(i);
    }
    if (q.empty() && runnerUp >= 0) q.push_back(runnerUp);
    if (q.empty()) {  // a single candidate: nothing to re-check
      a.measuredAt = view;
      return false;
    }
    const int contenders = int(q.size());
    for (int i = contenders - 1; i >= 0; --i) q.push_back(q[size_t(i)]);  // round 2, reversed
    q.push_back(a.kept);
    ++a.rechecks;
    a.recheckAt = view;
    std::vector<int> queue{a.kept};
    queue.insert(queue.end(), q.begin(), q.end());
    beginMeasuring(queue, true);
    return true;
  }

  /// Whether Auto measures on probes (BuildParams::autoProbe).
  bool autoProbes() const {
    return build.autoProbe > 0 || (build.autoProbe < 0 && backend->kind() == BackendKind::CPU);
  }

  /// The probe size for a frame of width x height: 1/4 of each axis or less, at most 128 pixels
  /// a side, at least 16 (or the frame's own size below that).
  static void probeSize(int width, int height, int& pw, int& ph) {
    const double f = std::max(4.0, double(std::max(width, height)) / 128.0);
    pw = std::max(std::min(width, 16), int(width / f));
    ph = std::max(std::min(height, 16), int(height / f));
  }

  /// Auto on probes, before the user's frame `full` (width x height, seen from `view`) is drawn:
  /// the triggers of the per-frame protocol (a new frame size; a still camera far from where
  /// the choice was measured, without an edit in this frame) start a measuring, and a measuring
  /// runs to its decision here, every candidate built and drawn on probes of the same view.
  /// The user's frame then draws with the kept structure.
  void autoProbe(const FrameView& full, int width, int height, const ViewKey& view) {
    AutoState& a = autoState;
    const ViewKey previous = a.lastView;
    a.lastView = view;
    const bool tfEdit = a.tfEdit;
    a.tfEdit = false;
    if (!a.exploring && !a.standIn) {
      if (width != a.fullWidth || height != a.fullHeight) startAutoExploration();
      else if (!tfEdit && !near(view, a.measuredAt, kAutoFarDegrees, kAutoFarZoom) &&
               near(view, previous, kAutoStillDegrees, kAutoStillZoom))
        startRecheck(view);
    }
    if (!a.exploring) return;
    a.fullWidth = width;
    a.fullHeight = height;
    FrameView p = full;
    probeSize(width, height, p.width, p.height);
    p.depth = nullptr;  // per pixel of the user's frame
    p.alphaIn = nullptr;
    p.sampleCount = nullptr;
    a.timeScale = double(width) * double(height) / (double(p.width) * double(p.height));
    Image img;
    // Each candidate at most 1 + 1 + kAutoMaxRepeats probes (a re-check: 2 + 2): a bound, not a rule.
    const int bound = 8 * int(a.candidates.size());
    for (int guard = 0; a.exploring && guard < bound; ++guard) {
      report(0.5 + 0.3 * double(guard) / double(bound), "measuring");
      update();  // builds the candidate to measure
      const auto t0 = Clock::now();
      backend->render(p, render.filter, nullptr, img);
      const double t = backend->lastFrameDeviceSeconds() > 0 ? backend->lastFrameDeviceSeconds() : since(t0);
      ++counters.autoProbeFrames;
      autoFrameDone([t] { return t; }, p.width, p.height, view);
    }
    if (a.exploring) {  // the bound was hit: keep the cheapest measured so far
      cancelRecheck();
    }
    ++counters.autoProbeMeasurings;
  }

  /// After a frame of `seconds()` at width x height seen from `view`: records it and picks the
  /// next build. `seconds` is called only when a time is recorded (it may wait for the device).
  void autoFrameDone(const std::function<double()>& seconds, int width, int height, const ViewKey& view) {
    AutoState& a = autoState;
    const ViewKey previous = a.lastView;
    a.lastView = view;
    const bool tfEdit = a.tfEdit;
    a.tfEdit = false;
    if (a.standIn) return;  // Grid stood in for the kept structure: not its frame time
    if (!a.exploring) {
      if (width != a.width || height != a.height) {
        startAutoExploration();
        return;
      }
      // Settled: the kept structure's frame at a view far from the measured one, with the camera
      // still since the previous frame and no edit in this frame, starts a re-check here (this
      // frame is its first).
      if (tfEdit || near(view, a.measuredAt, kAutoFarDegrees, kAutoFarZoom) ||
          !near(view, previous, kAutoStillDegrees, kAutoStillZoom))
        return;
      if (!startRecheck(view)) return;
      record(seconds());  // the frame just drawn: the kept one at this view
      a.queue.erase(a.queue.begin());
      a.current = a.queue.front();
      return;
    }
    const bool first = !a.rechecking && a.frames == std::vector<int>(a.frames.size(), 0);
    if (!first && (width != a.width || height != a.height)) {  // not comparable: from the start
      startAutoExploration();
      return;
    }
    if (a.rechecking && !near(view, a.recheckAt, kAutoRecheckDrift, kAutoStillZoom)) {
      // The camera moved during the re-check: its times are not comparable; keep the choice and
      // measure again when the camera rests (measuredAt stays where it was).
      cancelRecheck();
      return;
    }
    if (first) {
      a.width = width;
      a.height = height;
      a.measuredAt = view;
    }
    record(seconds());
    a.queue.erase(a.queue.begin());
    if (a.queue.empty() && a.round == 1) {
      // Round 2: the candidates within kAutoPrune of round 1's cheapest, in the reverse order,
      // each for frames adding up to kAutoMinMeasureSeconds (round 1's time), at most kAutoMaxRepeats.
      double cheapest = std::numeric_limits<double>::infinity();
      for (size_t i = 0; i < a.candidates.size(); ++i)
        if (autoCost(i) > 0) cheapest = std::min(cheapest, autoCost(i));
      for (int i = int(a.candidates.size()) - 1; i >= 0; --i) {
        const double c = autoCost(size_t(i));
        if (!(c > 0) || c > kAutoPrune * cheapest) continue;
        const double t = a.seconds[size_t(i)];
        const int repeats = std::clamp(int(std::ceil(kAutoMinMeasureSeconds / t)), 1, kAutoMaxRepeats);
        for (int k = 0; k < repeats; ++k) a.queue.push_back(i);
      }
      a.round = 2;
    }
    if (!a.queue.empty()) {
      a.current = a.queue.front();
      return;
    }
    // The decision over the candidates measured in this measuring: the cheapest (autoCost).
    int best = -1;
    for (size_t i = 0; i < a.candidates.size(); ++i)
      if (a.frames[i] > 0 && (best < 0 || autoCost(i) < autoCost(size_t(best)))) best = int(i);
    // Never slower than Naive: a structure must beat Naive by kAutoMargin to be kept (on dense
    // noise, 256^3, one frame each once put Grid 4% ahead of Naive and the next frames 11% behind
    // it); in a re-check the kept structure wins likewise unless another beats it by the margin.
    for (size_t i = 0; i < a.candidates.size(); ++i) {
      const bool favoured = a.rechecking ? int(i) == a.kept : a.candidates[i].builder == BuilderKind::Naive;
      if (favoured && a.frames[i] > 0 && int(i) != best && autoCost(size_t(best)) * kAutoMargin > autoCost(i))
        best = int(i);
    }
    if (a.rechecking && best != a.kept) ++a.switches;
    a.exploring = a.rechecking = false;
    a.round = 0;
    a.measuredAt = view;
    a.occupancy = backend->occupiedFraction();
    a.current = a.kept = best;
    describeAutoChoice();
  }

  /// "0.19 s", "12 ms", "0.35 ms": a duration a reader takes in at a glance.
  static std::string readableSeconds(double s) {
    char buf[32];
    if (s >= 1.0) std::snprintf(buf, sizeof buf, "%.2g s", s);
    else if (s >= 0.1) std::snprintf(buf, sizeof buf, "%.2f s", s);
    else std::snprintf(buf, sizeof buf, "%.2g ms", 1e3 * s);
    return buf;
  }

  /// Builder Choice: "Auto chose Grid: 0.19 s a frame, 1.4% occupied; measured (a frame
  /// [+ build/30]): Naive 4.1 s, Grid 0.19 s + 0.012 ms, ..." (probes: times scaled to the
  /// user's frame by its pixel count, and said so).
  void describeAutoChoice() {
    AutoState& a = autoState;
    const size_t k = size_t(a.kept);
    char buf[160];
    std::snprintf(buf, sizeof buf, "Auto chose %s: %s a frame, %.3g%% occupied", builderName(a.candidates[k].builder),
                  readableSeconds(a.seconds[k] * a.timeScale).c_str(), 100.0 * a.occupancy);
    std::string line = buf;
    if (a.rechecks) line += ", re-checked " + std::to_string(a.rechecks) + "x at new views";
    if (a.switches) line += ", switched " + std::to_string(a.switches) + "x";
    std::snprintf(buf, sizeof buf, "; measured (a frame + build/%g):", kAutoFramesPerBuild);
    line += buf;
    for (size_t i = 0; i < a.seconds.size(); ++i) {
      const double b = a.buildSeconds[i] > 0 ? a.buildSeconds[i] : 0.0;
      line += std::string(i ? ", " : " ") + builderName(a.candidates[i].builder) + " " +
              (a.seconds[i] > 0 ? readableSeconds(a.seconds[i] * a.timeScale) : std::string("-"));
      // A build term under 1% of the frame is left out: it changes nothing.
      if (b / kAutoFramesPerBuild > 0.01 * a.seconds[i] * a.timeScale)
        line += " + " + readableSeconds(b / kAutoFramesPerBuild);
    }
    if (a.timeScale > 1) {
      std::snprintf(buf, sizeof buf, " (from probes of 1/%.0f of the frame's pixels)", a.timeScale);
      line += buf;
    }
    a.choice = line;
    stats.choice = a.choice;
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
    autoState = AutoState{};
  }

  /// 4 dependent components: the colour channels' finite ranges (of the sampled values).
  double rgbRange[3][2] = {{0, 1}, {0, 1}, {0, 1}};
  void componentRanges() {
    if (volume.components != 4) return;
    for (int c = 0; c < 3; ++c)
      if (!volume.componentRange(c, rgbRange[c][0], rgbRange[c][1])) rgbRange[c][0] = 0, rgbRange[c][1] = 1;
  }

  /// Dependent components composite (the only mode vtkGPUVolumeRayCastMapper defines colour and
  /// opacity for from several components): other blend modes are drawn composite, with a warning.
  BlendMode blendMode() {
    if (volume.components > 1 && render.blend != BlendMode::Composite) {
      warn("blend mode " + std::to_string(int(render.blend)) + " with " + std::to_string(volume.components) +
           " dependent components is not supported: drawn as composite");
      return BlendMode::Composite;
    }
    return render.blend;
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

  void update() {
    if (!haveVolume) throw std::runtime_error("no volume set");
    if (!haveTF) throw std::runtime_error("no transfer function set");
    const bool refineNow = autoState.standIn;  // the last frame stood in: build the kept one now
    bool edited = false;                       // this update's classification changed the occupancy
    const CropClip cc = cropClipFor();
    if (cc != cropClip) {
      cropClip = cc;
      cropClipDirty = true;
    }
    const bool newRanges = rangesDirty;
    if (rangesDirty) {
      report(0.0, "value ranges");
      backend->setVolume(volume, build.brick);
      ++counters.rangeGrids;
      rangesDirty = false;
      opacityDirty = true;
      buildDirty = true;
    }
    if (opacityDirty || colorDirty || cropClipDirty) {
      // A TF (or crop/clip) edit: no contender is built on the frame that shows it.
      autoState.tfEdit = true;
      cancelRecheck();
    }
    if (opacityDirty || cropClipDirty) {
      report(0.3, "classification");
      auto t0 = Clock::now();
      bool changed = backend->classify(scaledTF(), cropClip);
      stats.classifySeconds = since(t0);
      stats.classifyWaitSeconds = backend->lastClassifyWaitSeconds();
      ++counters.classifications;
      if (opacityDirty) tableDirty = true;  // planes alone leave the table as it is
      opacityDirty = cropClipDirty = false;
      if (changed) buildDirty = edited = true;
      if (changed && build.builder == BuilderKind::Auto && !autoState.exploring && autoState.occupancy >= 0 &&
          std::fabs(backend->occupiedFraction() - autoState.occupancy) > kAutoReexplore)
        startAutoExploration(true);
    }
    if (build.builder == BuilderKind::Auto && autoState.candidates.empty()) startAutoExploration();
    if (tableDirty || colorDirty) {
      if (!tableDirty) ++counters.colorUpdates;
      std::string note;
      const double step = effectiveSampleDistance(latticeShape(), render.sampleDistance, &note);
      if (!note.empty()) warn(note);
      float lo, scale;
      tableMapping(scaledTF(), static_cast<int>(tf.table.size()), lo, scale);
      backend->setTransferTable(tableForBlend(tf, float(step), blendMode()), lo, scale);
      tableDirty = colorDirty = false;
    }
    if (refineNow && !buildDirty) buildDirty = true;
    // Progressive refinement without any build: an edit that only emptied bricks leaves the
    // structure Auto holds covering every occupied brick, so the edit's frame draws with it
    // (lossless: it only visits some bricks that are empty now, whose sub-brick masks are 0)
    // and the next frame rebuilds it.
    if (buildDirty && edited && !newRanges && build.builder == BuilderKind::Auto && build.autoQuickBuildSeconds >= 0 &&
        !autoState.exploring && autoState.built >= 0 && autoState.built == autoState.current &&
        buildsBeyondClassification(autoState.candidates[size_t(autoState.current)].builder) &&
        backend->lastClassifyOnlyEmptied()) {
      AutoState& a = autoState;
      a.standIn = true;
      a.refined = false;
      buildDirty = false;
      stats.seconds = 0;
      stats.occupancy = backend->occupiedFraction();
      stats.choice = a.choice + "; this frame: the " + builderName(a.candidates[size_t(a.current)].builder) +
                     " built before the edit (it only emptied bricks), rebuilt next frame";
      ++counters.staleFrames;
    }
    // Auto: the structure to draw with is built when the backend holds another (measuring moves
    // `current`; a cancelled re-check whose contender was never built rebuilds nothing).
    if (build.builder == BuilderKind::Auto && autoState.current != autoState.built) buildDirty = true;
    if (buildDirty) {
      const bool isAuto = build.builder == BuilderKind::Auto;
      int use = isAuto ? autoState.current : -1;
      if (isAuto) {
        // Progressive refinement: right after an edit, a kept structure that is slow to build
        // gives way to Grid (its occupancy grid is classification's output) for one frame; the
        // image is the same (lossless), only that frame's speed differs.
        AutoState& a = autoState;
        const int grid = gridCandidate();
        const double kept = a.buildSeconds.empty() ? -1.0 : a.buildSeconds[size_t(a.current)];
        a.standIn = edited && !a.exploring && grid >= 0 && grid != a.current &&
                    a.candidates[size_t(a.current)].builder != BuilderKind::Naive && build.autoQuickBuildSeconds >= 0 &&
                    kept > build.autoQuickBuildSeconds;
        a.refined = refineNow && !a.standIn;
        if (a.standIn) use = grid;
      }
      BuildParams p = isAuto ? autoState.candidates[size_t(use)] : build;
      const BuilderInfo& info = builderInfo(p.builder);
      if (!runsOnCpu(info) && backend->kind() != BackendKind::CUDA) {
        warn(std::string("builder ") + info.name + " needs the CUDA backend; building " + builderName(info.fallback) +
             " with the same parameters");
        p.builder = info.fallback;
      }
      BuildStats s;
      if (!autoState.exploring) report(0.4, "build");
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
      if (isAuto) {
        autoState.built = use;
        autoState.buildSeconds[size_t(use)] = s.seconds;
        s.choice = autoState.choice;
        if (autoState.standIn)
          s.choice += std::string("; this frame: Grid after the edit, ") +
                      builderName(autoState.candidates[size_t(autoState.current)].builder) + " next frame";
      }
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
void Engine::setProgress(std::function<void(double, const char*)> progress) {
  impl_->progress = std::move(progress);
  impl_->backend->setProgress(impl_->backendProgress());
}

void Engine::setVolume(const Volume& v) {
  validate(v);
  impl_->volume = v;
  impl_->valueExponent = 0;
  impl_->autoState = Impl::AutoState{};
  // The integrator samples in float: magnitudes near the ends of double's (or float's) range
  // would overflow trilinear interpolation or the table mapping (+-1e308 gave a blank image),
  // and denormal-scale data would collapse to one table entry. Such volumes are sampled from a
  // float copy scaled by an exact power of two; the TF range is scaled alike, so the image is
  // the one of the unscaled data. NaN stays NaN and +-Inf stays +-Inf in the copy.
  if (v.type == VoxelType::Float32 || v.type == VoxelType::Float64) {
    const int64_t n = v.voxelCount() * v.components;
    double lo = 0, hi = 0;  // the parallel finite range pass (NaN and +-Inf skipped)
    const double m = v.scalarRange(lo, hi) ? std::max(std::fabs(lo), std::fabs(hi)) : 0.0;
    if (m > 0 && (m > 0x1p60 || m < 0x1p-60)) {
      int e = 0;
      std::frexp(m, &e);
      auto copy = std::make_shared<std::vector<unsigned char>>(size_t(n) * sizeof(float));
      float* out = reinterpret_cast<float*>(copy->data());
      // m * 2^-e lies in [0.5, 1); ldexp is exact and reaches denormal scales a factor can't.
      if (v.type == VoxelType::Float32) scaleToFloat(static_cast<const float*>(v.data), out, n, -e);
      else scaleToFloat(static_cast<const double*>(v.data), out, n, -e);
      impl_->volume.type = VoxelType::Float32;
      impl_->volume.storage = copy;
      impl_->volume.data = copy->data();
      impl_->valueExponent = -e;
    }
  }
  impl_->componentRanges();
  impl_->haveVolume = true;
  impl_->rangesDirty = true;
  impl_->tableDirty = true;  // the default sample distance follows the spacing
}

void Engine::setTransferFunction(TransferFunction tf, bool colorMayDiffer, bool opacityMayDiffer) {
  if (tf.table.empty()) throw std::invalid_argument("empty transfer-function table");
  Impl& d = *impl_;
  // A table of another size, or the first one, is new as a whole whatever the caller says.
  const bool whole = !d.haveTF || tf.table.size() != d.tf.table.size();
  bool opacity = whole;
  if (!opacity && opacityMayDiffer) {
    ++d.counters.opacityCompares;
    opacity = !tf.sameOpacity(d.tf);
  }
  if (opacity) {
    d.opacityDirty = true;  // re-classified, and the whole table set again
  } else if (colorMayDiffer) {
    ++d.counters.colorCompares;
    if (!tf.sameColor(d.tf)) d.colorDirty = true;
  }
  d.tf = std::move(tf);
  d.haveTF = true;
}

void Engine::setBuildParams(const BuildParams& p) {
  // bins 1 would mean no candidate plane at all; rejected rather than silently clamped, since 0
  // (the sweep) is now a meaningful value next to it.
  validate(p);
  Impl& d = *impl_;
  if (p.brick != d.build.brick) d.rangesDirty = true;
  if (p != d.build) {
    d.buildDirty = true;
    d.autoState = Impl::AutoState{};  // Auto measures again with the new parameters
  }
  d.build = p;
  d.build.brick = std::max(1, p.brick);
}

void Engine::setRenderParams(const RenderParams& p) {
  if (p.sampleDistance != impl_->render.sampleDistance || p.blend != impl_->render.blend) impl_->tableDirty = true;
  impl_->render = p;
}

void Engine::setPiece(const VolumePiece& p) {
  if (p.wholeDims.x != impl_->piece.wholeDims.x || p.wholeDims.y != impl_->piece.wholeDims.y ||
      p.wholeDims.z != impl_->piece.wholeDims.z)
    impl_->tableDirty = true;  // the sample distance's bounds follow the whole box
  impl_->piece = p;
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
/// The light list (RenderParams::lights) into the frame, in its origin-relative world space.
template <class Impl>
void fillLights(Impl& d, FrameView& f) {
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
    v.pos = vec3f{float(l.position[0] - d.volume.origin[0]), float(l.position[1] - d.volume.origin[1]),
                  float(l.position[2] - d.volume.origin[2])};
    v.diffuse = vec3f{float(l.diffuse[0]), float(l.diffuse[1]), float(l.diffuse[2])};
    v.specular = vec3f{float(l.specular[0]), float(l.specular[1]), float(l.specular[2])};
    v.atten = vec3f{float(l.attenuation[0]), float(l.attenuation[1]), float(l.attenuation[2])};
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
void fillBlend(Impl& d, FrameView& f) {
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
  f.normScale = hi > lo ? float(1.0 / (hi - lo)) : 0.f;
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
  fillLights(d, f);
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
  // (computeLighting(color, 0)); later VTK uses component 3 for 4 components. Measured against
  // ParaView 5.11's vtkGPUVolumeRayCastMapper on TestSpaceSkippingVolumeRGBA shaded: 59.9 dB
  // with component 0, 25.7 dB with component 3.
  f.gradientComponent = 0;
  if (v.components > 1 && d.render.filter == FilterMode::Hardware)
    d.warn("hardware filtering with dependent components: sampling exactly");
}
}  // namespace

void Engine::render(const Camera& cam, int width, int height, Image& out, const float* depth,
                    const float* alphaIn) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("render size must be positive");
  update();
  Impl& d = *impl_;
  FrameView f{};
  // The kernels march in float in a frame relative to the volume's origin: both matrices are
  // composed with the origin shift here in double, so georeferenced data (origin 1e6..1e7,
  // where a float ulp is ~1 world unit) renders exactly like the same volume at the origin.
  mat4 vp = multiply(cam.proj, cam.view), ivp;
  if (!invert(vp, ivp)) throw std::invalid_argument("camera matrix is singular");
  // A piece of a larger volume (MPI): rays, box and planes are the whole volume's, relative to
  // its voxel 0, the same bits on every rank; the lattice part of the frame says what it draws.
  const VolumePiece* piece = d.fittingPiece();
  const double* origin = piece ? piece->wholeOrigin : d.volume.origin;
  mat4 toOrigin = identity4();
  Volume atOrigin = d.volume;
  for (int i = 0; i < 3; ++i) {
    toOrigin.m[12 + i] = -origin[i];
    atOrigin.origin[i] = 0;
  }
  const mat4 ivpRel = multiply(toOrigin, ivp);
  for (int i = 0; i < 16; ++i) f.invViewProj[i] = float(ivpRel.m[i]);
  const mat4 indexToWorldRel = atOrigin.indexToWorld();
  mat4 w2i;
  if (!invert(indexToWorldRel, w2i)) throw std::invalid_argument("volume direction/spacing is singular");
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
  f.dt = float(d.dt());
  f.ertThreshold = d.render.ertThreshold > 1.0 ? 2.f : float(d.render.ertThreshold);
  f.cut = piece ? d.cropClipFor(origin) : d.cropClip;  // the planes classification used (shifted)
  f.jitter = d.render.jitter ? 1 : 0;
  f.jitterSeed = d.render.jitterSeed;
  f.firstSample = float(std::max(0.0, d.render.firstSampleOffset));
  mat4 iv;
  if (!invert(cam.view, iv)) throw std::invalid_argument("camera view matrix is singular");
  // The eye in the same origin-relative frame as the rays (subtracted in double).
  f.eyeW = vec3f{float(iv.m[12] - origin[0]), float(iv.m[13] - origin[1]), float(iv.m[14] - origin[2])};
  fillBlend(d, f);
  fillComponents(d, f);
  std::vector<unsigned> counts;
  if (d.render.countSamples) {
    counts.assign(size_t(width) * size_t(height), 0u);
    f.sampleCount = counts.data();
  }
  const bool autoProbes = d.build.builder == BuilderKind::Auto && d.autoProbes();
  if (autoProbes) {
    d.autoProbe(f, width, height, d.viewKey(cam));
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
  if (d.build.builder == BuilderKind::Auto && !autoProbes)
    d.autoFrameDone([&d] { return d.frameDeviceSeconds() > 0 ? d.frame.deviceSeconds : d.frame.seconds; }, width,
                    height, d.viewKey(cam));
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
  return impl_->build.builder == BuilderKind::Auto && (impl_->autoState.exploring || impl_->autoState.candidates.empty());
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

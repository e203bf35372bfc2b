// AutoBuilder: Builder Auto's measuring rule (see AutoBuilder.h).
#include "spaceskip/AutoBuilder.h"

#include "spaceskip/Builders.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace spaceskip {

AutoBuilder::ViewKey AutoBuilder::viewKey(const Camera& cam, const double b[6]) {
  ViewKey k;
  const double* v = cam.view.m;  // column-major: row 2 of the rotation is the backward axis
  const double n = std::sqrt(v[2] * v[2] + v[6] * v[6] + v[10] * v[10]);
  mat4 iv;
  if (!(n > 0) || !invert(cam.view, iv)) return k;
  for (int i = 0; i < 3; ++i) k.dir[i] = v[2 + 4 * i] / n;
  k.zoom = std::fabs(cam.proj.m[0]);
  double d2 = 0;
  for (int i = 0; i < 3; ++i) {
    const double d = iv.m[12 + i] - 0.5 * (b[2 * i] + b[2 * i + 1]);
    d2 += d * d;
  }
  k.distance = std::sqrt(d2);
  k.valid = std::isfinite(k.zoom) && std::isfinite(k.distance);
  return k;
}

bool AutoBuilder::near(const ViewKey& a, const ViewKey& b, double degrees, double zoom) {
  if (!a.valid || !b.valid) return false;
  const double c = a.dir[0] * b.dir[0] + a.dir[1] * b.dir[1] + a.dir[2] * b.dir[2];
  const double angle = std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / 3.14159265358979323846;
  auto ratio = [](double x, double y) { return x > 0 && y > 0 ? std::max(x / y, y / x) : (x == y ? 1.0 : 1e30); };
  return angle <= degrees && ratio(a.zoom, b.zoom) <= zoom && ratio(a.distance, b.distance) <= zoom;
}

std::vector<BuildParams> AutoBuilder::candidates(const BuildParams& base, BackendKind kind) {
  auto with = [&](BuilderKind k, int mls) {
    BuildParams p = base;
    p.builder = k;
    p.leaf = LeafCriterion::Deep;
    p.maxLeafSize = mls;
    return p;
  };
  if (kind == BackendKind::CUDA) {
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

bool AutoBuilder::usesProbes(const BuildParams& base, BackendKind kind) {
  return base.autoProbe > 0 || (base.autoProbe < 0 && kind == BackendKind::CPU);
}

void AutoBuilder::probeSize(int width, int height, int& pw, int& ph) {
  const double f = std::max(4.0, double(std::max(width, height)) / 128.0);
  pw = std::max(std::min(width, 16), int(width / f));
  ph = std::max(std::min(height, 16), int(height / f));
}

int AutoBuilder::gridCandidate() const {
  for (size_t i = 0; i < candidates_.size(); ++i)
    if (candidates_[i].builder == BuilderKind::Grid) return int(i);
  return -1;
}

/// Starts measuring: every candidate (the first pass), or, for a re-check, the kept one and its
/// contenders; the first in the queue is built next.
void AutoBuilder::beginMeasuring(std::vector<int> queue, bool recheck) {
  frames_.assign(candidates_.size(), 0);
  queue_ = std::move(queue);
  exploring_ = true;
  rechecking_ = recheck;
  pass_ = recheck ? 0 : 1;
  current_ = firstMeasured_ = queue_.front();
}

void AutoBuilder::start(const BuildParams& base, BackendKind kind, bool afterEdit) {
  base_ = base;
  kind_ = kind;
  candidates_ = candidates(base, kind);
  seconds_.assign(candidates_.size(), -1.0);
  buildSeconds_.assign(candidates_.size(), -1.0);
  kept_ = -1;
  current_ = -1;
  rechecks_ = switches_ = 0;
  std::vector<int> all(candidates_.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = int(i);
  const int grid = gridCandidate();
  if (afterEdit && grid > 0) std::rotate(all.begin(), all.begin() + grid, all.begin() + grid + 1);
  beginMeasuring(all, false);
  choice_ = "Auto: measuring " + std::to_string(candidates_.size()) + " structures";
  built_ = -1;  // the candidates are new: build whatever is current
}

bool AutoBuilder::occupancyMoved(double occupied) const {
  return !exploring_ && occupancy_ >= 0 && std::fabs(occupied - occupancy_) > kReexplore;
}

/// Ends a re-check without a decision: the kept structure draws the next frame.
void AutoBuilder::cancelRecheck() {
  if (!rechecking_) return;
  exploring_ = rechecking_ = false;
  queue_.clear();
  current_ = kept_;
}

void AutoBuilder::edited() {
  tfEdit_ = true;
  cancelRecheck();
}

bool AutoBuilder::drawStale(std::string& note) {
  if (exploring_ || built_ < 0 || built_ != current_ ||
      !buildsBeyondClassification(candidates_[size_t(current_)].builder))
    return false;
  standIn_ = true;
  refined_ = false;
  note = choice_ + "; this frame: the " + builderName(candidates_[size_t(current_)].builder) +
         " built before the edit (it only emptied bricks), rebuilt next frame";
  return true;
}

int AutoBuilder::chooseBuild(bool edited, bool refineNow, double quickBuildSeconds) {
  const int grid = gridCandidate();
  const double kept = buildSeconds_.empty() ? -1.0 : buildSeconds_[size_t(current_)];
  standIn_ = edited && !exploring_ && grid >= 0 && grid != current_ &&
             candidates_[size_t(current_)].builder != BuilderKind::Naive && quickBuildSeconds >= 0 &&
             kept > quickBuildSeconds;
  refined_ = refineNow && !standIn_;
  return standIn_ ? grid : current_;
}

std::string AutoBuilder::builtCandidate(int i, double seconds) {
  built_ = i;
  buildSeconds_[size_t(i)] = seconds;
  std::string line = choice_;
  if (standIn_)
    line += std::string("; this frame: Grid after the edit, ") +
            builderName(candidates_[size_t(current_)].builder) + " next frame";
  return line;
}

/// A candidate's cost per frame: its measured frame time plus its last build time spread over
/// kFramesPerBuild frames; < 0 when it has no frame time yet.
double AutoBuilder::cost(size_t i) const {
  if (!(seconds_[i] > 0)) return -1.0;
  const double b = i < buildSeconds_.size() && buildSeconds_[i] > 0 ? buildSeconds_[i] : 0.0;
  return seconds_[i] + b / kFramesPerBuild;
}

/// Records a measured frame of the current candidate (the minimum of its frames so far).
void AutoBuilder::record(double seconds) {
  double& t = seconds_[size_t(current_)];
  t = frames_[size_t(current_)]++ == 0 ? seconds : std::min(t, seconds);
}

/// Starts a re-check of the kept structure at `view` against its contenders: those within kPrune
/// of it when it was measured, at least the runner-up (the likeliest to overtake it at another
/// view); the queue is the kept one, the contenders, them again reversed, the kept one. False
/// (nothing started) with a single candidate.
bool AutoBuilder::startRecheck(const ViewKey& view) {
  std::vector<int> q;
  int runnerUp = -1;
  for (size_t i = 0; i < candidates_.size(); ++i) {
    if (int(i) == kept_ || !(seconds_[i] > 0)) continue;
    if (cost(i) < kPrune * cost(size_t(kept_))) q.push_back(int(i));
    if (runnerUp < 0 || cost(i) < cost(size_t(runnerUp))) runnerUp = int(i);
  }
  if (q.empty() && runnerUp >= 0) q.push_back(runnerUp);
  if (q.empty()) {  // a single candidate: nothing to re-check
    measuredAt_ = view;
    return false;
  }
  const int contenders = int(q.size());
  for (int i = contenders - 1; i >= 0; --i) q.push_back(q[size_t(i)]);  // the second pass, reversed
  q.push_back(kept_);
  ++rechecks_;
  recheckAt_ = view;
  std::vector<int> queue{kept_};
  queue.insert(queue.end(), q.begin(), q.end());
  beginMeasuring(queue, true);
  return true;
}

/// The second pass: the candidates within kPrune of the first pass's cheapest, in the reverse
/// order, each for frames adding up to kMinMeasureSeconds (the first pass's time), at most
/// kMaxRepeats. The first pass's first frame also pays the measuring's warm-up (cold caches, the
/// thread pool waking, a page-in after other work): its candidate, when that frame alone would
/// prune it, draws one frame more (once Naive's first 64 x 64 probe of the dense Wavelet took
/// 46 ms against its usual 16, and Auto kept Grid, slower than Naive).
void AutoBuilder::queueSecondPass() {
  double cheapest = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < candidates_.size(); ++i)
    if (cost(i) > 0) cheapest = std::min(cheapest, cost(i));
  for (int i = int(candidates_.size()) - 1; i >= 0; --i) {
    const double c = cost(size_t(i));
    if (!(c > 0)) continue;
    if (c > kPrune * cheapest) {
      if (i == firstMeasured_) queue_.push_back(i);
      continue;
    }
    const double t = seconds_[size_t(i)];
    const int repeats = std::clamp(int(std::ceil(kMinMeasureSeconds / t)), 1, kMaxRepeats);
    for (int k = 0; k < repeats; ++k) queue_.push_back(i);
  }
  pass_ = 2;
}

/// The decision over the candidates measured in this measuring: the cheapest (cost()).
void AutoBuilder::decide(const ViewKey& view, double occupied) {
  int best = -1;
  for (size_t i = 0; i < candidates_.size(); ++i)
    if (frames_[i] > 0 && (best < 0 || cost(i) < cost(size_t(best)))) best = int(i);
  // Never slower than Naive: a structure must beat Naive by kMargin to be kept (on dense noise,
  // 256^3, one frame each once put Grid 4% ahead of Naive and the next frames 11% behind it); in
  // a re-check the kept structure wins likewise unless another beats it by the margin.
  for (size_t i = 0; i < candidates_.size(); ++i) {
    const bool favoured = rechecking_ ? int(i) == kept_ : candidates_[i].builder == BuilderKind::Naive;
    if (favoured && frames_[i] > 0 && int(i) != best && cost(size_t(best)) * kMargin > cost(i)) best = int(i);
  }
  if (rechecking_ && best != kept_) ++switches_;
  exploring_ = rechecking_ = false;
  pass_ = 0;
  measuredAt_ = view;
  occupancy_ = occupied;
  current_ = kept_ = best;
  describeChoice();
}

bool AutoBuilder::frameDone(const std::function<double()>& seconds, int width, int height, const ViewKey& view,
                            const std::function<double()>& occupied) {
  const ViewKey previous = lastView_;
  lastView_ = view;
  const bool tfEdit = tfEdit_;
  tfEdit_ = false;
  if (standIn_) return false;  // Grid stood in for the kept structure: not its frame time
  if (!exploring_) {
    if (width != width_ || height != height_) {
      start(base_, kind_);
      return false;
    }
    // Settled: the kept structure's frame at a view far from the measured one, with the camera
    // still since the previous frame and no edit in this frame, starts a re-check here (this
    // frame is its first).
    if (tfEdit || near(view, measuredAt_, kFarDegrees, kFarZoom) || !near(view, previous, kStillDegrees, kStillZoom))
      return false;
    if (!startRecheck(view)) return false;
    record(seconds());  // the frame just drawn: the kept one at this view
    queue_.erase(queue_.begin());
    current_ = queue_.front();
    return false;
  }
  const bool first = !rechecking_ && frames_ == std::vector<int>(frames_.size(), 0);
  if (!first && (width != width_ || height != height_)) {  // not comparable: from the start
    start(base_, kind_);
    return false;
  }
  if (rechecking_ && !near(view, recheckAt_, kRecheckDrift, kStillZoom)) {
    // The camera moved during the re-check: its times are not comparable; keep the choice and
    // measure again when the camera rests (measuredAt_ stays where it was).
    cancelRecheck();
    return false;
  }
  if (first) {
    width_ = width;
    height_ = height;
    measuredAt_ = view;
  }
  record(seconds());
  queue_.erase(queue_.begin());
  if (queue_.empty() && pass_ == 1) queueSecondPass();
  if (!queue_.empty()) {
    current_ = queue_.front();
    return false;
  }
  decide(view, occupied());
  return true;
}

bool AutoBuilder::measureOnProbes(int width, int height, const ViewKey& view,
                                  const std::function<double(int, int)>& drawProbe,
                                  const std::function<void(double)>& progress,
                                  const std::function<double()>& occupied, bool& decided) {
  decided = false;
  const ViewKey previous = lastView_;
  lastView_ = view;
  const bool tfEdit = tfEdit_;
  tfEdit_ = false;
  if (!exploring_ && !standIn_) {
    if (width != fullWidth_ || height != fullHeight_) start(base_, kind_);
    else if (!tfEdit && !near(view, measuredAt_, kFarDegrees, kFarZoom) &&
             near(view, previous, kStillDegrees, kStillZoom))
      startRecheck(view);
  }
  if (!exploring_) return false;
  fullWidth_ = width;
  fullHeight_ = height;
  int pw = 0, ph = 0;
  probeSize(width, height, pw, ph);
  timeScale_ = double(width) * double(height) / (double(pw) * double(ph));
  calibrated_ = false;
  // Each candidate at most 1 + 1 + kMaxRepeats probes (a re-check: 2 + 2): a bound, not a rule.
  const int bound = 8 * int(candidates_.size());
  for (int guard = 0; exploring_ && guard < bound; ++guard) {
    progress(double(guard) / double(bound));
    const double t = drawProbe(pw, ph);
    if (frameDone([t] { return t; }, pw, ph, view, occupied)) decided = true;
  }
  if (exploring_) cancelRecheck();  // the bound was hit: keep the cheapest measured so far
  calibrate_ = true;
  return true;
}

bool AutoBuilder::keptFrameDrawn(double seconds) {
  if (!calibrate_ || exploring_ || standIn_ || kept_ < 0 || built_ != kept_) return false;
  calibrate_ = false;
  const double probe = seconds_[size_t(kept_)];
  if (!(seconds > 0) || !(probe > 0)) return false;
  timeScale_ = seconds / probe;
  calibrated_ = true;
  describeChoice();
  return true;
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
void AutoBuilder::describeChoice() {
  const size_t k = size_t(kept_);
  char buf[160];
  std::snprintf(buf, sizeof buf, "Auto chose %s: %s a frame, %.3g%% occupied", builderName(candidates_[k].builder),
                readableSeconds(seconds_[k] * timeScale_).c_str(), 100.0 * occupancy_);
  std::string line = buf;
  if (rechecks_) line += ", re-checked " + std::to_string(rechecks_) + "x at new views";
  if (switches_) line += ", switched " + std::to_string(switches_) + "x";
  std::snprintf(buf, sizeof buf, "; measured (a frame + build/%g):", kFramesPerBuild);
  line += buf;
  for (size_t i = 0; i < seconds_.size(); ++i) {
    const double b = buildSeconds_[i] > 0 ? buildSeconds_[i] : 0.0;
    line += std::string(i ? ", " : " ") + builderName(candidates_[i].builder) + " " +
            (seconds_[i] > 0 ? readableSeconds(seconds_[i] * timeScale_) : std::string("-"));
    // A build term under 1% of the frame is left out: it changes nothing.
    if (b / kFramesPerBuild > 0.01 * seconds_[i] * timeScale_) line += " + " + readableSeconds(b / kFramesPerBuild);
  }
  if (calibrated_) line += " (measured on probes, scaled by the kept structure's own frame)";
  else if (timeScale_ > 1) {
    std::snprintf(buf, sizeof buf, " (from probes of 1/%.0f of the frame's pixels)", timeScale_);
    line += buf;
  }
  choice_ = line;
}

}  // namespace spaceskip

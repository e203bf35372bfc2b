// AutoBuilder: Builder Auto's measuring rule ("never slower than naive"), out of the Engine. The
// Engine asks it which candidate to build and draw with, and tells it the frame times it saw.
//
// Skipping is lossless, so every candidate draws the same image and only its speed differs.
// Measuring: every candidate renders a frame, in turn (the first pass); those within kPrune of the
// first pass's cheapest (and the first one, whose frame paid the measuring's warm-up) render
// again, in the reverse order (the second pass: A B C D, then D C B A, so a drift of the machine's
// load favours none and the last structure of the first pass needs no rebuild), short frames
// several times in a row (until kMinMeasureSeconds, at most kMaxRepeats frames: one
// sub-millisecond frame is at the mercy of a launch's jitter); a candidate's frame time
// is the minimum of its frames (other work only ever adds time). Its cost is that frame time plus
// its build time spread over kFramesPerBuild frames (cost()): a structure that draws a few percent
// faster at the measured view but takes milliseconds to rebuild on every opacity edit loses to one
// nearly as fast that rebuilds at once. The cheapest is kept, over Naive only when kMargin cheaper.
// The candidates are measured again when the occupancy moves by more than kReexplore or the image
// size changes, otherwise an occupancy change rebuilds the chosen one only.
// Frame times depend on the view, so measurements are compared only when taken at one view: once
// the camera has moved far (kFarDegrees, or a zoom of kFarZoom) from where the choice was measured
// and then stays still, the kept structure is re-checked there against the contenders (those
// within kPrune of it when it was measured, at least the runner-up), two frames each; a moving
// camera (an orbit) never triggers a re-check, and one that moves during it cancels it. A frame
// that carries a TF or crop/clip change never builds a contender: it cancels a re-check under way
// and starts none, so an edit under Auto costs what the kept structure's edit costs (a user
// editing at a resting view would otherwise pay a contender's build on the frames that show the
// edits).
// On probes (BuildParams::autoProbe, the CPU backend's default) a measuring runs to its decision
// inside the frame that needs it, every candidate drawn on reduced frames of the same view.
#pragma once
#include "Camera.h"
#include "Types.h"

#include <functional>
#include <string>
#include <vector>

namespace spaceskip {

class AutoBuilder {
public:
  /// Where a frame was seen from, for comparing frame times taken at one view.
  struct ViewKey {
    double dir[3] = {0, 0, 0};  ///< the camera's backward axis in world space
    double zoom = 0;            ///< |proj[0][0]|
    double distance = 0;        ///< the eye's distance from the volume's centre (perspective)
    bool valid = false;
  };
  /// The view of `cam` on a volume with world bounds `bounds` (xmin, xmax, ymin, ...).
  static ViewKey viewKey(const Camera& cam, const double bounds[6]);
  /// Whether two views are within `degrees` and a factor `zoom` (in scale and, for perspective
  /// cameras, eye distance) of each other; an invalid one is near nothing.
  static bool near(const ViewKey& a, const ViewKey& b, double degrees, double zoom);

  /// Measuring all candidates again when the occupancy moves by more than this.
  static constexpr double kReexplore = 0.1;
  /// The second pass (and a re-check) measures only candidates within this factor of the cheapest.
  static constexpr double kPrune = 1.5;
  /// The second pass renders a candidate until its frames there add up to this, at most kMaxRepeats.
  static constexpr double kMinMeasureSeconds = 2e-3;
  static constexpr int kMaxRepeats = 3;
  /// A candidate's build time counts as if spread over this many frames (cost()): an opacity edit
  /// about every second at 30 frames/s, as when a user drags a TF point. On the H100
  /// (docs/results/h100-auto) the k-d tree drew the first, axis-aligned
  /// view of aneurism, stag beetle and kingsnake 3-8% faster than DistanceGrid and the orbit
  /// 5-11% slower, with builds of 0.9-2.2 ms against 0.03-0.33 ms: this weight keeps DistanceGrid
  /// there, and the k-d tree where it is 17-58% faster (Menger, Richtmyer-Meshkov).
  static constexpr double kFramesPerBuild = 30;
  /// A structure is kept over Naive (or over the kept one in a re-check) only when this much faster.
  static constexpr double kMargin = 1.05;
  /// A view this far from the measured one (degrees between view directions, or zoom ratio) is
  /// another view; consecutive frames within kStill* of each other are a still camera.
  static constexpr double kFarDegrees = 25.0, kFarZoom = 1.25;
  static constexpr double kStillDegrees = 2.0, kStillZoom = 1.02;
  /// A re-check is cancelled when the camera moves this far from where it started.
  static constexpr double kRecheckDrift = 5.0;

  /// The candidates Auto measures for `base` on a backend of `kind`.
  static std::vector<BuildParams> candidates(const BuildParams& base, BackendKind kind);
  /// Whether Auto measures on probes (BuildParams::autoProbe) on a backend of `kind`.
  static bool usesProbes(const BuildParams& base, BackendKind kind);
  /// The probe size for a frame of width x height: 1/4 of each axis or less, at most 128 pixels
  /// a side, at least 16 (or the frame's own size below that).
  static void probeSize(int width, int height, int& pw, int& ph);

  /// Forgets everything: the next started() is false (new volume, parameters or backend).
  void reset() { *this = AutoBuilder{}; }
  /// Whether candidates were set up since the last reset().
  bool started() const { return !candidates_.empty(); }
  /// Measuring (all candidates, or a re-check).
  bool exploring() const { return exploring_; }
  /// Measures every candidate of `base` on a backend of `kind` from the start. `afterEdit`: an
  /// opacity edit moved the occupancy, and the frame that shows it is the first measured: Grid
  /// (no build beyond the classification) draws it instead of Naive, so the edit costs what
  /// Grid's frame costs.
  void start(const BuildParams& base, BackendKind kind, bool afterEdit = false);
  /// Whether an occupancy of `occupied` is far enough from the one the choice was made at to
  /// measure again (kReexplore; never while measuring).
  bool occupancyMoved(double occupied) const;

  /// This frame carries a transfer-function (or crop/clip) change: it builds no contender (a
  /// re-check under way is cancelled, none starts).
  void edited();
  /// Whether the structure to draw with differs from the one the backend holds.
  bool needsBuild() const { return current_ != built_; }
  /// The last frame drew with Grid standing in for the kept structure (build the kept one now).
  bool standingIn() const { return standIn_; }
  /// Progressive refinement without any build: when the kept structure is built and builds
  /// beyond classification, an edit that only emptied bricks draws with it; true when it does
  /// (it is rebuilt on the next frame), and `note` is the Builder Choice line to show.
  bool drawStale(std::string& note);
  /// The candidate to build now. Right after an edit (`edited`) a kept structure slower to build
  /// than `quickBuildSeconds` (BuildParams::autoQuickBuildSeconds, < 0: never) gives way to Grid
  /// for one frame; `refineNow`: the last frame stood in.
  int chooseBuild(bool edited, bool refineNow, double quickBuildSeconds);
  const BuildParams& candidate(int i) const { return candidates_[size_t(i)]; }
  /// The backend now holds candidate `i`, built in `seconds`; returns the Builder Choice line.
  std::string builtCandidate(int i, double seconds);

  /// After a frame of `seconds()` at width x height seen from `view`: records it and picks the
  /// next build. `seconds` is called only when a time is recorded (it may wait for the device);
  /// `occupied` when a decision is made. True when this frame made a decision (choice() is new).
  bool frameDone(const std::function<double()>& seconds, int width, int height, const ViewKey& view,
                 const std::function<double()>& occupied);
  /// Auto on probes, before the user's frame (width x height, seen from `view`) is drawn: the
  /// triggers of the per-frame rule (a new frame size; a still camera far from where the choice
  /// was measured, without an edit in this frame) start a measuring, and a measuring runs to its
  /// decision here. `drawProbe(pw, ph)` builds what needsBuild() asks for, draws a probe of that
  /// size and returns its time; `progress` gets the fraction of the measuring's bound done.
  /// Returns whether a measuring ran; `decided` whether it made a decision.
  bool measureOnProbes(int width, int height, const ViewKey& view,
                       const std::function<double(int, int)>& drawProbe,
                       const std::function<void(double)>& progress, const std::function<double()>& occupied,
                       bool& decided);
  /// The Builder Choice line ("Auto chose Grid: 0.19 s a frame, ...", or "Auto: measuring ...").
  /// After the user's frame that follows a measuring on probes, drawn with the kept structure in
  /// `seconds`: the probes' times are scaled by that frame over the kept one's probe (the ratio
  /// of a probe to a frame differs by structure only as much as their probes do; pixel counts
  /// alone overstate SIMD frames, whose packets gain more on full frames). True when the choice
  /// line changed.
  bool keptFrameDrawn(double seconds);
  const std::string& choice() const { return choice_; }

private:
  int gridCandidate() const;
  void beginMeasuring(std::vector<int> queue, bool recheck);
  void cancelRecheck();
  double cost(size_t i) const;
  void record(double seconds);
  bool startRecheck(const ViewKey& view);
  void queueSecondPass();
  void decide(const ViewKey& view, double occupied);
  void describeChoice();

  BuildParams base_;
  BackendKind kind_ = BackendKind::CPU;
  std::vector<BuildParams> candidates_;
  std::vector<double> seconds_;       ///< measured frame time per candidate (minimum), < 0: not yet
  std::vector<double> buildSeconds_;  ///< last build time per candidate, < 0: not yet
  std::vector<int> frames_;           ///< frames measured per candidate in the current measuring
  std::vector<int> queue_;            ///< the candidates still to render in this measuring, in order
  bool standIn_ = false;              ///< this frame draws Grid while the kept one waits (refinement)
  bool tfEdit_ = false;               ///< this frame carries a transfer-function (or crop/clip) change
  bool refined_ = false;              ///< the kept structure was rebuilt after a stand-in frame
  int current_ = -1;                  ///< the candidate to draw with (built when it differs from built_)
  int built_ = -1;                    ///< the candidate the backend holds, -1: none (or stale)
  int kept_ = -1;                     ///< the kept structure (during a re-check: the one before it)
  int firstMeasured_ = -1;            ///< the candidate of the measuring's first frame (its warm-up)
  bool exploring_ = false;            ///< measuring (all candidates, or a re-check)
  bool rechecking_ = false;           ///< this measuring is a re-check of the kept one at a new view
  int pass_ = 0;                      ///< 1 or 2 while measuring all candidates
  double occupancy_ = -1;             ///< when the choice was made
  int width_ = 0, height_ = 0;
  ViewKey measuredAt_;                ///< the view of the last measuring
  ViewKey lastView_;                  ///< the previous frame's view
  ViewKey recheckAt_;                 ///< the view a re-check started at
  int rechecks_ = 0;                  ///< re-checks at a new view since the measuring
  int switches_ = 0;                  ///< changes of the kept structure by a re-check
  int fullWidth_ = 0, fullHeight_ = 0;  ///< the user's frame size (probes: width_ is the probe's)
  double timeScale_ = 1;              ///< probes: the user's frame pixels over a probe's
  bool calibrate_ = false;            ///< probes: timeScale_ awaits the kept structure's frame
  bool calibrated_ = false;           ///< timeScale_ comes from the kept structure's frame
  std::string choice_;
};

}  // namespace spaceskip

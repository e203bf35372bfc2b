// `spaceskip bench gen:nbody:N --time-series STEPS` (or gen:rm:N, the mixing layer widening over
// the steps): playback of a simulation's time steps (issue 38). Each step is a new volume of the same shape: the engine's time-step path (Engine::setVolume
// keeps Builder Auto's choice; the upload reuses the device allocation through pinned staging)
// uploads it, computes its brick ranges where it lands, classifies, rebuilds the kept structure
// and draws it at an orbiting camera; each step's frame is waited for. Beside it: the upload bound
// (bytes a step over the measured pinned host-to-device rate), the same playback with Naive (no
// structure to rebuild), and a fresh engine per step (everything redone, Auto measuring afresh).
#include "Commands.h"
#include "spaceskip/Builders.h"
#include "spaceskip/Generators.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <vector>

namespace spaceskip::cli {

namespace {

struct Playback {
  // ms per played step: all; setVolume + prefetchVolume (with prefetch: the wait for this step's
  // upload and its value ranges); update (without prefetch: upload, ranges, classification, build;
  // with it: classification, build); render (the frame, waited for).
  std::vector<double> step, set, update, frame;
  double seconds = 0;
  std::string builder;
  int builds = 0, measurings = 0;
  int prefetched = 0;  // prefetches started
};

/// Plays `played` steps cycling over `steps` in `e` (already showing steps[0]): per step
/// setVolume + update() (upload, value ranges, classification, build) then the frame at the
/// orbit's next angle, waited for.
Playback play(Engine& e, const std::vector<Volume>& steps, int played, const double* b6, int w, int h,
              bool prefetch = false) {
  Playback p;
  Image img;
  const double aspect = double(w) / h;
  const Counters c0 = e.counters();
  const auto t0 = Clock::now();
  for (int i = 1; i <= played; ++i) {
    const Camera cam = orbitCamera(b6, 360.0 * i / played, 15, 1, false, aspect);
    const auto a = Clock::now();
    e.setVolume(steps[size_t(i) % steps.size()]);
    // The next step's upload on the copy stream while this one is classified, built and drawn
    // (Engine::prefetchVolume uploads this one first, or swaps it in when it was prefetched).
    if (prefetch) p.prefetched += e.prefetchVolume(steps[size_t(i + 1) % steps.size()]) ? 1 : 0;
    const auto s = Clock::now();
    e.update();
    const auto b = Clock::now();
    e.render(cam, w, h, img);
    (void)e.frameStats(true);
    const auto c = Clock::now();
    p.set.push_back(1e3 * std::chrono::duration<double>(s - a).count());
    p.update.push_back(1e3 * std::chrono::duration<double>(b - s).count());
    p.frame.push_back(1e3 * std::chrono::duration<double>(c - b).count());
    p.step.push_back(1e3 * std::chrono::duration<double>(c - a).count());
  }
  p.seconds = since(t0);
  p.builder = builderName(e.buildStats().builder);
  p.builds = e.counters().builds - c0.builds;
  p.measurings = e.counters().autoProbeMeasurings - c0.autoProbeMeasurings;
  return p;
}

void printPlayback(const char* what, const Playback& p, int played, double boundMs) {
  std::printf("%s: %d steps in %.3f s: %.2f steps/s; a step median %.3f ms, max %.3f ms (medians: set + prefetch "
              "%.3f ms, update %.3f ms, frame %.3f ms); %.2fx the upload bound; drew with %s, %d builds%s\n",
              what, played, p.seconds, played / p.seconds, median(p.step), maxOf(p.step), median(p.set),
              median(p.update), median(p.frame), boundMs > 0 ? median(p.step) / boundMs : 0.0, p.builder.c_str(), p.builds,
              p.measurings ? (", " + std::to_string(p.measurings) + " Auto measurings").c_str() : "");
}

}  // namespace

int cmdBenchTimeSeries(const Options& o) {
  if (o.positional.size() != 1) throw std::invalid_argument("bench --time-series needs one VOLUME: gen:nbody:N or gen:rm:N");
  const int played = int(o.getInt("--time-series", 100, 1, 1000000));
  const int held = int(o.getInt("--steps-held", std::min(played, 10), 1, 100000));
  const std::string typeName = o.get("--step-type", "uint8");
  VoxelType type;
  if (typeName == "uint8") type = VoxelType::UInt8;
  else if (typeName == "float32") type = VoxelType::Float32;
  else throw std::invalid_argument("--step-type '" + typeName + "' is not uint8 or float32");
  std::string shape;
  vec3l dims;
  const uint64_t cap = maxVolumeBytes(o);
  if (!parseGeneratorSpec(o.positional[0], cap, shape, dims))
    throw std::invalid_argument("bench --time-series: " + o.positional[0] + " is not gen:nbody:N or gen:rm:N");
  int w = 1024, h = 1024;
  imageSize(o, w, h);

  // --step-memory pinned: the steps in the engine's step memory (page-locked on CUDA), as a
  // reader that reads each step into Engine::allocateStepMemory hands them over; pageable
  // (default): plain host memory, as most readers' arrays.
  const std::string memoryName = o.get("--step-memory", "pageable");
  if (memoryName != "pageable" && memoryName != "pinned")
    throw std::invalid_argument("--step-memory '" + memoryName + "' is not pageable or pinned");
  Engine engine(backendKind(o));

  // The steps, held in host memory (the data of every step differs from the one before; a
  // playback longer than --steps-held cycles over them).
  const auto tg = Clock::now();
  std::vector<Volume> steps;
  std::vector<std::shared_ptr<unsigned char>> stepMemory;
  const uint64_t stepBytes = checkedByteSize(dims, type, cap, "a time step");
  for (int k = 0; k < held; ++k) {
    steps.push_back(allocating("time step " + std::to_string(k), stepBytes,
                               [&] { return generateTimeStep(shape, dims, k, type); }));
    if (memoryName == "pinned") {
      stepMemory.push_back(allocating("step memory " + std::to_string(k), stepBytes,
                                      [&] { return engine.allocateStepMemory(size_t(stepBytes)); }));
      Volume& v = steps.back();
      std::memcpy(stepMemory.back().get(), v.data, size_t(stepBytes));
      v.data = stepMemory.back().get();
      v.storage.reset();
    }
  }
  std::printf("time series %s %s: %s, %.1f MiB a step, %d steps held in %s memory (generated in %.2f s), %d played\n",
              o.positional[0].c_str(), typeName.c_str(), dimsText(dims).c_str(), stepBytes / 1048576.0, held,
              memoryName == "pinned" ? "the engine's step (page-locked)" : "pageable", since(tg), played);
  double b6[6];
  steps[0].worldBounds(b6);
  const TransferFunction tf = makeTF(o, steps[0]);
  const BuildParams bp = buildParams(o, o.get("--builder", "auto"));

  auto makeEngine = [&](Engine& e, const BuildParams& p) {
    e.setLogger([](const std::string& m) { std::fprintf(stderr, "  note: %s\n", m.c_str()); });
    e.setTuning(tuning(o));
    e.setMemoryBudget(memoryBudget(o), poolBrick(o));
    e.setVolume(steps[0]);
    e.setTransferFunction(tf);
    e.setBuildParams(p);
    e.setRenderParams(renderParams(o));
  };
  makeEngine(engine, bp);
  const UploadRates rates = engine.measureUpload(size_t(stepBytes));
  const double boundMs = rates.pinned > 0 ? 1e3 * double(stepBytes) / rates.pinned : 0;
  if (rates.pinned > 0)
    std::printf("host to device (%s): pinned %.2f GB/s, pageable %.2f GB/s, the engine's staged upload %.2f GB/s; "
                "upload bound %.3f ms a step (bytes / pinned rate)\n",
                engine.backendName(), rates.pinned / 1e9, rates.pageable / 1e9, rates.staged / 1e9, boundMs);
  else
    std::printf("backend %s: no host-to-device copy (the steps are read in place)\n", engine.backendName());

  // The first step, as a user's first frame, then Auto's measuring (untimed); the window path
  // leaves the image on the device.
  Image img;
  const double aspect = double(w) / h;
  const auto tf0 = Clock::now();
  allocating(frameText(w, h), frameBytes(w, h),
             [&] { engine.render(orbitCamera(b6, 0, 15, 1, false, aspect), w, h, img); });
  const double first = since(tf0);
  for (int i = 0; i < 40 && engine.exploring(); ++i) engine.render(orbitCamera(b6, 0, 15, 1, false, aspect), w, h, img);
  const bool onDevice = engine.setImageOnDevice(true);
  std::printf("first frame %.3f s; %s; image %s\n", first, engine.buildStats().choice.c_str(),
              onDevice ? "left on the device (as the window path)" : "on the host");
  // The time-step path with the next step prefetched while each is drawn, then without (each
  // step uploaded by its setVolume), in this process, on this engine.
  const int prefetchedBefore = engine.counters().prefetchedSteps;
  const Playback ours = play(engine, steps, played, b6, w, h, true);
  const Counters& c = engine.counters();
  printPlayback("playback (time-step path, next step prefetched)", ours, played, boundMs);
  std::printf("counters: time steps %d, prefetched %d (started %d), value-range passes %d, classifications %d, builds %d, "
              "Auto measurings on probes %d\n",
              c.timeSteps, c.prefetchedSteps - prefetchedBefore, ours.prefetched, c.rangeGrids, c.classifications, c.builds,
              c.autoProbeMeasurings);
  const Playback unfetched = play(engine, steps, played, b6, w, h, false);
  printPlayback("playback (time-step path, no prefetch)", unfetched, played, boundMs);
  std::printf("prefetch: %.2fx the steps/s of uploading each step at its setVolume\n", unfetched.seconds / ours.seconds);

  // Naive: no structure, the same upload and frame otherwise.
  {
    BuildParams nb = bp;
    nb.builder = BuilderKind::Naive;
    Engine naive(backendKind(o));
    makeEngine(naive, nb);
    naive.render(orbitCamera(b6, 0, 15, 1, false, aspect), w, h, img);
    naive.setImageOnDevice(true);
    const Playback pn = play(naive, steps, played, b6, w, h);
    printPlayback("playback (Naive)", pn, played, boundMs);
    std::printf("time-step path vs Naive: %.2fx the steps/s\n", pn.seconds / ours.seconds);
  }
  // A fresh engine per step: what a pipeline that forgets everything pays (allocation, Auto's
  // measuring, the first frame), over the held steps once.
  {
    std::vector<double> fresh;
    for (int k = 0; k < held; ++k) {
      const auto a = Clock::now();
      Engine e(backendKind(o));
      makeEngine(e, bp);
      e.setVolume(steps[size_t(k)]);
      e.setImageOnDevice(true);
      e.render(orbitCamera(b6, 360.0 * k / held, 15, 1, false, aspect), w, h, img);
      for (int i = 0; i < 40 && e.exploring(); ++i)
        e.render(orbitCamera(b6, 360.0 * k / held, 15, 1, false, aspect), w, h, img);
      (void)e.frameStats(true);
      fresh.push_back(1e3 * since(a));
    }
    std::printf("a fresh engine per step (%d steps): median %.3f ms, max %.3f ms: the time-step path is %.2fx faster\n",
                held, median(fresh), maxOf(fresh), median(fresh) / median(ours.step));
  }
  // Every played frame of the held steps against a static render of that step by a new engine.
  if (o.has("--check")) {
    if (onDevice) engine.setImageOnDevice(false);
    float worst = 0;
    Image ref;
    for (int k = 0; k < held; ++k) {
      const Camera cam = orbitCamera(b6, 37.0 * k, 15, 1, false, aspect);
      engine.setVolume(steps[size_t(k)]);  // prefetched below on the CUDA backend (k > 0)
      engine.update();
      engine.prefetchVolume(steps[size_t(k + 1) % steps.size()]);
      engine.render(cam, w, h, img);
      Engine e(backendKind(o));
      makeEngine(e, bp);
      e.setVolume(steps[size_t(k)]);
      e.render(cam, w, h, ref);
      for (size_t i = 0; i < img.rgba.size(); ++i)
        worst = std::max({worst, std::fabs(img.rgba[i].x - ref.rgba[i].x), std::fabs(img.rgba[i].y - ref.rgba[i].y),
                          std::fabs(img.rgba[i].z - ref.rgba[i].z), std::fabs(img.rgba[i].w - ref.rgba[i].w)});
    }
    std::printf("check: %d steps played (each prefetched while the one before was drawn) vs each step's static "
                "render: max difference %.3f/255\n", held, 255 * worst);
    if (255 * worst > 1.0) return 3;
  }
  return 0;
}

}  // namespace spaceskip::cli

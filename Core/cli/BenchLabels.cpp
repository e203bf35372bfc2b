// `spaceskip bench VOLUME --label-map blend|nearest`: the label-map benchmark (issue 37): the
// first frame, frame rates with every label and with a tenth of them visible (against Naive),
// and the latency of toggling one label's visibility, with the counters that show the toggles
// read no voxel.
#include "Commands.h"
#include "spaceskip/Builders.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <vector>

namespace spaceskip::cli {

namespace {

struct Rate {
  double fps = 0, kernelFps = 0, occupancy = 0;
  std::string builder;
};

/// The bench's protocol (measureItem): a warm-up frame (and Auto's measuring frames, untimed),
/// then `frames` frames of the orthographic camera rotating about the volume, timed by the
/// engine's frame statistics (the image downloaded: the frame waited for).
Rate orbitRate(Engine& e, const double* b6, int w, int h, int frames) {
  Image img;
  const double aspect = double(w) / h;
  e.render(orbitCamera(b6, 0, 0, 1, false, aspect), w, h, img);
  for (int i = 0; i < 40 && e.exploring(); ++i) e.render(orbitCamera(b6, 0, 0, 1, false, aspect), w, h, img);
  double total = 0, device = 0;
  for (int f = 0; f < frames; ++f) {
    e.render(orbitCamera(b6, 360.0 * f / frames, 15, 1, false, aspect), w, h, img);
    total += e.frameStats().seconds;
    device += e.frameStats().deviceSeconds;
  }
  Rate r;
  r.fps = frames / total;
  r.kernelFps = device > 0 ? frames / device : r.fps;
  r.occupancy = e.occupancy().occupancy();
  r.builder = builderName(e.buildStats().builder);
  return r;
}

}  // namespace

int cmdBenchLabels(const Options& o) {
  if (o.positional.size() != 1) throw std::invalid_argument("bench --label-map needs one VOLUME (e.g. gen:labels:512)");
  if (o.has("--builders")) throw std::invalid_argument("bench --label-map takes --builder B, not --builders");
  const int frames = int(o.getInt("--frames", 8, 1, 1000000));
  const int toggles = int(o.getInt("--toggles", 20, 1, 100000));
  const int every = int(o.getInt("--visible-every", 10, 1, 65535));
  int w = 1024, h = 1024;
  imageSize(o, w, h);
  const std::string spec = o.positional[0];
  auto tg = Clock::now();
  Volume v = openVolume(spec, o);
  std::printf("volume %s: %s %s, ready in %.2f s\n", spec.c_str(), dimsText(v.dims).c_str(), voxelTypeName(v.type),
              since(tg));
  const LabelTable all = labelTable(o, v);
  if (all.labels.empty())
    throw std::invalid_argument("bench --label-map: " + spec + " is not a label map (one component of 8- or 16-bit integers)");
  LabelTable tenth = all;
  std::vector<size_t> shown;  // indices into tenth.labels of its visible labels
  for (size_t i = 0; i < tenth.labels.size(); ++i) {
    Label& l = tenth.labels[i];
    l.visible = l.visible && l.id % every == 0;
    if (l.visible) shown.push_back(i);
  }
  if (shown.empty()) throw std::invalid_argument("bench --label-map: --visible-every leaves no label visible");
  const BuildParams bp = buildParams(o, o.get("--builder", "auto"));
  BuildParams naive = bp;
  naive.builder = BuilderKind::Naive;
  double b6[6];
  v.worldBounds(b6);
  const Camera still = makeCamera(o, v, w, h);

  Engine engine(backendKind(o));
  engine.setLogger([](const std::string& m) { std::fprintf(stderr, "  note: %s\n", m.c_str()); });
  engine.setTuning(tuning(o));
  engine.setMemoryBudget(memoryBudget(o), poolBrick(o));
  Image img;
  // (1) The first frame: upload, value ranges, label sets, classification, build, frame.
  const auto t0 = Clock::now();
  engine.setVolume(v);
  engine.setTransferFunction(makeTF(o, v));
  engine.setBuildParams(bp);
  engine.setRenderParams(renderParams(o));
  engine.setLabelTable(all);
  allocating(frameText(w, h), frameBytes(w, h), [&] { engine.render(still, w, h, img); });
  const double first = since(t0);
  if (!engine.labelMapActive()) throw std::runtime_error("bench --label-map: the engine did not draw a label map");
  {
    const BuildStats& s = engine.buildStats();
    const Counters& c = engine.counters();
    std::printf("backend %s, builder %s -> %s, %zu labels, %dx%d, %s sampling\n", engine.backendName(),
                builderName(bp.builder), builderName(s.builder), all.labels.size(), w, h,
                engine.renderParams().labelSampling == LabelSampling::Nearest ? "nearest" : "blend");
    std::printf("first frame: %.3f s (classify %.3f s, build %.3f s, frame %.3f s; label sets %d, voxel passes %d)\n",
                first, s.classifySeconds, s.seconds, engine.frameStats().seconds, c.labelSets, c.voxelPasses);
  }
  // (2) Every label visible; (3) a tenth, the builder against Naive.
  const Rate rAll = orbitRate(engine, b6, w, h, frames);
  if (!engine.buildStats().choice.empty()) std::printf("%s\n", engine.buildStats().choice.c_str());
  std::printf("all %zu labels visible: %s %.2f fps (kernel %.2f), occupied bricks %.2f%%\n", all.labels.size(),
              rAll.builder.c_str(), rAll.fps, rAll.kernelFps, 100 * rAll.occupancy);
  engine.setLabelTable(tenth);
  engine.setBuildParams(naive);
  const Rate rNaive = orbitRate(engine, b6, w, h, frames);
  engine.setBuildParams(bp);
  const Rate rTenth = orbitRate(engine, b6, w, h, frames);
  std::printf("%zu labels visible (ids %% %d == 0): %s %.2f fps (kernel %.2f), Naive %.2f fps (kernel %.2f): "
              "%.2fx (kernel %.2fx), occupied bricks %.2f%%\n",
              shown.size(), every, rTenth.builder.c_str(), rTenth.fps, rTenth.kernelFps, rNaive.fps, rNaive.kernelFps,
              rTenth.fps / rNaive.fps, rTenth.kernelFps / rNaive.kernelFps, 100 * rTenth.occupancy);

  // (4) Toggles at a still view, a tenth visible: hide one visible label, then show it again,
  // each edit timed from setLabelTable() to its frame finished (the image left on the device, as
  // the mapper's window path does; the CPU backend's frame is the host's), against plain frames.
  const bool onDevice = engine.setImageOnDevice(true);
  for (int i = 0; i < 3 || (i < 40 && engine.exploring()); ++i) engine.render(still, w, h, img);
  (void)engine.frameStats(true);
  std::vector<double> plain, plainFrame;
  const Counters c0 = engine.counters();
  std::vector<double> edit[2], set[2], classify[2], next[2], build;
  int rebuilt[2] = {0, 0};
  LabelTable t = tenth;
  for (int i = 0; i < toggles; ++i) {
    Label& l = t.labels[shown[size_t(i) % shown.size()]];
    for (int k = 0; k < 2; ++k) {  // 0: hide, 1: show again
      const int builds = engine.counters().builds;
      const int classifications = engine.counters().classifications;
      l.visible = k == 1;
      const auto t1 = Clock::now();
      engine.setLabelTable(t);
      set[k].push_back(1e3 * since(t1));
      engine.render(still, w, h, img);
      (void)engine.frameStats(true);
      edit[k].push_back(1e3 * since(t1));
      if (engine.counters().classifications > classifications)
        classify[k].push_back(1e3 * engine.buildStats().classifySeconds);
      rebuilt[k] += engine.counters().builds - builds;
      if (engine.counters().builds > builds) build.push_back(1e3 * engine.buildStats().seconds);
      const auto t2 = Clock::now();  // the frame after the edit (work left to it: Auto's rebuild)
      engine.render(still, w, h, img);
      (void)engine.frameStats(true);
      next[k].push_back(1e3 * since(t2));
    }
    // A plain frame (no edit, nothing left to do), interleaved with the toggles so that both
    // see the same machine load.
    const auto t3 = Clock::now();
    engine.render(still, w, h, img);
    plainFrame.push_back(1e3 * engine.frameStats(true).seconds);
    plain.push_back(1e3 * since(t3));
  }
  const Counters c1 = engine.counters();
  if (onDevice) engine.setImageOnDevice(false);
  std::vector<double> both = edit[0];
  both.insert(both.end(), edit[1].begin(), edit[1].end());
  std::printf("toggle (setLabelTable + its frame), %d hides and %d shows of %zu labels: median %.3f ms, max %.3f ms "
              "(hide median %.3f, max %.3f; show median %.3f, max %.3f)\n",
              toggles, toggles, std::min(shown.size(), size_t(toggles)), median(both), maxOf(both), median(edit[0]),
              maxOf(edit[0]), median(edit[1]), maxOf(edit[1]));
  std::printf("plain frame (no edit, same view, one per toggle pair): median %.3f ms, max %.3f ms (engine frame %.3f ms)\n", median(plain),
              maxOf(plain), median(plainFrame));
  std::printf("edit cost = toggle - plain: %.3f ms (median); setLabelTable alone %.3f ms; classification %.3f ms "
              "(median of %zu); rebuilds: %d on hides, %d on shows, median %.3f ms; frame after an edit: median %.3f ms\n",
              median(both) - median(plain), median([&] {
                std::vector<double> s = set[0];
                s.insert(s.end(), set[1].begin(), set[1].end());
                return s;
              }()),
              median([&] {
                std::vector<double> s = classify[0];
                s.insert(s.end(), classify[1].begin(), classify[1].end());
                return s;
              }()),
              classify[0].size() + classify[1].size(), rebuilt[0], rebuilt[1], median(build), median([&] {
                std::vector<double> s = next[0];
                s.insert(s.end(), next[1].begin(), next[1].end());
                return s;
              }()));
  // (5) What the toggles ran: no pass over the voxels, one classification over the label sets each.
  std::printf("counters over the %d toggles (and their %d frames after and %d plain frames): voxel passes +%d, label sets +%d, value ranges +%d, classifications +%d, "
              "builds +%d, colour updates +%d, frames +%d, Auto stale frames +%d, Auto measurings +%d\n",
              2 * toggles, 2 * toggles, toggles, c1.voxelPasses - c0.voxelPasses, c1.labelSets - c0.labelSets, c1.rangeGrids - c0.rangeGrids,
              c1.classifications - c0.classifications, c1.builds - c0.builds, c1.colorUpdates - c0.colorUpdates,
              c1.frames - c0.frames, c1.staleFrames - c0.staleFrames, c1.autoProbeMeasurings - c0.autoProbeMeasurings);
  return c1.voxelPasses == c0.voxelPasses ? 0 : 4;
}

}  // namespace spaceskip::cli

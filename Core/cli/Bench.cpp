// `spaceskip bench`: builders measured on volumes (build, frame rates, samples, edits).
#include "Commands.h"
#include "spaceskip/Backend.h"
#include "spaceskip/Builders.h"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace spaceskip::cli {

namespace {

/// --edits N: opacity edits at a still view, each timed from setTransferFunction() to its
/// frame finished on the device (the image left in device memory, as the mapper's interop path
/// does; on the CPU backend the frame is the host's), with one untimed frame after each. The
/// edits alternate between zeroing the opacity below `cut` of the table (bricks empty) and the
/// TF as it was (bricks occupied again); with a 2-D transfer function (--tf2d) the same share of
/// its columns as well.
void measureEdits(Engine& engine, const TransferFunction& tf, const Camera& cam, int w, int h, int edits, double cut,
                  BenchRow& row) {
  TransferFunction cutTF = tf;
  const double share = std::clamp(cut, 0.0, 1.0);
  const size_t below = size_t(share * double(cutTF.table.size()));
  for (size_t i = 0; i < below && i < cutTF.table.size(); ++i) cutTF.table[i].w = 0.f;
  if (cutTF.uses2D()) {  // a 2-D table: the same share of its columns, at every gradient magnitude
    const size_t cols = size_t(share * double(cutTF.width2D));
    for (int r = 0; r < cutTF.height2D; ++r)
      for (size_t c = 0; c < cols; ++c) cutTF.table2D[size_t(r) * size_t(cutTF.width2D) + c].w = 0.f;
  }
  const bool onDevice = engine.setImageOnDevice(true);
  Image img;
  engine.render(cam, w, h, img);
  (void)engine.frameStats(true);
  for (int e = 0; e < edits; ++e) {
    const int kind = e % 2;  // 0: to the cut TF (empties bricks), 1: back (occupies them)
    const int builds = engine.counters().builds;
    const auto t0 = Clock::now();
    engine.setTransferFunction(kind == 0 ? cutTF : tf);
    engine.render(cam, w, h, img);
    const FrameStats& fs = engine.frameStats(true);
    const double ms = 1e3 * since(t0);
    BenchRow::Edit& k = row.edits[kind];
    const BuildStats& s = engine.buildStats();
    ++k.count;
    k.ms += ms;
    k.classifyMs += 1e3 * s.classifySeconds;
    k.waitMs += 1e3 * s.classifyWaitSeconds;
    const int built = engine.counters().builds - builds;
    k.builds += built;
    if (built) k.buildMs += 1e3 * s.seconds;
    k.frameMs += 1e3 * fs.seconds;
    k.kernelMs += fs.deviceSeconds > 0 ? 1e3 * fs.deviceSeconds : 0;
    const auto t1 = Clock::now();
    engine.render(cam, w, h, img);  // the frame after the edit (masks, refinement)
    const FrameStats& next = engine.frameStats(true);
    k.nextMs += 1e3 * since(t1);
    k.nextKernelMs += next.deviceSeconds > 0 ? 1e3 * next.deviceSeconds : 0;
  }
  if (onDevice) engine.setImageOnDevice(false);
  for (BenchRow::Edit& k : row.edits)
    if (k.count) {
      const double n = k.count;
      k.ms /= n, k.classifyMs /= n, k.waitMs /= n, k.buildMs /= n, k.frameMs /= n, k.kernelMs /= n, k.builds /= n;
      k.nextMs /= n, k.nextKernelMs /= n;
    }
  auto text = [](const BenchRow::Edit& k) {
    char b[320];
    std::snprintf(b, sizeof b,
                  "%.3f ms (classify %.3f, of it waiting %.3f; build %.3f x%.2f; frame %.3f, kernel %.3f; next frame "
                  "%.3f, kernel %.3f)",
                  k.ms, k.classifyMs, k.waitMs, k.buildMs, k.builds, k.frameMs, k.kernelMs, k.nextMs, k.nextKernelMs);
    return std::string(b);
  };
  std::printf("  edits: %s: occupying %s; emptying %s; device memory in use %.1f MiB\n", row.label.c_str(),
              text(row.edits[1]).c_str(), text(row.edits[0]).c_str(), double(cudaDeviceBytesInUse()) / 1048576.0);
}

const char* leafName(LeafCriterion l) {
  return l == LeafCriterion::Shallow ? "shallow" : l == LeafCriterion::Empty ? "empty" : "deep";
}

/// An item's knobs: the bench's (`base`: the environment and the options), with the suffixes
/// :resN (BenchItem::resident) and :whole / :partsN (BenchItem::parts) over them. When the
/// sub-brick mask knobs differ from the engine's, the engine classifies again (an opacity edit
/// and back), so items with and without masks are measured side by side in one process.
void applyItemTuning(Engine& engine, const Volume& v, const Options& o, const BenchItem& item, const Tuning& base) {
  Tuning t = base;
  if (item.resident >= 0) t.resident = item.resident;
  if (item.parts == -1) t.subMasks = false;
  if (item.parts >= 0) {
    t.subMasks = true;
    t.cpuSubMasks = true;
    t.subMaskMaxSet = item.parts;
  }
  const Tuning& was = engine.tuning();
  const bool reclassify =
      t.subMasks != was.subMasks || t.cpuSubMasks != was.cpuSubMasks || t.subMaskMaxSet != was.subMaskMaxSet;
  engine.setTuning(t);
  if (!reclassify) return;
  TransferFunction tf = makeTF(o, v), edited = tf;
  for (vec4f& e : edited.table) e.w = e.w > 0.f ? 0.f : 1.f;  // every brick's state differs
  engine.setTransferFunction(edited);
  engine.update();
  engine.setTransferFunction(tf);
}

}  // namespace

BenchRow measureItem(Engine& engine, const Volume& v, const std::string& itemText, const Options& o, int w, int h,
                     int frames, int buildReps, const Tuning& tuning) {
  BenchRow row;
  const BenchItem item = benchItem(itemText);
  const BuildParams bp = buildParams(o, item.spec);
  applyItemTuning(engine, v, o, item, tuning);
  row.bp = bp;
  RenderParams rp = renderParams(o);
  if (item.filter >= 0) rp.filter = FilterMode(item.filter);
  engine.setRenderParams(rp);
  engine.setBuildParams(bp);
  engine.update();
  row.cold = engine.buildStats().seconds;
  // Rebuild, timed alone (the first build includes one-time allocations); with
  // --build-reps N the fastest of N rebuilds. A Naive build in between (which costs nothing)
  // forces each rebuild.
  BuildStats s = engine.buildStats();
  for (int rep = 0; rep < buildReps && !item.cold; ++rep) {
    BuildParams none = bp;
    none.builder = BuilderKind::Naive;
    engine.setBuildParams(none);
    engine.update();
    engine.setBuildParams(bp);
    engine.update();
    if (rep == 0 || engine.buildStats().seconds < s.seconds) s = engine.buildStats();
  }
  double b6[6];
  v.worldBounds(b6);
  Image img;
  engine.render(orbitCamera(b6, 0, 0, 1, false, double(w) / h), w, h, img);  // warm-up
  // Auto: its measuring frames (one to four per candidate) are not timed; then what it chose is.
  for (int i = 0; i < 40 && engine.exploring(); ++i)
    engine.render(orbitCamera(b6, 0, 0, 1, false, double(w) / h), w, h, img);
  if (bp.builder == BuilderKind::Auto) {
    engine.update();  // builds the kept structure when it was not the last one measured
    s = engine.buildStats();
    std::printf("%s\n", s.choice.c_str());
  }
  double total = 0, totalDevice = 0, cpuTotal = 0;
  for (int f = 0; f < frames; ++f) {
    const double c0 = processCpuSeconds();
    engine.render(orbitCamera(b6, 360.0 * f / frames, 15, 1, false, double(w) / h), w, h, img);
    cpuTotal += processCpuSeconds() - c0;
    total += engine.frameStats().seconds;
    totalDevice += engine.frameStats().deviceSeconds;
  }
  row.fps = frames / total;
  // CUDA: frame rate of the render kernel alone (CUDA events), without the host copy.
  row.kernelFps = totalDevice > 0 ? frames / totalDevice : row.fps;
  row.frameCpu = cpuTotal / frames;
  // One more frame with sample counting (not timed): samples/frame and samples/s.
  RenderParams counted = rp;
  counted.countSamples = true;
  engine.setRenderParams(counted);
  engine.render(orbitCamera(b6, 0, 15, 1, false, double(w) / h), w, h, img);
  row.samples = double(engine.frameStats().samples);
  row.gsps = row.samples * row.kernelFps * 1e-9;
  // Logical voxel traffic of trilinear sampling: 8 voxels per sample (mostly cache hits).
  row.voxelGBs = row.gsps * 8.0 * double(voxelSize(v.type));
  // The variant as asked for; when the engine fell back (e.g. a GPU builder on the CPU), say so.
  row.label = itemText;
  if (s.builder != bp.builder) row.label += std::string("->") + builderName(s.builder);
  row.filter = rp.filter == FilterMode::Hardware ? "hardware" : "exact";
  // Hybrid always builds the shallow tree (paper 3.3).
  row.leaf = s.builder == BuilderKind::Hybrid ? "shallow" : leafName(bp.leaf);
  row.s = s;
  // The share of set sub-brick parts as the frames saw it (without part ranges the CUDA backend
  // computes the masks on the frame after a classification, so the build's statistics may
  // predate them).
  row.s.partsShare = engine.buildStats().partsShare;
  const int edits = int(o.getInt("--edits", 0, 0, 100000));
  if (edits > 0) {
    engine.setRenderParams(rp);
    measureEdits(engine, makeTF(o, v), orbitCamera(b6, 0, 15, 1, false, double(w) / h), w, h, edits,
                 o.getDouble("--edit-cut", 0.3, 0.0, 1.0), row);
  }
  return row;
}


int cmdBench(const Options& o) {
  if (o.has("--paper")) return cmdBenchPaper(o);
  if (o.has("--label-map")) return cmdBenchLabels(o);
  if (o.has("--time-series")) return cmdBenchTimeSeries(o);
  if (o.positional.empty()) throw std::invalid_argument("bench needs at least one VOLUME (or --paper)");
  std::vector<std::string> builders = split(o.get("--builders", "naive,grid"), ',');
  const int frames = int(o.getInt("--frames", 8, 1, 1000000));
  const int buildReps = int(o.getInt("--build-reps", 1, 1, 1000000));
  const Tuning knobs = tuning(o);
  int w = 1024, h = 1024;
  imageSize(o, w, h);
  std::ostringstream json;
  json << "[\n";
  // Both files opened before any work (a path that cannot be written fails at once), written to
  // temporary files and renamed into place at the end.
  const std::unique_ptr<OutputFile> jsonFile = outputOption(o, "--json");
  const std::unique_ptr<OutputFile> csvFile = outputOption(o, "--csv");
  if (csvFile) {
    csvFile->stream() << "dataset,dims,variant,builder,backend,leaf,mls,bins,brick,build_s,classify_s,fps,nodes,height,leaves,occupancy,"
           "filter,kernel_fps,build_cold_s,built_on,samples_per_frame,gsamples_per_s_kernel,voxel_gbytes_per_s_kernel,frame_cpu_s\n";
  }
  bool firstJson = true;
  std::printf("%-16s %-30s %-6s %10s %11s %8s %9s %9s %9s %6s %9s %8s %8s\n", "dataset", "builder", "backend", "build_ms",
              "classify_ms", "fps", "kern_fps", "cpu_ms/f", "nodes", "height", "leaves", "vs_naive", "Gsmp/s");
  for (const std::string& spec : o.positional) {
    auto tg = Clock::now();
    Volume v = openVolume(spec, o);
    std::fprintf(stderr, "  note: %s ready in %.2f s\n", spec.c_str(), since(tg));
    TransferFunction tf = makeTF(o, v);
    double naiveFps = 0;
    // One engine per data set: the volume is uploaded (CUDA) and its ranges computed once.
    Engine engine(backendKind(o));
    engine.setLogger([](const std::string& m) { std::fprintf(stderr, "  note: %s\n", m.c_str()); });
    engine.setTuning(knobs);
    engine.setMemoryBudget(memoryBudget(o), poolBrick(o));
    engine.setVolume(v);
    engine.setTransferFunction(tf);
    for (const std::string& b : builders) {
      const BenchRow r = allocating(frameText(w, h), frameBytes(w, h),
                                    [&] { return measureItem(engine, v, b, o, w, h, frames, buildReps, knobs); });
      const BuildStats& s = r.s;
      const BuildParams& bp = r.bp;
      if (s.builder == BuilderKind::Naive && naiveFps == 0) naiveFps = r.kernelFps;
      const std::string dims = dimsText(v.dims);
      std::string name = spec.substr(spec.find_last_of('/') + 1);
      std::printf("%-16s %-30s %-6s %10.3f %11.3f %8.2f %9.2f %9.1f %9lld %6d %9lld %8s %8.3f\n", name.c_str(), r.label.c_str(),
                  engine.backendName(), s.seconds * 1e3, s.classifySeconds * 1e3, r.fps, r.kernelFps, r.frameCpu * 1e3,
                  (long long)s.nodes, s.height, (long long)s.leaves,
                  naiveFps > 0 ? (std::to_string(r.kernelFps / naiveFps).substr(0, 5) + "x").c_str() : "-", r.gsps);
      std::fflush(stdout);
      if (!firstJson) json << ",\n";
      firstJson = false;
      json << "  {\"dataset\": \"" << name << "\", \"dims\": \"" << dims << "\", \"variant\": \"" << r.label
           << "\", \"builder\": \"" << builderName(s.builder) << "\", \"backend\": \"" << engine.backendName()
           << "\", \"built_on\": \"" << s.builtOn << "\", \"leaf\": \"" << r.leaf << "\", \"mls\": " << bp.maxLeafSize
           << ", \"bins\": " << bp.bins << ", \"brick\": " << bp.brick << ", \"filter\": \"" << r.filter
           << "\", \"build_s\": " << s.seconds << ", \"build_cold_s\": " << r.cold << ", \"classify_s\": " << s.classifySeconds
           << ", \"fps\": " << r.fps << ", \"kernel_fps\": " << r.kernelFps << ", \"frame_cpu_s\": " << r.frameCpu
           << ", \"nodes\": " << s.nodes << ", \"height\": " << s.height << ", \"leaves\": " << s.leaves
           << ", \"samples_per_frame\": " << r.samples << ", \"gsamples_per_s\": " << r.gsps
           << ", \"voxel_gbytes_per_s\": " << r.voxelGBs << ", \"occupancy\": " << s.occupancy << ", \"width\": " << w
           << ", \"height_px\": " << h << ", \"frames\": " << frames << "}";
      if (csvFile)
        csvFile->stream() << name << "," << dims << "," << r.label << "," << builderName(s.builder) << "," << engine.backendName() << ","
            << r.leaf << "," << bp.maxLeafSize << "," << bp.bins << "," << bp.brick << "," << s.seconds << ","
            << s.classifySeconds << "," << r.fps << "," << s.nodes << "," << s.height << "," << s.leaves << ","
            << s.occupancy << "," << r.filter << "," << r.kernelFps << "," << r.cold << "," << s.builtOn << "," << r.samples
            << "," << r.gsps << "," << r.voxelGBs << "," << r.frameCpu << "\n";
    }
  }
  json << "\n]\n";
  if (jsonFile) {
    jsonFile->stream() << json.str();
    jsonFile->commit();
  }
  if (csvFile) csvFile->commit();
  return 0;
}

}  // namespace spaceskip::cli

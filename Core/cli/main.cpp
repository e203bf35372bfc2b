// spaceskip: command-line renderer, generator and benchmark over Core (no VTK).
#include "Options.h"
#include "spaceskip/Backend.h"
#include "spaceskip/Builders.h"
#include "spaceskip/BrickPool.h"
#include "spaceskip/Engine.h"
#include "spaceskip/Generators.h"
#include "spaceskip/ImageIO.h"
#include "spaceskip/TransferFunctionIO.h"
#include "spaceskip/VolumeIO.h"

#include <tbb/global_control.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

using namespace spaceskip;
using namespace spaceskip::cli;

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// CPU seconds used by this process (all threads): a frame's work, robust against other load
/// on a shared machine (wall-clock fps is not).
double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

const char* kUsage = R"(usage:
  spaceskip generate SHAPE --dims X Y Z [--seed N] -o FILE(.nrrd|_XxYxZ_TYPE.raw)
      SHAPE: menger nbody shell noise rm vessels, and the paper's data sets: aneurism xmas_tree
      magnetic stag_beetle kingsnake richtmyer_meshkov
  spaceskip render VOLUME -o out.png [options]
  spaceskip accuracy VOLUME [--builder B] [--size WxH] [--csv FILE] [options]
      speed/accuracy trade: sample distance 0.25-4 voxels x filter x ERT x jitter vs PSNR/SSIM
      against a fine reference, and fps (scripts/plot_pareto.py draws the Pareto fronts)
  spaceskip bench VOLUME... [--builders b1,b2,...] [--frames N] [--json FILE] [--csv FILE] [options]
      each builder may carry suffixes overriding --leaf/--mls/--bins/--brick, e.g.
      --builders naive,grid,lbvh-cpu,kdtree-cpu:shallow,kdtree-cpu:deep:mls32,kdtree-cpu:deep:mls128,hybrid
      or kdtree-gpu-fast:deep:mls32:bins0 (the sweep: the kdtree-cpu:deep:mls32 tree)
      --build-reps N: report the fastest of N rebuilds (default 1)
      bench-only suffixes: :hw / :exact (filter for this item), :cold (time the first build only),
      :resN (CUDA: persistent launch with N blocks per SM; res0 = plain), :whole (no sub-brick
      masks: occupied bricks marched whole), :partsN (bricks with <= N of 64 parts set walked by parts)
      --edits N [--edit-cut C]: after an item's frames, N opacity edits at a still view, alternately
      zeroing the TF's opacity below C of the range (default 0.3: bricks empty) and restoring it
      (bricks occupied again), each timed to its first frame finished on the device (the image
      left there, as the mapper's window path does), with a frame after each; the line
      "edits:" gives each kind's mean: classification (of it the wait for the device), build, frame
  spaceskip bench --paper [--scale F] [--datasets a,b] [--builders k1,k2] [--frames N] [--time-limit S]
                  [--csv FILE] [--json FILE] [options]
      the paper's whole benchmark: stand-ins for its 11 data sets (dims x F), every builder and
      parameter set of its table (naive lbvh cpu_shallow cpu_mls32 cpu_mls128 gpu_shallow gpu_mls32
      gpu_mls128 hybrid) plus ours (grid distance_grid kdtree_gpu_fast kdtree_empty auto), 1024x1024,
      rotating orthographic camera, no ERT; progress on stderr; --time-limit S stops starting new
      items after S seconds (the rest are written as skipped). Figures: scripts/plot-paper-bench.py

  spaceskip sparse VOLUME --memory-budget N[K|M|G] [--pool-brick N] [--builders b1,b2] [--edit-tf PRESET]
                   [--no-in-core] [--frames N] [options]
      sparse residency: only the bricks a frame needs on the device, within the budget; per
      builder the in-core and the sparse run side by side (kernel fps, max difference of every
      frame), and the TF edit --tf -> --edit-tf (default ramp) timed to its first frame

  VOLUME: NAME_XxYxZ_TYPE.raw, FILE.nrrd, or gen:SHAPE:N / gen:SHAPE:XxYxZ (generated in memory)
options:
  --builder B        auto (default: a frame with each of naive, grid, distance-grid and a
                     k-d tree, one more for those within 1.5x of the fastest, then the fastest)
                     or one of the builders listed at the end
  --leaf shallow|deep|empty  --mls N  --bins N  --brick N
      empty: deep, but leaves are kept or split by their empty space, not their size (MLS ignored)
      --bins (kdtree-gpu, kdtree-gpu-fast; default 4): N >= 2 tries N-1 planes per node;
      0 sweeps every brick boundary, the kdtree-cpu tree (kdtree-cpu always sweeps)
  --backend auto|cpu|cuda     --threads N (oneTBB worker limit)
  --cuda-block WxH   CUDA launch shape: threads per block (32..256; default 16x8; also
                     SPACESKIP_CUDA_BLOCK; the other SPACESKIP_* knobs: docs/tuning.md)
  --tf PRESET|FILE   presets: ramp grayscale coolwarm band spike opaque zero
  --size WxH         (render default 512x512, bench default 1024x1024)
  --camera AZ,EL[,ZOOM]  orbit angles in degrees  --perspective
  --sample-distance D  (world units; default half the smallest spacing)
  --ert T  --jitter  --filter exact|hardware
  --blend composite|mip|minip|average|additive|iso   --iso V1,V2,...  (iso values)
  --shade on|AMBIENT,DIFFUSE,SPECULAR,POWER  gradient shading with a headlight (on: 0,0.7,0.2,10)
  --compare REF.png  print max difference and PSNR against a reference image
  --max-diff N       with --compare: exit 3 when the max difference exceeds N/255
  --memory-budget N[K|M|G|T]  the most memory the voxels may take on the device (default: free
                     device memory less what the rest needs); above it the volume stays sparse:
                     only the pool bricks a frame needs are resident (--pool-brick N cells, 16)
  --max-volume-bytes N[K|M|G|T]  largest volume read or generated (default: the environment's
                     SPACESKIP_MAX_VOLUME_BYTES, else min(64 GiB, physical memory))
builders:
)";

/// The usage text and the registry's builders (Builders.cpp), one per line.
void printUsage(FILE* to) {
  std::fputs(kUsage, to);
  int n = 0;
  const BuilderInfo* rows = builderRegistry(&n);
  for (int i = 0; i < n; ++i) std::fprintf(to, "  %-18s %s\n", rows[i].cliName, rows[i].summary);
}

Volume openVolume(const std::string& spec, const Options& o) {
  const uint64_t cap = maxVolumeBytes(o);
  std::string shape;
  vec3l dims;
  if (parseGeneratorSpec(spec, cap, shape, dims)) return generateVolume(shape, dims);
  ReadLimits limits;
  limits.maxBytes = cap;
  return loadVolume(spec, limits);
}

TransferFunction makeTF(const Options& o, const Volume& v) {
  double lo, hi;
  if (!v.scalarRange(lo, hi)) lo = 0, hi = 1;
  std::string t = o.get("--tf", "ramp");
  // A preset name unless a file of that name exists (loadTransferFunction refuses devices).
  std::error_code ec;
  if (std::filesystem::exists(t, ec)) return loadTransferFunction(t, lo, hi);
  return TransferFunction::preset(t, lo, hi);
}

Camera makeCamera(const Options& o, const Volume& v, int w, int h, double azDefault = 30, double elDefault = 20) {
  double az = azDefault, el = elDefault, zoom = 1;
  if (o.has("--camera")) {
    parseCamera(o.get("--camera", ""), az, el, zoom);
  }
  double b[6];
  v.worldBounds(b);
  return orbitCamera(b, az, el, zoom, o.has("--perspective"), double(w) / h);
}

int cmdGenerate(const Options& o) {
  if (o.positional.size() != 1 || !o.has("--dims") || !o.has("-o"))
    throw std::invalid_argument("generate needs SHAPE --dims X Y Z -o FILE");
  vec3l d = parseDims(o.get("--dims", ""), "--dims");
  checkGeneratorSize(o.positional[0], d, maxVolumeBytes(o));
  const unsigned seed = unsigned(o.getInt("--seed", 1, 0, 4294967295LL));
  auto t0 = Clock::now();
  Volume v = generateVolume(o.positional[0], d, seed);
  double gen = since(t0);
  std::string out = o.get("-o", "");
  if (out.size() > 5 && out.substr(out.size() - 5) == ".nrrd") saveNrrd(v, out);
  else {
    vec3l pd;
    VoxelType pt;
    if (!parseRawName(out, pd, pt) || pd.x != d.x || pd.y != d.y || pd.z != d.z || pt != v.type)
      throw std::invalid_argument(std::string("output must end in .nrrd or be named NAME_") + std::to_string(d.x) + "x" +
                                  std::to_string(d.y) + "x" + std::to_string(d.z) + "_" + voxelTypeName(v.type) + ".raw");
    saveRaw(v, out);
  }
  std::printf("generated %s %lldx%lldx%lld %s in %.3f s -> %s\n", o.positional[0].c_str(), (long long)d.x,
              (long long)d.y, (long long)d.z, voxelTypeName(v.type), gen, out.c_str());
  return 0;
}

void printResidency(const ResidencyStats& r) {
  if (!r.sparse) return;
  std::printf("residency sparse: pool bricks of %d cells, %lld needed, %lld resident of %lld (%lld slots, %.1f MiB "
              "pool, budget %.1f MiB)\n",
              r.poolBrick, (long long)r.needed, (long long)r.resident, (long long)r.bricks, (long long)r.capacity,
              double(r.poolBytes) / 1048576.0, double(r.budgetBytes) / 1048576.0);
}

int cmdRender(const Options& o) {
  if (o.positional.size() != 1 || !o.has("-o")) throw std::invalid_argument("render needs VOLUME -o out.png");
  auto t0 = Clock::now();
  Volume v = openVolume(o.positional[0], o);
  double load = since(t0);
  int w = 512, h = 512;
  if (o.has("--size")) parseSize(o.get("--size", ""), w, h);
  Engine engine(backendKind(o));
  engine.setTuning(tuning(o));
  engine.setMemoryBudget(memoryBudget(o), poolBrick(o));
  engine.setVolume(v);
  engine.setTransferFunction(makeTF(o, v));
  engine.setBuildParams(buildParams(o, o.get("--builder", "auto")));
  engine.setRenderParams(renderParams(o));
  auto t1 = Clock::now();
  engine.update();
  double prep = since(t1);
  Image img;
  Camera cam = makeCamera(o, v, w, h);
  engine.render(cam, w, h, img);  // first frame (warm-up)
  for (int i = 0; i < 40 && engine.exploring(); ++i) engine.render(cam, w, h, img);  // Auto measures
  engine.render(cam, w, h, img);
  const BuildStats& s = engine.buildStats();
  if (!s.choice.empty()) std::printf("%s\n", s.choice.c_str());
  std::printf("volume %s: %lldx%lldx%lld %s, load %.3f s\n", o.positional[0].c_str(), (long long)v.dims.x,
              (long long)v.dims.y, (long long)v.dims.z, voxelTypeName(v.type), load);
  std::printf("backend %s, builder %s: ranges+classify+build %.3f s (classify %.4f s, build %.4f s), "
              "nodes %lld, height %d, leaves %lld, occupied bricks %.2f%%\n",
              engine.backendName(), builderName(s.builder), prep, s.classifySeconds, s.seconds,
              (long long)s.nodes, s.height, (long long)s.leaves, 100.0 * s.occupancy);
  std::printf("render %dx%d: %.4f s (%.2f fps), sample distance %g\n", w, h, engine.frameStats().seconds,
              1.0 / engine.frameStats().seconds, engine.sampleDistance());
  printResidency(engine.frameStats().residency);
  savePng(img, o.get("-o", ""));
  std::printf("wrote %s\n", o.get("-o", "").c_str());
  if (o.has("--compare")) {
    ImageDiff d = compareImages(img, loadPng(o.get("--compare", "")));
    std::printf("compare: max diff %.5f (%.2f/255), PSNR %.2f dB, %lld pixels > 1/255\n", d.maxAbs, d.maxAbs * 255,
                d.psnr, (long long)d.differing);
    if (o.has("--max-diff") && d.maxAbs * 255.0 > o.getDouble("--max-diff", 1, 0, 255)) {
      std::fprintf(stderr, "spaceskip: max difference %.2f/255 exceeds --max-diff %s\n", d.maxAbs * 255.0,
                   o.get("--max-diff", "").c_str());
      return 3;
    }
  }
  return 0;
}


/// `spaceskip sparse`: the same frames in core and sparse under --memory-budget, per builder:
/// images compared, frame rates side by side, and the TF edit (--tf -> --edit-tf) that makes
/// new bricks visible timed to its first frame. --no-in-core: sparse alone (a volume the device
/// cannot hold).
int cmdSparse(const Options& o) {
  if (o.positional.size() != 1 || !o.has("--memory-budget"))
    throw std::invalid_argument("sparse needs VOLUME --memory-budget N[K|M|G]");
  const std::vector<std::string> builders = split(o.get("--builders", "naive,grid,distance-grid,auto"), ',');
  const int frames = int(o.getInt("--frames", 8, 1, 1000000));
  int w = 1024, h = 1024;
  if (o.has("--size")) parseSize(o.get("--size", ""), w, h);
  const bool inCore = !o.has("--no-in-core");
  auto tg = Clock::now();
  Volume v = openVolume(o.positional[0], o);
  std::printf("volume %s: %lldx%lldx%lld %s, %.2f GiB, ready in %.1f s\n", o.positional[0].c_str(), (long long)v.dims.x,
              (long long)v.dims.y, (long long)v.dims.z, voxelTypeName(v.type), double(v.byteSize()) / 1073741824.0,
              since(tg));
  double lo, hi;
  if (!v.scalarRange(lo, hi)) lo = 0, hi = 1;
  const TransferFunction tf = makeTF(o, v);
  const std::string editName = o.get("--edit-tf", "ramp");
  const TransferFunction edited = TransferFunction::preset(editName, lo, hi);
  double b6[6];
  v.worldBounds(b6);
  auto cam = [&](int f) { return orbitCamera(b6, 360.0 * f / frames, 15, 1, false, double(w) / h); };
  std::printf("%-16s %-7s %9s %9s %9s %10s %9s %9s %9s %10s %11s\n", "builder", "mode", "kern_fps", "fps", "vs_incore",
              "max_diff", "needed", "resident", "pool_MiB", "first_ms", "edit_ms");
  int worst = 0;
  for (const std::string& b : builders) {
    struct Run {
      double kfps = 0, fps = 0, maxDiff = -1, firstMs = 0, editMs = 0;
      std::vector<Image> imgs;
      Image editImg;
      ResidencyStats r, edit;
      std::string backend;
    };
    auto run = [&](bool sparse) {
      Run out;
      Engine e(backendKind(o));
      e.setTuning(tuning(o));
      if (sparse) e.setMemoryBudget(memoryBudget(o), poolBrick(o));
      else e.setMemoryBudget(INT64_MAX);  // in core whatever the default budget says
      e.setLogger([](const std::string& m) { std::fprintf(stderr, "  note: %s\n", m.c_str()); });
      e.setVolume(v);
      e.setTransferFunction(tf);
      e.setBuildParams(buildParams(o, b));
      e.setRenderParams(renderParams(o));
      Image img;
      auto t0 = Clock::now();
      e.render(cam(0), w, h, img);  // ranges, classification, build, residency, one frame
      out.firstMs = 1e3 * since(t0);
      for (int i = 0; i < 40 && e.exploring(); ++i) e.render(cam(0), w, h, img);
      double total = 0, dev = 0;
      for (int f = 0; f < frames; ++f) {
        e.render(cam(f), w, h, img);
        total += e.frameStats().seconds;
        dev += e.frameStats().deviceSeconds;
        out.imgs.push_back(img);
      }
      out.fps = frames / total;
      out.kfps = dev > 0 ? frames / dev : out.fps;
      out.r = e.frameStats().residency;
      out.backend = e.frameStats().backend;
      // The edit: new bricks become visible; its first frame is timed (classification, rebuild,
      // residency update, the frame) and compared.
      e.setTransferFunction(edited);
      t0 = Clock::now();
      e.render(cam(0), w, h, out.editImg);
      out.editMs = 1e3 * since(t0);
      out.edit = e.frameStats().residency;
      return out;
    };
    Run ref;
    if (inCore) ref = run(false);
    Run sp = run(true);
    if (inCore) {
      sp.maxDiff = 0;
      for (int f = 0; f < frames; ++f) sp.maxDiff = std::max(sp.maxDiff, double(compareImages(ref.imgs[size_t(f)], sp.imgs[size_t(f)]).maxAbs));
      sp.maxDiff = std::max(sp.maxDiff, double(compareImages(ref.editImg, sp.editImg).maxAbs));
      std::printf("%-16s %-7s %9.1f %9.1f %9s %10s %9s %9s %9s %10.1f %11.2f\n", b.c_str(), "incore", ref.kfps, ref.fps,
                  "1", "-", "-", "-", "-", ref.firstMs, ref.editMs);
      if (sp.maxDiff * 255.0 > 1.0) worst = 3;
    }
    char diff[32] = "-", ratio[32] = "-";
    if (sp.maxDiff >= 0) std::snprintf(diff, sizeof diff, "%.2f/255", sp.maxDiff * 255.0);
    if (inCore) std::snprintf(ratio, sizeof ratio, "%.3f", sp.kfps / ref.kfps);
    std::printf("%-16s %-7s %9.1f %9.1f %9s %10s %9lld %9lld %9.1f %10.1f %11.2f\n", b.c_str(),
                sp.r.overflow ? "over" : sp.r.sparse ? "sparse" : sp.backend.c_str(), sp.kfps, sp.fps, ratio, diff, (long long)sp.r.needed,
                (long long)sp.r.resident, double(sp.r.poolBytes) / 1048576.0, sp.firstMs, sp.editMs);
    if (sp.edit.sparse)
      std::printf("%-16s %-7s after the edit to %s: %lld bricks needed, %lld uploaded (%.1f MiB), %lld evicted, "
                  "pool %.1f MiB, residency update %.2f ms of the %.2f ms\n",
                  b.c_str(), "", editName.c_str(), (long long)sp.edit.needed, (long long)sp.edit.uploaded,
                  double(sp.edit.uploaded) * double(makePoolLayout(v.dims, buildParams(o, b).brick, poolBrick(o)).slotVoxels()) *
                      double(voxelSize(v.type)) / 1048576.0,
                  (long long)sp.edit.evicted, double(sp.edit.poolBytes) / 1048576.0, 1e3 * sp.edit.updateSeconds,
                  sp.editMs);
    std::fflush(stdout);
  }
  if (worst) std::fprintf(stderr, "spaceskip: a sparse image differs from the in-core one by more than 1/255\n");
  return worst;
}

/// One measured bench item: a builder variant on one volume, the paper's protocol (orthographic
/// camera rotating about the volume, `frames` frames, the TF of --tf, no ERT unless --ert).
struct BenchRow {
  std::string label;  ///< the variant as asked for, "->Used" when the engine fell back
  BuildParams bp;
  BuildStats s;
  double cold = 0, fps = 0, kernelFps = 0, frameCpu = 0, samples = 0, gsps = 0, voxelGBs = 0;
  const char* filter = "exact";
  const char* leaf = "deep";
  /// --edits: the mean edit of each kind (0: the edits that empty bricks, 1: that occupy them).
  struct Edit {
    int count = 0;
    double ms = 0, classifyMs = 0, waitMs = 0, buildMs = 0, frameMs = 0, kernelMs = 0, builds = 0;
    double nextMs = 0, nextKernelMs = 0;  ///< the frame after the edit's (same view)
  } edits[2];
};

/// --edits N: opacity edits at a still view, each timed from setTransferFunction() to its
/// frame finished on the device (the image left in device memory, as the mapper's interop path
/// does; on the CPU backend the frame is the host's), with one untimed frame after each. The
/// edits alternate between zeroing the opacity below `cut` of the table (bricks empty) and the
/// TF as it was (bricks occupied again).
void measureEdits(Engine& engine, const TransferFunction& tf, const Camera& cam, int w, int h, int edits, double cut,
                  BenchRow& row) {
  TransferFunction cutTF = tf;
  const size_t below = size_t(std::clamp(cut, 0.0, 1.0) * double(cutTF.table.size()));
  for (size_t i = 0; i < below && i < cutTF.table.size(); ++i) cutTF.table[i].w = 0.f;
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
    t.subMaskMaxSet = item.parts;
  }
  const Tuning& was = engine.tuning();
  const bool reclassify = t.subMasks != was.subMasks || t.subMaskMaxSet != was.subMaskMaxSet;
  engine.setTuning(t);
  if (!reclassify) return;
  TransferFunction tf = makeTF(o, v), edited = tf;
  for (vec4f& e : edited.table) e.w = e.w > 0.f ? 0.f : 1.f;  // every brick's state differs
  engine.setTransferFunction(edited);
  engine.update();
  engine.setTransferFunction(tf);
}

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

/// `s` with quotes, backslashes and control characters escaped for a JSON string.
std::string jsonEscape(const std::string& s) {
  std::string o;
  for (const char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 0x20) o += ' ';
    else o += c;
  }
  return o;
}

std::string dimsText(vec3l d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

int cmdBenchPaper(const Options& o);

int cmdBench(const Options& o) {
  if (o.has("--paper")) return cmdBenchPaper(o);
  if (o.positional.empty()) throw std::invalid_argument("bench needs at least one VOLUME (or --paper)");
  std::vector<std::string> builders = split(o.get("--builders", "naive,grid"), ',');
  const int frames = int(o.getInt("--frames", 8, 1, 1000000));
  const int buildReps = int(o.getInt("--build-reps", 1, 1, 1000000));
  const Tuning knobs = tuning(o);
  int w = 1024, h = 1024;
  if (o.has("--size")) parseSize(o.get("--size", ""), w, h);
  std::ostringstream json;
  json << "[\n";
  std::ofstream csv;
  if (o.has("--csv")) {
    csv.open(o.get("--csv", ""));
    csv << "dataset,dims,variant,builder,backend,leaf,mls,bins,brick,build_s,classify_s,fps,nodes,height,leaves,occupancy,"
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
      const BenchRow r = measureItem(engine, v, b, o, w, h, frames, buildReps, knobs);
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
      if (csv.is_open())
        csv << name << "," << dims << "," << r.label << "," << builderName(s.builder) << "," << engine.backendName() << ","
            << r.leaf << "," << bp.maxLeafSize << "," << bp.bins << "," << bp.brick << "," << s.seconds << ","
            << s.classifySeconds << "," << r.fps << "," << s.nodes << "," << s.height << "," << s.leaves << ","
            << s.occupancy << "," << r.filter << "," << r.kernelFps << "," << r.cold << "," << s.builtOn << "," << r.samples
            << "," << r.gsps << "," << r.voxelGBs << "," << r.frameCpu << "\n";
    }
  }
  json << "\n]\n";
  if (o.has("--json")) {
    std::ofstream js(o.get("--json", ""));
    js << json.str();
  }
  return 0;
}

// ---- bench --paper: the paper's whole benchmark (Zellmann, Table 2 and Figs. 3-4) ----------------

/// A column group of the paper's table (shared/paper/paper_results.csv: <key>_build, <key>_fps),
/// or one of ours (no paper numbers), and the bench item that measures it.
struct PaperVariant {
  const char* key;
  const char* item;
  bool paper;  ///< the paper measured it
};

const std::vector<PaperVariant>& paperVariants() {
  // The paper's GPU k-d trees (4 bins) are built here with KdTreeGPUFast:bins4, which builds the
  // tree of the paper's KdTreeGPU method (KdTreeSplit.h) in milliseconds instead of minutes; on
  // the CPU backend a GPU builder falls back to KdTreeCPU (the label says "->KdTreeCPU").
  static const std::vector<PaperVariant> v = {
      {"naive", "naive", true},
      {"lbvh", "lbvh", true},
      {"cpu_shallow", "kdtree-cpu:shallow", true},
      {"cpu_mls32", "kdtree-cpu:deep:mls32", true},
      {"cpu_mls128", "kdtree-cpu:deep:mls128", true},
      {"gpu_shallow", "kdtree-gpu-fast:shallow:bins4", true},
      {"gpu_mls32", "kdtree-gpu-fast:deep:mls32:bins4", true},
      {"gpu_mls128", "kdtree-gpu-fast:deep:mls128:bins4", true},
      {"hybrid", "hybrid", true},
      {"grid", "grid", false},
      {"distance_grid", "distance-grid", false},
      {"kdtree_gpu_fast", "kdtree-gpu-fast:deep:mls128:bins0", false},
      {"kdtree_empty", "kdtree-gpu-fast:empty:bins0", false},
      {"auto", "auto", false},
  };
  return v;
}

/// Progress on stderr: a bar redrawn in place on a terminal, one line per step otherwise.
class Progress {
 public:
  explicit Progress(int total) : total_(total), tty_(isatty(2) != 0), t0_(Clock::now()) {}
  void step(int done, const std::string& what) {
    const double el = since(t0_);
    const double eta = done > 0 ? el / done * (total_ - done) : 0;
    const int width = 30, fill = total_ > 0 ? width * done / total_ : width;
    std::fprintf(stderr, "%s[%s%s] %d/%d %5.0f s, eta %5.0f s  %-50.50s%s", tty_ ? "\r" : "", std::string(size_t(fill), '#').c_str(),
                 std::string(size_t(width - fill), '.').c_str(), done, total_, el, eta, what.c_str(), tty_ ? "" : "\n");
    std::fflush(stderr);
  }
  void finish() {
    if (tty_) std::fputc('\n', stderr);
  }

 private:
  int total_;
  bool tty_;
  Clock::time_point t0_;
};

int cmdBenchPaper(const Options& o) {
  if (!o.positional.empty()) throw std::invalid_argument("bench --paper generates its volumes: no VOLUME arguments");
  const double scale = o.getDouble("--scale", 1.0, 1e-3, 1.0);
  const int frames = int(o.getInt("--frames", 8, 1, 1000000));
  const int buildReps = int(o.getInt("--build-reps", 1, 1, 1000000));
  const double timeLimit = o.getDouble("--time-limit", 0, 0, 1e9);  // 0: none
  const uint64_t cap = maxVolumeBytes(o);
  const Tuning knobs = tuning(o);
  int w = 1024, h = 1024;
  if (o.has("--size")) parseSize(o.get("--size", ""), w, h);

  // Data sets and variants: all, or the subsets named (unknown names are errors).
  std::vector<PaperDataset> sets;
  const std::vector<std::string> wantSets = split(o.get("--datasets", ""), ',');
  for (const std::string& n : wantSets) {
    auto it = std::find_if(paperDatasets().begin(), paperDatasets().end(), [&](const PaperDataset& d) { return n == d.name; });
    if (it == paperDatasets().end()) {
      std::string known;
      for (const PaperDataset& d : paperDatasets()) known += std::string(known.empty() ? "" : " ") + d.name;
      throw std::invalid_argument("--datasets: '" + n + "' is not one of " + known);
    }
    sets.push_back(*it);
  }
  if (wantSets.empty()) sets = paperDatasets();
  // --builders: the table's keys (naive, lbvh, cpu_shallow, cpu_mls32, ..., hybrid; ours: grid,
  // distance_grid, kdtree_gpu_fast, kdtree_empty, auto) or any bench item (its own key).
  std::vector<PaperVariant> vars;
  std::vector<std::string> owned;  // storage for items given as raw specs
  const std::vector<std::string> wantVars = split(o.get("--builders", ""), ',');
  owned.reserve(wantVars.size());
  for (const std::string& n : wantVars) {
    auto it = std::find_if(paperVariants().begin(), paperVariants().end(), [&](const PaperVariant& v) { return n == v.key; });
    if (it != paperVariants().end()) {
      vars.push_back(*it);
    } else {
      (void)buildParams(o, benchItem(n).spec);  // a bad spec fails here, before any work
      owned.push_back(n);
      vars.push_back(PaperVariant{owned.back().c_str(), owned.back().c_str(), false});
    }
  }
  if (wantVars.empty()) vars = paperVariants();
  // Naive first: every row's ratio is against it.
  std::stable_partition(vars.begin(), vars.end(), [](const PaperVariant& v) { return std::string(v.key) == "naive"; });

  std::ofstream csv;
  if (o.has("--csv")) {
    csv.open(o.get("--csv", ""));
    if (!csv) throw std::runtime_error("cannot write " + o.get("--csv", ""));
    csv << "dataset,paper_dims,dims,scale,variant,item,builder,backend,built_on,leaf,mls,bins,brick,build_s,build_cold_s,"
           "classify_s,fps,kernel_fps,frame_cpu_s,nodes,height,leaves,brick_occupancy,voxel_occupancy_pct,"
           "paper_occupancy_pct,samples_per_frame,vs_naive_kernel,width,height_px,frames,status,parts_share,"
           "edit_empty_ms,edit_occupy_ms,edit_occupy_classify_ms,edit_occupy_wait_ms,edit_occupy_build_ms,"
           "edit_occupy_frame_ms,edit_occupy_kernel_ms\n";
  }
  std::ostringstream json;
  json << "{\n  \"protocol\": {\"width\": " << w << ", \"height\": " << h << ", \"frames\": " << frames
       << ", \"scale\": " << scale << ", \"tf\": \"" << o.get("--tf", "ramp") << "\", \"ert\": " << o.get("--ert", "2")
       << ", \"camera\": \"orthographic, rotating about the volume (azimuth 360 f / frames, elevation 15)\"},\n  \"rows\": [\n";
  bool firstJson = true;

  Progress progress(int(sets.size() * vars.size()));
  int done = 0, measured = 0, failed = 0;
  const auto t0 = Clock::now();
  std::printf("%-18s %-14s %-16s %-40s %-6s %9s %9s %9s %8s %6s %8s\n", "dataset", "dims", "variant", "item", "backend",
              "build_ms", "fps", "kern_fps", "nodes", "height", "vs_naive");
  for (const PaperDataset& ds : sets) {
    const vec3l dims{std::max<int64_t>(8, std::llround(double(ds.dims.x) * scale)),
                     std::max<int64_t>(8, std::llround(double(ds.dims.y) * scale)),
                     std::max<int64_t>(8, std::llround(double(ds.dims.z) * scale))};
    auto skipAll = [&](const std::string& why) {
      for (const PaperVariant& pv : vars) {
        if (csv.is_open())
          csv << ds.name << "," << dimsText(ds.dims) << "," << dimsText(dims) << "," << scale << "," << pv.key << "," << pv.item
              << ",,,,,,,,,,,,,,,,,,," << ds.occupancyPct << ",,,,,," << why << ",,,,,,,,\n";
        progress.step(++done, std::string(ds.name) + " " + pv.key + ": " + why);
      }
    };
    if (timeLimit > 0 && since(t0) > timeLimit) {
      skipAll("skipped: time limit");
      continue;
    }
    Volume v;
    try {
      checkGeneratorSize(ds.shape, dims, cap);
      progress.step(done, std::string("generating ") + ds.name + " " + dimsText(dims));
      v = generateVolume(ds.shape, dims, 1);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "\n  note: %s %s skipped: %s\n", ds.name, dimsText(dims).c_str(), e.what());
      skipAll("skipped: volume too large");
      continue;
    }
    const TransferFunction tf = makeTF(o, v);
    const double voxelOcc = 100.0 * visibleVoxelFraction(v, tf);
    double naiveKernel = 0;
    std::unique_ptr<Engine> engine;
    try {
      engine = std::make_unique<Engine>(backendKind(o));
      engine->setLogger([](const std::string& m) { std::fprintf(stderr, "\n  note: %s\n", m.c_str()); });
      engine->setTuning(knobs);
      engine->setVolume(v);
      engine->setTransferFunction(tf);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "\n  note: %s: %s\n", ds.name, e.what());
      skipAll(std::string("skipped: ") + e.what());
      continue;
    }
    for (const PaperVariant& pv : vars) {
      progress.step(done, std::string(ds.name) + " " + pv.key);
      std::string status = "ok";
      BenchRow r;
      if (timeLimit > 0 && since(t0) > timeLimit) {
        status = "skipped: time limit";
      } else {
        try {
          r = measureItem(*engine, v, pv.item, o, w, h, frames, buildReps, knobs);
        } catch (const std::exception& e) {
          status = std::string("failed: ") + e.what();
          for (char& c : status)
            if (c == ',' || c == '\n' || c == '"') c = ' ';
        }
      }
      ++done;
      measured += status == "ok";
      failed += status.rfind("failed", 0) == 0;
      if (status != "ok") {
        if (csv.is_open())
          csv << ds.name << "," << dimsText(ds.dims) << "," << dimsText(dims) << "," << scale << "," << pv.key << ","
              << pv.item << ",,,,,,,,,,,,,,,,,,," << ds.occupancyPct << ",,,,,," << status << ",,,,,,,,\n";
        progress.step(done, std::string(ds.name) + " " + pv.key + ": " + status);
        continue;
      }
      const BuildStats& s = r.s;
      if (std::string(pv.key) == "naive") naiveKernel = r.kernelFps;
      const double vsNaive = naiveKernel > 0 ? r.kernelFps / naiveKernel : 0;
      std::printf("%-18s %-14s %-16s %-40s %-6s %9.3f %9.2f %9.2f %8lld %6d %7.3fx\n", ds.name, dimsText(dims).c_str(), pv.key,
                  r.label.c_str(), engine->backendName(), s.seconds * 1e3, r.fps, r.kernelFps, (long long)s.nodes, s.height,
                  vsNaive);
      std::fflush(stdout);
      if (csv.is_open()) {
        csv << ds.name << "," << dimsText(ds.dims) << "," << dimsText(dims) << "," << scale << "," << pv.key << "," << r.label
            << "," << builderName(s.builder) << "," << engine->backendName() << "," << s.builtOn << "," << r.leaf << ","
            << r.bp.maxLeafSize << "," << r.bp.bins << "," << r.bp.brick << "," << s.seconds << "," << r.cold << ","
            << s.classifySeconds << "," << r.fps << "," << r.kernelFps << "," << r.frameCpu << "," << s.nodes << ","
            << s.height << "," << s.leaves << "," << s.occupancy << "," << voxelOcc << "," << ds.occupancyPct << ","
            << r.samples << "," << vsNaive << "," << w << "," << h << "," << frames << ",ok," << s.partsShare;
        const BenchRow::Edit& em = r.edits[0];
        const BenchRow::Edit& oc = r.edits[1];
        if (oc.count)
          csv << "," << em.ms << "," << oc.ms << "," << oc.classifyMs << "," << oc.waitMs << "," << oc.buildMs << ","
              << oc.frameMs << "," << oc.kernelMs;
        else
          csv << ",,,,,,,";
        csv << "\n";
        csv.flush();
      }
      if (!firstJson) json << ",\n";
      firstJson = false;
      json << "    {\"dataset\": \"" << ds.name << "\", \"paper_dims\": \"" << dimsText(ds.dims) << "\", \"dims\": \""
           << dimsText(dims) << "\", \"variant\": \"" << pv.key << "\", \"item\": \"" << r.label << "\", \"builder\": \""
           << builderName(s.builder) << "\", \"backend\": \"" << engine->backendName() << "\", \"built_on\": \"" << s.builtOn
           << "\", \"leaf\": \"" << r.leaf << "\", \"mls\": " << r.bp.maxLeafSize << ", \"bins\": " << r.bp.bins
           << ", \"build_s\": " << s.seconds << ", \"build_cold_s\": " << r.cold << ", \"classify_s\": " << s.classifySeconds
           << ", \"fps\": " << r.fps << ", \"kernel_fps\": " << r.kernelFps << ", \"nodes\": " << s.nodes
           << ", \"height\": " << s.height << ", \"leaves\": " << s.leaves << ", \"brick_occupancy\": " << s.occupancy
           << ", \"voxel_occupancy_pct\": " << voxelOcc << ", \"paper_occupancy_pct\": " << ds.occupancyPct
           << ", \"samples_per_frame\": " << r.samples << ", \"vs_naive_kernel\": " << vsNaive
           << (s.choice.empty() ? std::string() : ", \"choice\": \"" + jsonEscape(s.choice) + "\"") << "}";
      progress.step(done, std::string(ds.name) + " " + pv.key + " done");
    }
  }
  progress.finish();
  json << "\n  ]\n}\n";
  if (o.has("--json")) {
    std::ofstream js(o.get("--json", ""));
    js << json.str();
  }
  std::printf("bench --paper: %d items, %d measured, %d failed, in %.1f s\n", done, measured, failed, since(t0));
  return failed ? 4 : 0;
}

// The speed/accuracy trade: image error against a reference at 1/8 of the smallest spacing
// (exact trilinear, no ERT), and frame rate, for coarser sample distances, both filter modes
// (hardware filtering exists on the CUDA backend only) and early ray termination.
int cmdAccuracy(const Options& o) {
  if (o.positional.size() != 1) throw std::invalid_argument("accuracy needs one VOLUME");
  Volume v = openVolume(o.positional[0], o);
  int w = 512, h = 512;
  if (o.has("--size")) parseSize(o.get("--size", ""), w, h);
  const double minSpacing = std::min({v.spacing[0], v.spacing[1], v.spacing[2]});
  Engine engine(backendKind(o));
  engine.setLogger([](const std::string& m) { std::fprintf(stderr, "  note: %s\n", m.c_str()); });
  engine.setTuning(tuning(o));
  engine.setVolume(v);
  engine.setTransferFunction(makeTF(o, v));
  engine.setBuildParams(buildParams(o, o.get("--builder", "auto")));
  Camera cam = makeCamera(o, v, w, h);
  RenderParams ref;
  ref.sampleDistance = minSpacing / 8;
  engine.setRenderParams(ref);
  Image reference;
  engine.render(cam, w, h, reference);
  std::printf("reference: sample distance %g (1/8 voxel), exact filtering, no ERT, backend %s\n",
              ref.sampleDistance, engine.backendName());
  std::printf("%-10s %-9s %-5s %-6s %10s %10s %8s %9s %9s %9s\n", "dt/voxel", "filter", "ert", "jitter", "max_diff",
              "psnr_db", "ssim", "fps", "kern_fps", "Msmp/frm");
  std::ofstream csv;
  if (o.has("--csv")) {
    csv.open(o.get("--csv", ""));
    if (!csv) throw std::runtime_error("cannot write " + o.get("--csv", ""));
    csv << "dataset,backend,builder,dt_voxel,filter,ert,jitter,max_diff,psnr_db,ssim,fps,kernel_fps,msamples\n";
  }
  std::vector<FilterMode> filters{FilterMode::Exact};
  if (std::string(engine.backendName()) == "cuda") filters.push_back(FilterMode::Hardware);
  for (double f : {0.25, 0.5, 1.0, 2.0, 4.0}) {
    for (FilterMode fm : filters) {
      for (bool ert : {false, true}) {
        for (bool jitter : {false, true}) {
          RenderParams rp;
          rp.sampleDistance = f * minSpacing;
          rp.filter = fm;
          rp.ertThreshold = ert ? 0.99 : 2.0;
          rp.jitter = jitter;
          engine.setRenderParams(rp);
          Image img;
          engine.render(cam, w, h, img);  // warm-up
          double t = 0, tk = 0;
          const int frames = 3;
          for (int i = 0; i < frames; ++i) {
            engine.render(cam, w, h, img);
            t += engine.frameStats().seconds;
            tk += engine.frameStats().deviceSeconds > 0 ? engine.frameStats().deviceSeconds : engine.frameStats().seconds;
          }
          rp.countSamples = true;
          engine.setRenderParams(rp);
          engine.render(cam, w, h, img);
          ImageDiff d = compareImages(reference, img);
          const double s = ssim(reference, img), ms = double(engine.frameStats().samples) * 1e-6;
          const char* fname = fm == FilterMode::Exact ? "exact" : "hardware";
          std::printf("%-10.2f %-9s %-5s %-6s %10.4f %10.2f %8.4f %9.2f %9.2f %9.2f\n", f, fname, ert ? "0.99" : "off",
                      jitter ? "on" : "off", d.maxAbs, d.psnr, s, frames / t, frames / tk, ms);
          std::fflush(stdout);
          if (csv.is_open())
            csv << o.positional[0] << ',' << engine.backendName() << ',' << builderName(engine.buildStats().builder) << ','
                << f << ',' << fname << ',' << (ert ? "0.99" : "off") << ',' << (jitter ? "on" : "off") << ','
                << d.maxAbs << ',' << d.psnr << ',' << s << ',' << frames / t << ',' << frames / tk << ',' << ms << '\n';
        }
      }
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "-h") || !std::strcmp(argv[1], "--help")) {
    printUsage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  try {
    std::string cmd = argv[1];
    Options o = parseArgs(argc, argv, 2);
    // Checked before any work: a bad value is reported even when no volume is loaded.
    (void)maxVolumeBytes(o);
    std::unique_ptr<tbb::global_control> threads;
    if (o.has("--threads"))
      threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      size_t(o.getInt("--threads", 1, 1, 65536)));
    if (cmd == "generate") return cmdGenerate(o);
    if (cmd == "render") return cmdRender(o);
    if (cmd == "bench") return cmdBench(o);
    if (cmd == "accuracy") return cmdAccuracy(o);
    if (cmd == "sparse") return cmdSparse(o);
    std::fprintf(stderr, "unknown command '%s'\n", cmd.c_str());
    printUsage(stderr);
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "spaceskip: error: %s\n", e.what());
    return 1;
  }
}

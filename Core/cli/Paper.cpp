// `spaceskip bench --paper`: the paper's whole benchmark (Zellmann, Table 2 and Figs. 3-4).
#include "Commands.h"
#include "spaceskip/Builders.h"
#include "spaceskip/Generators.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace spaceskip::cli {

namespace {

/// A column group of the paper's table (shared/paper/paper_results.csv: <key>_build, <key>_fps),
/// or one of ours (no paper numbers), and the bench item that measures it.
struct PaperVariant {
  std::string key;
  std::string item;
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

/// --datasets: all of the paper's, or the ones named (unknown names are errors).
std::vector<PaperDataset> selectDatasets(const Options& o) {
  std::vector<PaperDataset> sets;
  const std::vector<std::string> want = split(o.get("--datasets", ""), ',');
  for (const std::string& n : want) {
    auto it = std::find_if(paperDatasets().begin(), paperDatasets().end(), [&](const PaperDataset& d) { return n == d.name; });
    if (it == paperDatasets().end()) {
      std::string known;
      for (const PaperDataset& d : paperDatasets()) known += std::string(known.empty() ? "" : " ") + d.name;
      throw std::invalid_argument("--datasets: '" + n + "' is not one of " + known);
    }
    sets.push_back(*it);
  }
  if (want.empty()) sets = paperDatasets();
  return sets;
}

/// --builders: the table's keys (naive, lbvh, cpu_shallow, cpu_mls32, ..., hybrid; ours: grid,
/// distance_grid, kdtree_gpu_fast, kdtree_empty, auto) or any bench item (its own key); all when
/// absent. Naive first: every row's ratio is against it.
std::vector<PaperVariant> selectVariants(const Options& o) {
  std::vector<PaperVariant> vars;
  const std::vector<std::string> want = split(o.get("--builders", ""), ',');
  for (const std::string& n : want) {
    auto it = std::find_if(paperVariants().begin(), paperVariants().end(), [&](const PaperVariant& v) { return n == v.key; });
    if (it != paperVariants().end()) {
      vars.push_back(*it);
    } else {
      (void)buildParams(o, benchItem(n).spec);  // a bad spec fails here, before any work
      vars.push_back(PaperVariant{n, n, false});
    }
  }
  if (want.empty()) vars = paperVariants();
  std::stable_partition(vars.begin(), vars.end(), [](const PaperVariant& v) { return v.key == "naive"; });
  return vars;
}

/// The benchmark's results: a CSV row and a JSON row per item (skipped and failed items in the
/// CSV only), the JSON written at the end. Both files are opened at the start (a path that cannot
/// be written fails before any work) and renamed into place by finish(); until then the CSV rows
/// are in the temporary file beside it (OutputFile), one flushed per item.
class PaperOutput {
 public:
  PaperOutput(const Options& o, int w, int h, int frames, double scale)
      : w_(w), h_(h), frames_(frames), scale_(scale), jsonFile_(outputOption(o, "--json")),
        csvFile_(outputOption(o, "--csv")) {
    if (csvFile_) {
      csvFile_->stream() << "dataset,paper_dims,dims,scale,variant,item,builder,backend,built_on,leaf,mls,bins,brick,build_s,build_cold_s,"
              "classify_s,fps,kernel_fps,frame_cpu_s,nodes,height,leaves,brick_occupancy,voxel_occupancy_pct,"
              "paper_occupancy_pct,samples_per_frame,vs_naive_kernel,width,height_px,frames,status,parts_share,"
              "edit_empty_ms,edit_occupy_ms,edit_occupy_classify_ms,edit_occupy_wait_ms,edit_occupy_build_ms,"
              "edit_occupy_frame_ms,edit_occupy_kernel_ms\n";
    }
    json_ << "{\n  \"protocol\": {\"width\": " << w << ", \"height\": " << h << ", \"frames\": " << frames
          << ", \"scale\": " << scale << ", \"tf\": \"" << o.get("--tf", "ramp") << "\", \"ert\": " << o.get("--ert", "2")
          << ", \"camera\": \"orthographic, rotating about the volume (azimuth 360 f / frames, elevation 15)\"},\n"
          << "  \"rows\": [\n";
  }

  /// An item not measured: `status` says why.
  void skipped(const PaperDataset& ds, vec3l dims, const PaperVariant& pv, const std::string& status) {
    if (csvFile_)
      csvFile_->stream() << ds.name << "," << dimsText(ds.dims) << "," << dimsText(dims) << "," << scale_ << "," << pv.key << ","
           << pv.item << ",,,,,,,,,,,,,,,,,,," << ds.occupancyPct << ",,,,,," << status << ",,,,,,,,\n";
  }

  void measured(const PaperDataset& ds, vec3l dims, const PaperVariant& pv, const BenchRow& r, const char* backend,
                double voxelOcc, double vsNaive) {
    const BuildStats& s = r.s;
    if (csvFile_) {
      std::ostream& csv = csvFile_->stream();
      csv << ds.name << "," << dimsText(ds.dims) << "," << dimsText(dims) << "," << scale_ << "," << pv.key << ","
           << r.label << "," << builderName(s.builder) << "," << backend << "," << s.builtOn << "," << r.leaf << ","
           << r.bp.maxLeafSize << "," << r.bp.bins << "," << r.bp.brick << "," << s.seconds << "," << r.cold << ","
           << s.classifySeconds << "," << r.fps << "," << r.kernelFps << "," << r.frameCpu << "," << s.nodes << ","
           << s.height << "," << s.leaves << "," << s.occupancy << "," << voxelOcc << "," << ds.occupancyPct << ","
           << r.samples << "," << vsNaive << "," << w_ << "," << h_ << "," << frames_ << ",ok," << s.partsShare;
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
    if (!firstJson_) json_ << ",\n";
    firstJson_ = false;
    json_ << "    {\"dataset\": \"" << ds.name << "\", \"paper_dims\": \"" << dimsText(ds.dims) << "\", \"dims\": \""
          << dimsText(dims) << "\", \"variant\": \"" << pv.key << "\", \"item\": \"" << r.label << "\", \"builder\": \""
          << builderName(s.builder) << "\", \"backend\": \"" << backend << "\", \"built_on\": \"" << s.builtOn
          << "\", \"leaf\": \"" << r.leaf << "\", \"mls\": " << r.bp.maxLeafSize << ", \"bins\": " << r.bp.bins
          << ", \"build_s\": " << s.seconds << ", \"build_cold_s\": " << r.cold << ", \"classify_s\": " << s.classifySeconds
          << ", \"fps\": " << r.fps << ", \"kernel_fps\": " << r.kernelFps << ", \"nodes\": " << s.nodes
          << ", \"height\": " << s.height << ", \"leaves\": " << s.leaves << ", \"brick_occupancy\": " << s.occupancy
          << ", \"voxel_occupancy_pct\": " << voxelOcc << ", \"paper_occupancy_pct\": " << ds.occupancyPct
          << ", \"samples_per_frame\": " << r.samples << ", \"vs_naive_kernel\": " << vsNaive
          << (s.choice.empty() ? std::string() : ", \"choice\": \"" + jsonEscape(s.choice) + "\"") << "}";
  }

  void finish() {
    json_ << "\n  ]\n}\n";
    if (jsonFile_) {
      jsonFile_->stream() << json_.str();
      jsonFile_->commit();
    }
    if (csvFile_) csvFile_->commit();
  }

 private:
  int w_, h_, frames_;
  double scale_;
  std::unique_ptr<OutputFile> jsonFile_, csvFile_;
  std::ostringstream json_;
  bool firstJson_ = true;
};

/// One data set's engine (its volume and TF set), or null with the reason in `why`.
std::unique_ptr<Engine> datasetEngine(const Options& o, const Tuning& knobs, const Volume& v, const TransferFunction& tf,
                                      std::string& why) {
  try {
    auto engine = std::make_unique<Engine>(backendKind(o));
    engine->setLogger([](const std::string& m) { std::fprintf(stderr, "\n  note: %s\n", m.c_str()); });
    engine->setTuning(knobs);
    engine->setVolume(v);
    engine->setTransferFunction(tf);
    return engine;
  } catch (const std::exception& e) {
    why = e.what();
    return nullptr;
  }
}

}  // namespace

int cmdBenchPaper(const Options& o) {
  if (!o.positional.empty()) throw std::invalid_argument("bench --paper generates its volumes: no VOLUME arguments");
  const double scale = o.getDouble("--scale", 1.0, 1e-3, 1.0);
  const int frames = int(o.getInt("--frames", 8, 1, 1000000));
  const int buildReps = int(o.getInt("--build-reps", 1, 1, 1000000));
  const double timeLimit = o.getDouble("--time-limit", 0, 0, 1e9);  // 0: none
  const uint64_t cap = maxVolumeBytes(o);
  const Tuning knobs = tuning(o);
  int w = 1024, h = 1024;
  imageSize(o, w, h);
  const std::vector<PaperDataset> sets = selectDatasets(o);
  const std::vector<PaperVariant> vars = selectVariants(o);
  PaperOutput out(o, w, h, frames, scale);

  Progress progress(int(sets.size() * vars.size()));
  int done = 0, measured = 0, failed = 0;
  const auto t0 = Clock::now();
  auto overTime = [&] { return timeLimit > 0 && since(t0) > timeLimit; };
  std::printf("%-18s %-14s %-16s %-40s %-6s %9s %9s %9s %8s %6s %8s\n", "dataset", "dims", "variant", "item", "backend",
              "build_ms", "fps", "kern_fps", "nodes", "height", "vs_naive");
  for (const PaperDataset& ds : sets) {
    const vec3l dims{std::max<int64_t>(8, std::llround(double(ds.dims.x) * scale)),
                     std::max<int64_t>(8, std::llround(double(ds.dims.y) * scale)),
                     std::max<int64_t>(8, std::llround(double(ds.dims.z) * scale))};
    auto skip = [&](const PaperVariant& pv, const std::string& why) {
      out.skipped(ds, dims, pv, why);
      progress.step(done, std::string(ds.name) + " " + pv.key + ": " + why);
    };
    auto skipAll = [&](const std::string& why) {
      for (const PaperVariant& pv : vars) {
        ++done;
        skip(pv, why);
      }
    };
    if (overTime()) {
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
    std::string why;
    const std::unique_ptr<Engine> engine = datasetEngine(o, knobs, v, tf, why);
    if (!engine) {
      std::fprintf(stderr, "\n  note: %s: %s\n", ds.name, why.c_str());
      skipAll("skipped: " + why);
      continue;
    }
    for (const PaperVariant& pv : vars) {
      progress.step(done, std::string(ds.name) + " " + pv.key);
      std::string status = "ok";
      BenchRow r;
      if (overTime()) {
        status = "skipped: time limit";
      } else {
        try {
          r = allocating(frameText(w, h), frameBytes(w, h),
                         [&] { return measureItem(*engine, v, pv.item, o, w, h, frames, buildReps, knobs); });
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
        skip(pv, status);
        continue;
      }
      if (pv.key == "naive") naiveKernel = r.kernelFps;
      const double vsNaive = naiveKernel > 0 ? r.kernelFps / naiveKernel : 0;
      std::printf("%-18s %-14s %-16s %-40s %-6s %9.3f %9.2f %9.2f %8lld %6d %7.3fx\n", ds.name, dimsText(dims).c_str(),
                  pv.key.c_str(), r.label.c_str(), engine->backendName(), r.s.seconds * 1e3, r.fps, r.kernelFps,
                  (long long)r.s.nodes, r.s.height, vsNaive);
      std::fflush(stdout);
      out.measured(ds, dims, pv, r, engine->backendName(), voxelOcc, vsNaive);
      progress.step(done, std::string(ds.name) + " " + pv.key + " done");
    }
  }
  progress.finish();
  out.finish();
  std::printf("bench --paper: %d items, %d measured, %d failed, in %.1f s\n", done, measured, failed, since(t0));
  return failed ? 4 : 0;
}

}  // namespace spaceskip::cli

// The spaceskip CLI's commands (one file each) and what they share: opening volumes, the TF and
// camera from the options, the bench's measured item.
#pragma once
#include "Options.h"
#include "spaceskip/Engine.h"
#include "spaceskip/OutputFile.h"

#include <chrono>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

namespace spaceskip::cli {

using Clock = std::chrono::steady_clock;
inline double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// The median of `v` (the mean of the middle two for an even count; 0 when empty).
double median(std::vector<double> v);
/// The largest of `v` (0 when empty).
double maxOf(const std::vector<double>& v);
/// CPU seconds used by this process (all threads): a frame's work, robust against other load
/// on a shared machine (wall-clock fps is not).
double processCpuSeconds();
/// VOLUME: NAME_XxYxZ_TYPE.raw, FILE.nrrd, or gen:SHAPE:N / gen:SHAPE:XxYxZ, within --max-volume-bytes.
Volume openVolume(const std::string& spec, const Options& o);
/// --tf: a preset over the volume's range, or a file of that name.
TransferFunction makeTF(const Options& o, const Volume& v);
/// --camera AZ,EL[,ZOOM] and --perspective for a w x h image.
Camera makeCamera(const Options& o, const Volume& v, int w, int h, double azDefault = 30, double elDefault = 20);
/// One line on sparse residency (nothing when the volume is in core).
void printResidency(const ResidencyStats& r);
/// `s` with quotes, backslashes and control characters escaped for a JSON string.
std::string jsonEscape(const std::string& s);
/// "XxYxZ".
std::string dimsText(vec3l d);
/// "out of memory WHAT (N bytes, G GiB)".
std::string outOfMemory(const std::string& what, uint64_t bytes);
/// Runs `f`; a std::bad_alloc becomes a std::runtime_error naming what was being allocated and
/// how large (outOfMemory), instead of a bare "std::bad_alloc".
template <class F>
decltype(auto) allocating(const std::string& what, uint64_t bytes, F&& f) {
  try {
    return f();
  } catch (const std::bad_alloc&) {
    throw std::runtime_error(outOfMemory(what, bytes));
  }
}
/// A w x h frame's text for allocating(): "drawing a WxH frame (its image alone)" and its bytes.
std::string frameText(int w, int h);
inline uint64_t frameBytes(int w, int h) { return uint64_t(w) * uint64_t(h) * kImageBytesPerPixel; }

/// The file an output option names (--json, --csv), opened before any work so that a path that
/// cannot be written fails at once (the message names the option); null when it is absent.
std::unique_ptr<OutputFile> outputOption(const Options& o, const std::string& option);

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

/// Measures one bench item (a --builders entry) on `engine`, which holds `v` and its TF.
BenchRow measureItem(Engine& engine, const Volume& v, const std::string& itemText, const Options& o, int w, int h,
                     int frames, int buildReps, const Tuning& tuning);

int cmdGenerate(const Options& o);    ///< Generate.cpp
int cmdRender(const Options& o);      ///< Render.cpp
int cmdSparse(const Options& o);      ///< Sparse.cpp
int cmdBench(const Options& o);       ///< Bench.cpp
int cmdBenchPaper(const Options& o);  ///< Paper.cpp
int cmdBenchLabels(const Options& o); ///< BenchLabels.cpp (bench --label-map)
int cmdBenchTimeSeries(const Options& o); ///< BenchTimeSeries.cpp (bench --time-series)
int cmdAccuracy(const Options& o);    ///< Accuracy.cpp

}  // namespace spaceskip::cli

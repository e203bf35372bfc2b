// Command-line parsing for the spaceskip CLI: strict values, range checks, clear messages.
// Separate from the commands (Commands.h) so the option fuzzer (Testing/Fuzz) and the tests
// can call it.
#pragma once
#include "spaceskip/Engine.h"
#include "spaceskip/Tuning.h"

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace spaceskip::cli {

/// Every error here is a std::invalid_argument naming the option and the value.
struct Options {
  std::vector<std::string> positional;
  std::map<std::string, std::string> kv;
  bool has(const std::string& k) const { return kv.count(k) != 0; }
  std::string get(const std::string& k, const std::string& def) const {
    auto it = kv.find(k);
    return it == kv.end() ? def : it->second;
  }
  /// Integer option in [lo, hi]; `def` when absent.
  int64_t getInt(const std::string& k, int64_t def, int64_t lo, int64_t hi) const;
  /// Finite number in [lo, hi]; `def` when absent.
  double getDouble(const std::string& k, double def, double lo, double hi) const;
};

/// argv[first..argc): options (unknown ones refused), flags and positional arguments.
Options parseArgs(int argc, const char* const* argv, int first);

/// Integer text in [lo, hi], or std::invalid_argument("<what>: ..."); no "12abc", no overflow.
int64_t parseIntArg(const std::string& text, const std::string& what, int64_t lo, int64_t hi);
/// Finite number in [lo, hi], or std::invalid_argument.
double parseDoubleArg(const std::string& text, const std::string& what, double lo, double hi);

/// "N" (a cube) or "XxYxZ"; each axis in [1, 2^30].
vec3l parseDims(const std::string& s, const std::string& what);
/// "WxH", each in [1, kMaxImageSide].
constexpr int kMaxImageSide = 16384;
void parseSize(const std::string& s, int& w, int& h);
/// The image budget: an image takes kImageBytesPerPixel (float RGBA) per pixel on the host (and
/// as much on a device); --max-image-bytes N[K|M|G|T] raises the default of 1 GiB (8192x8192).
constexpr uint64_t kImageBytesPerPixel = 16;
constexpr uint64_t kDefaultMaxImageBytes = uint64_t(1) << 30;
uint64_t maxImageBytes(const Options& o);
/// --size WxH if given (else w, h as passed: the command's default), within the image budget:
/// std::invalid_argument naming the size, its bytes, the budget and --max-image-bytes.
void imageSize(const Options& o, int& w, int& h);
/// "AZ,EL[,ZOOM]": finite angles, zoom > 0.
void parseCamera(const std::string& s, double& az, double& el, double& zoom);

/// "gen:SHAPE:N" or "gen:SHAPE:XxYxZ": the shape and dims, size-checked against maxBytes
/// before anything is generated. False when `spec` does not start with "gen:".
bool parseGeneratorSpec(const std::string& spec, uint64_t maxBytes, std::string& shape, vec3l& dims);
/// Voxel bytes of a generated volume, checked (throws like checkedByteSize).
uint64_t checkGeneratorSize(const std::string& shape, vec3l dims, uint64_t maxBytes);

/// --max-volume-bytes (N with an optional K/M/G/T suffix), else SPACESKIP_MAX_VOLUME_BYTES
/// (Environment.h), else defaultMaxVolumeBytes().
uint64_t maxVolumeBytes(const Options& o);

/// --memory-budget N[K|M|G|T]: the most memory the voxels may take on the backend (0 when
/// absent: the backend's default); above it the volume is kept sparse (Engine::setMemoryBudget).
int64_t memoryBudget(const Options& o);
/// --pool-brick N (1..1024, default 16): cells per pool brick edge of sparse residency.
int poolBrick(const Options& o);

/// `spec` is NAME[:SUFFIX]... (bench variants); suffixes override --leaf/--mls/--bins/--brick:
/// shallow, deep, mlsN, binsN, brickN.
BuildParams buildParams(const Options& o, const std::string& spec);
/// --label-map's labels for `v`: every id of its value range but 0, colours far apart for
/// neighbouring ids, opacity 0.5, --hide-labels hidden (empty for volumes that are no label map).
LabelTable labelTable(const Options& o, const Volume& v);
RenderParams renderParams(const Options& o);
BackendKind backendKind(const Options& o);
/// The engine's knobs: the environment's (Environment.h), then --cuda-block WxH (32..256
/// threads) over SPACESKIP_CUDA_BLOCK.
Tuning tuning(const Options& o);

/// Bench-only suffixes of a --builders item, stripped before buildParams sees it:
/// `hw`/`exact` pick the filter for this item, `cold` times the first build only (no rebuilds:
/// for very slow builders such as the paper's KdTreeGPU at 2048^3).
struct BenchItem {
  std::string spec;      ///< the item without bench-only suffixes
  int filter = -1;       ///< -1: --filter, else a FilterMode
  bool cold = false;
  int resident = -1;  ///< `resN`: Tuning::resident = N for this item (CUDA launch shape)
  /// Sub-brick masks for this item: -2 as the environment says; -1 (`whole`): none
  /// (Tuning::subMasks off); N (`partsN`): bricks with at most N of 64 parts set are walked part
  /// by part (Tuning::subMaskMaxSet = N; on the CPU backend too: Tuning::cpuSubMasks).
  int parts = -2;
};
BenchItem benchItem(const std::string& item);

std::vector<std::string> split(const std::string& s, char c);

}  // namespace spaceskip::cli

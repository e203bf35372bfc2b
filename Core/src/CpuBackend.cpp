// The oneTBB backend: tiles of pixels run the shared per-ray integrator.
#include "spaceskip/Backend.h"
#include "spaceskip/DeviceImageCopy.h"
#include "spaceskip/PeerImages.h"
#include "spaceskip/BrickPool.h"
#include "spaceskip/Builders.h"
#include "spaceskip/DistanceField.h"
#include "spaceskip/GradientBound.h"
#include "spaceskip/StepMemory.h"
#include "src/CpuMarch.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cstring>

namespace spaceskip {

namespace {

constexpr int kTile = 16;  // pixels per tile edge: one oneTBB task

class CpuBackend final : public Backend {
 public:
  BackendKind kind() const override { return BackendKind::CPU; }
  const char* name() const override { return "cpu"; }

  void setVolume(const Volume& v, int brick) override {
    volume_ = v;
    ranges_ = computeRangeGrid(v, brick);
    pool_.release();
    // Sparse residency in host memory when a budget below the volume is set (the device
    // pool's rules, checked here without a GPU); one component only, else in core.
    // Not for a warped volume (AxisWarp.h): the pool's bricks are read by the lattice's index.
    if (budget_ > 0 && int64_t(v.byteSize()) > budget_ && v.components == 1 && !v.warp)
      pool_.init(v, ranges_.brick, poolBrick_, budget_);
    dist_.clear();
    sub_ = SubMasks{};
    occ_ = OccupancyGrid{};
    tree_ = Tree{};
  }

  bool brickValueRange(double& lo, double& hi) override {
    if (ranges_.vmin.empty()) return false;
    lo = *std::min_element(ranges_.vmin.begin(), ranges_.vmin.end());
    hi = *std::max_element(ranges_.vmax.begin(), ranges_.vmax.end());
    return true;
  }

  void setTuning(const Tuning& t) override { tuning_ = t; }

  bool classify(const TransferFunction& tf, const CropClip& cc) override {
    // A 2-D function over the gradient (classificationTF keeps its table): the gradient rule too.
    const GradientRows rows(tf, volume_.spacing);
    OccupancyGrid o = classifyWithGradientRows(ranges_, tf, cc, rows.view());
    const bool sameDims = o.dims.x == occ_.dims.x && o.dims.y == occ_.dims.y && o.dims.z == occ_.dims.z &&
                          o.occ.size() == occ_.occ.size();
    bool changed = !sameDims || o.occ != occ_.occ;
    onlyEmptied_ = sameDims && !pool_.active();
    for (size_t i = 0; onlyEmptied_ && i < o.occ.size(); ++i)
      if (o.occ[i] && !occ_.occ[i]) onlyEmptied_ = false;
    occ_ = std::move(o);
    sub_ = tuning_.cpuSubMasks ? computeSubMasks(volume_, occ_, tf, tuning_) : SubMasks{};
    readVoxels_ = !sub_.mask.empty();
    markDistances();  // a field kept across the edit takes the new states' marks
    tf_ = tf;
    if (changed) ++generation_;
    return changed;
  }

  bool classifyLabels(const LabelSets& ls, const std::vector<uint8_t>& drawn, const CropClip& cc) override {
    OccupancyGrid o = spaceskip::classifyLabels(ls, drawn, cc);
    const bool sameDims = o.dims.x == occ_.dims.x && o.dims.y == occ_.dims.y && o.dims.z == occ_.dims.z &&
                          o.occ.size() == occ_.occ.size();
    const bool changed = !sameDims || o.occ != occ_.occ;
    onlyEmptied_ = sameDims && !pool_.active();
    for (size_t i = 0; onlyEmptied_ && i < o.occ.size(); ++i)
      if (o.occ[i] && !occ_.occ[i]) onlyEmptied_ = false;
    occ_ = std::move(o);
    sub_ = SubMasks{};  // no masks for label maps: an edit reads no voxel
    readVoxels_ = false;
    markDistances();
    if (changed) ++generation_;
    return changed;
  }
  bool lastClassifyReadVoxels() const override { return readVoxels_; }

  bool lastClassifyOnlyEmptied() const override { return onlyEmptied_; }
  double subMaskShare() const override { return sub_.mask.empty() ? 1.0 : sub_.share; }

  void setMemoryBudget(int64_t bytes, int poolBrick) override {
    budget_ = bytes > 0 ? bytes : 0;
    poolBrick_ = poolBrick > 0 ? poolBrick : kPoolBrick;
  }
  ResidencyStats residency() const override {
    ResidencyStats s = pool_.active() ? pool_.stats() : ResidencyStats{};
    if (!pool_.active()) s.budgetBytes = budget_;
    s.overflow = overflow_;
    return s;
  }

  void setTransferTable(const std::vector<vec4f>& t, float lo, float scale) override {
    table_ = t;
    tfLo_ = lo;
    tfScale_ = scale;
  }

  void build(const BuildParams& p, BuildStats& s) override {
    auto t0 = std::chrono::steady_clock::now();
    const BuilderInfo& info = builderInfo(p.builder);
    traversal_ = info.traversal;
    tree_ = Tree{};
    hybridGrid_ = OccupancyGrid{};
    dist_.clear();
    if (info.extra == BuilderExtra::DistanceField) {
      dist_ = computeDistanceField(occ_);
      markDistances();
    }
    if (info.extra == BuilderExtra::CoarseGrid) hybridGrid_ = coarsen(occ_, std::max(1, kHybridCell / occ_.brick));
    if (buildsTree(info)) tree_ = buildTreeCPU(occ_, p);
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    s.builtOn = "cpu";
    s.nodes = int64_t(tree_.nodes.size());
    s.height = tree_.height;
    s.leaves = tree_.leaves;
  }

  void render(FrameView f, FilterMode, const float* depth, Image& out) override {
    f.depth = depth;
    f.traversal = traversal_;
    const OccupancyGrid& g = traversal_ == TraversalKind::Hybrid ? hybridGrid_ : occ_;
    // Grid and DistanceGrid frames walk the parts of sparse bricks wherever there are masks
    // (GridParts), which is only with Tuning::cpuSubMasks: against whole bricks on the paper's
    // stand-ins at 1/4 scale the walk measured 1.06-1.53x on 2026-11-24, and 0.92-1.03x on
    // 2026-12-01, after the SIMD packets made samples cheaper (docs/results/cpu-sub-brick-masks).
    const bool parts = traversal_ == TraversalKind::Grid && !sub_.mask.empty();
    if (parts) f.traversal = TraversalKind::GridParts;
    f.grid = GridView{parts ? sub_.state.data() : g.occ.data(), g.dims, g.brick, dist_.empty() ? nullptr : dist_.data(),
                      nullptr, nullptr, parts ? sub_.mask.data() : nullptr};
    f.tree = TreeView{tree_.nodes.data(), int(tree_.nodes.size())};
    // In these modes every skipping builder marches the value ranges (render/Integrator.h, usesValueRanges).
    if (usesValueRanges(f.blend) && traversal_ != TraversalKind::Naive) {
      f.traversal = TraversalKind::Grid;
      f.grid = GridView{nullptr, ranges_.dims, ranges_.brick, nullptr, ranges_.vmin.data(), ranges_.vmax.data()};
    }
    f.tf = TransferFunctionView{table_.data(), int(table_.size()), tfLo_, tfScale_};
    // Shadow rays skip with the finest structure this classification has, whatever the builder:
    // the parts of sparse bricks where there are masks, and DistanceGrid's leaps where it made them.
    if (scatterSkips(f, traversal_)) {
      const bool masks = !sub_.mask.empty();
      f.scatter.occ = GridView{masks ? sub_.state.data() : occ_.occ.data(), occ_.dims, occ_.brick,
                               dist_.empty() ? nullptr : dist_.data(), nullptr, nullptr, masks ? sub_.mask.data() : nullptr};
    }
    out.width = f.width;
    out.height = f.height;
    out.rgba.assign(size_t(f.width) * size_t(f.height), vec4f{0, 0, 0, 0});
    overflow_ = false;
    if (pool_.active() && f.sampling == kSampleTrilinear) {  // nearest and label frames sample in core
      try {
        pool_.update(poolNeedFor(f.blend, f.shade != 0 || f.gtf.mode != 0, tf_, f.avgLo, f.avgHi), occ_.occ.data(), generation_,
                     ranges_.vmin.data(), ranges_.vmax.data(), ranges_.dims, ranges_.brick);
      } catch (const std::runtime_error&) {
        overflow_ = true;  // the whole volume is in host memory: this frame samples it in core
      }
    }
    if (volume_.warp) {  // a rectilinear grid through its coordinates (AxisWarp.h): the scalar integrator
      if (f.sampling != kSampleTrilinear)
        throw BackendError("a rectilinear grid is drawn through its coordinates with trilinear sampling only");
      tiles(f, out, WarpedSampler{volume_.data, volume_.type, volume_.dims.x, volume_.dims.y, volume_.dims.z,
                                  volume_.warp->view()});
      return;
    }
    dispatchVoxelType(volume_.type, [&](auto voxel) { run<decltype(voxel)>(f, out); });
  }

  const OccupancyGrid& occupancy() override { return occ_; }
  Tree tree() override { return tree_; }

 private:
  /// DistanceGrid's field marked with markedDistance for the current states (cleared without).
  void markDistances() {
    const bool states = sub_.state.size() == dist_.size();
    for (size_t i = 0; i < dist_.size(); ++i)
      dist_[i] = states ? markedDistance(dist_[i], sub_.state[i]) : uint8_t(dist_[i] & 0x7f);
  }

  template <class T>
  void run(const FrameView& f, Image& out) {
    if (f.sampling != kSampleTrilinear && volume_.components == 1) {  // nearest, label maps (LabelSampler.h)
      tiles(f, out, NearestSampler<T>{static_cast<const T*>(volume_.data), volume_.dims.x, volume_.dims.y,
                                      volume_.dims.z, f.sampling});
      return;
    }
    if (pool_.active() && !overflow_) {
      tiles(f, out, pool_.view().sampler<T>());
      return;
    }
    if (volume_.components > 1) {  // dependent components (render/Components.h)
      tiles(f, out, ChannelSampler<T>{static_cast<const T*>(volume_.data), volume_.dims.x, volume_.dims.y,
                                      volume_.dims.z, volume_.components});
      return;
    }
    if (packetMarchable(f, volume_.type, volume_.components, volume_.dims.x, volume_.dims.y, volume_.dims.z)) {
      packetTiles(f, out);  // SIMD ray packets (CpuMarch.h): the same pixels as the scalar integrator's
      return;
    }
    tiles(f, out, ArraySampler<T>{static_cast<const T*>(volume_.data), volume_.dims.x, volume_.dims.y, volume_.dims.z});
  }

  void packetTiles(const FrameView& f, Image& out) {
    vec4f* px = out.rgba.data();
    packetPairTable(f.tf, pairs_);
    const float* pairs = pairs_.data();
    forTiles(f, [&](const tbb::blocked_range2d<int>& r) {
      marchPacketTile(f, pairs, volume_.type, volume_.data, volume_.dims.x, volume_.dims.y, volume_.dims.z,
                      r.cols().begin(), r.rows().begin(), r.cols().end(), r.rows().end(), px);
    });
  }

  template <class Sampler>
  void tiles(const FrameView& f, Image& out, const Sampler& s) {
    vec4f* px = out.rgba.data();
    // Plain frames take the integrator's composite-only code (renderPixel's Plain), as on CUDA.
    const bool plain = isPlainFrame(f);
    forTiles(f, [&](const tbb::blocked_range2d<int>& r) {
      for (int y = r.rows().begin(); y != r.rows().end(); ++y)
        for (int x = r.cols().begin(); x != r.cols().end(); ++x)
          px[size_t(y) * size_t(f.width) + size_t(x)] =
              plain ? renderPixel<Sampler, -1, true>(f, s, x, y) : renderPixel(f, s, x, y);
    });
  }

  /// Runs `tile` over the frame's tiles with oneTBB. A large frame with a progress hook goes in
  /// kProgressBands bands of rows, the hook told after each on this thread (the cores stay busy
  /// within a band; between bands they wait for its slowest tile).
  template <class Tile>
  void forTiles(const FrameView& f, const Tile& tile) {
    const bool bands = progress_ && int64_t(f.width) * f.height >= kProgressPixels;
    const int n = bands ? kProgressBands : 1;
    for (int b = 0; b < n; ++b) {
      const int y0 = int(int64_t(f.height) * b / n), y1 = int(int64_t(f.height) * (b + 1) / n);
      tbb::parallel_for(tbb::blocked_range2d<int>(y0, y1, kTile, 0, f.width, kTile), tile);
      if (bands) progress_(double(b + 1) / n);
    }
  }

  void setProgress(std::function<void(double)> progress) override { progress_ = std::move(progress); }
  static constexpr int64_t kProgressPixels = 512 * 512;  ///< smaller frames report nothing
  static constexpr int kProgressBands = 16;
  std::function<void(double)> progress_;

  static constexpr int kPoolBrick = 16;
  int poolBrick_ = kPoolBrick;
  Volume volume_;
  HostPool pool_;
  int64_t budget_ = 0;
  bool overflow_ = false;
  uint64_t generation_ = 0;
  TransferFunction tf_;
  RangeGrid ranges_;
  OccupancyGrid occ_;
  OccupancyGrid hybridGrid_;
  std::vector<uint8_t> dist_;  ///< DistanceGrid's field over occ_
  SubMasks sub_;  ///< sub-brick masks and brick states of occ_ (Classification.h); empty: none
  Tuning tuning_;  ///< setTuning: the sub-brick mask knobs
  bool readVoxels_ = false;    ///< the last classification computed sub-brick masks (lastClassifyReadVoxels)
  bool onlyEmptied_ = false;   ///< the last classify() only emptied bricks (lastClassifyOnlyEmptied)
  Tree tree_;
  TraversalKind traversal_ = TraversalKind::Naive;
  std::vector<vec4f> table_;
  std::vector<float> pairs_;  ///< the table as the SIMD packets read it (packetPairTable)
  float tfLo_ = 0, tfScale_ = 1;
};

}  // namespace

std::unique_ptr<Backend> makeCpuBackend() { return std::make_unique<CpuBackend>(); }

void parallelCopy(void* dst, const void* src, size_t bytes) {
  constexpr size_t kChunk = size_t(1) << 20;
  if (bytes <= kChunk) {
    std::memcpy(dst, src, bytes);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, (bytes + kChunk - 1) / kChunk), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t c = r.begin(); c != r.end(); ++c) {
      const size_t off = c * kChunk;
      std::memcpy(static_cast<char*>(dst) + off, static_cast<const char*>(src) + off, std::min(kChunk, bytes - off));
    }
  });
}

#ifndef SPACESKIP_HAVE_CUDA
namespace {
const char* const kNoCuda = "this build of SpaceSkip has no CUDA backend (configured with SPACESKIP_ENABLE_CUDA=OFF)";
}
std::unique_ptr<Backend> makeCudaBackend() {
  throw BackendError(kNoCuda);
}
bool cudaAvailable(std::string* why) {
  if (why) *why = "built without CUDA";
  return false;
}
int64_t cudaDeviceBytesInUse() { return 0; }
std::shared_ptr<unsigned char> allocatePageLocked(size_t) { return nullptr; }
void* allocatePageLockedRaw(size_t) { return nullptr; }
void freePageLocked(void*) {}
std::vector<uint8_t> computeDistanceFieldCuda(const OccupancyGrid&, int) {
  throw BackendError(kNoCuda);
}
SubMasks computeSubMasksCuda(const Volume&, const TransferFunction&, int, int, size_t*) {
  throw BackendError(kNoCuda);
}

struct DeviceImageCopy::Impl {};
DeviceImageCopy::DeviceImageCopy() = default;
DeviceImageCopy::~DeviceImageCopy() = default;
int DeviceImageCopy::copy(const void*, int, int, void*, int, int, int, int, bool, void*) { return 1; }
int DeviceImageCopy::blendOver(const void*, int, int, void*, int, int, int, int, int, int, int, int, bool, void*) {
  return 1;
}
void DeviceImageCopy::releaseSurface() {}

struct PeerImages::Impl {};
PeerImages::PeerImages() = default;
PeerImages::~PeerImages() = default;
bool PeerImages::share(const void*, size_t, void*, Handle&, std::string& problem) {
  problem = kNoCuda;
  return false;
}
const void* PeerImages::map(int, const Handle&, std::string& problem) {
  problem = kNoCuda;
  return nullptr;
}
bool PeerImages::download(const void*, size_t, float*, std::string& problem) {
  problem = kNoCuda;
  return false;
}
bool PeerImages::wait(void*, std::string& problem) {
  problem = kNoCuda;
  return false;
}
struct PieceBlend::Impl {};
PieceBlend::PieceBlend() = default;
PieceBlend::~PieceBlend() = default;
const void* PieceBlend::blend(const std::vector<BlendSource>&, int, int, float, void*, std::string& problem) {
  problem = kNoCuda;
  return nullptr;
}
#endif

}  // namespace spaceskip

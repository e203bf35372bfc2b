// The CUDA backend: the Backend interface over a device volume (DeviceVolume), its brick
// classification (Classification), the GPU builders, and the render executor (CudaExecutor).
#include "BuildContext.cuh"
#include "Classification.cuh"
#include "CudaExecutor.cuh"
#include "DevicePool.cuh"
#include "DeviceVolume.cuh"
#include "HostStaging.cuh"
#include "spaceskip/StepMemory.h"
#include "DistanceField.cuh"
#include "KdTreeBuilder.cuh"
#include "LbvhBuilder.cuh"
#include "spaceskip/Backend.h"
#include "spaceskip/Builders.h"
#include "spaceskip/DistanceField.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <thread>
#include <utility>
#include <vector>

namespace spaceskip {

namespace {

using cuda::DeviceBuffer;

class CudaBackend final : public Backend {
 public:
  BackendKind kind() const override { return BackendKind::CUDA; }
  const char* name() const override { return "cuda"; }

  void setVolume(const Volume& v, int brick) override {
    const bool haveNext = std::exchange(haveNext_, false);  // consumed here, whatever follows
    validate(v);
    tree_.clear();  // the nodes' storage kept: freeing it would wait for the whole device (a prefetch's copy)
    hostTree_ = Tree{};
    traversal_ = TraversalKind::Naive;
    d_distField_ = nullptr;
    cls_.haveOcc = false;
    pool_.release();
    const int64_t budget = budget_ > 0 ? budget_ : defaultBudget(v, brick);
    if (int64_t(v.byteSize()) <= budget) {
      prefetchedLast_ = takePrefetched(v);
      // The step after it (Engine::prefetchVolume) starts now, into the buffer just swapped out.
      if (prefetchedLast_ && haveNext) (void)prefetchVolume(nextVolume_);
      if (!prefetchedLast_) vol_->upload(v, stream_);
      vol_->setWarp(v, stream_);
      // A rectilinear grid (AxisWarp.h): the virtual lattice's ranges from the host's voxels (the
      // grid's bricks remapped), no sub-brick masks (they read voxels by the lattice's index).
      const RangeGrid warpRanges = v.warp ? computeRangeGrid(v, brick) : RangeGrid{};
      if (v.warp) {
        cls_.setRanges(v, warpRanges, stream_);
      } else {
        cls_.setVolume(*vol_, brick, stream_);
      }
      SS_CUDA_CHECK(cudaStreamSynchronize(stream_));
      inCore_ = ResidencyStats{};
      inCore_.budgetBytes = budget;
      return;
    }
    // Sparse residency (BrickPool.h): the value ranges from the host's voxels, and a pool of
    // the budget's size that each frame fills with the bricks it needs.
    if (v.warp)
      throw BackendError("a rectilinear grid is drawn through its coordinates with the whole grid on the device: " +
                         std::to_string(v.byteSize()) + " bytes exceed the memory budget of " + std::to_string(budget) +
                         " bytes");
    finishPrefetch();
    prefetchedLast_ = false;
    vol_->describe(v);
    vol_->setWarp(v, stream_);
    const RangeGrid ranges = computeRangeGrid(v, brick);
    cls_.setRanges(v, ranges, stream_);
    SS_CUDA_CHECK(cudaStreamSynchronize(stream_));
    pool_.init(v, brick, poolBrick_, budget);
  }

  bool classify(const TransferFunction& tf, const CropClip& cc) override {
    tf_ = tf;
    cls_.editMaskMaxShare = tuning_.partsShare;
    const bool changed = cls_.classify(tf, cc, stream_);
    classifiedSinceRender_ = true;
    // The field kept across an edit that changed no occupancy (or drawn stale after one that only
    // emptied bricks) takes the new states' marks, in render(): an edit that occupies bricks
    // rebuilds the field (which marks it) first, and marking the old one too would only add a
    // kernel to the edit's path.
    distMarksStale_ = true;
    return changed;
  }
  bool classifyLabels(const LabelSets& ls, const std::vector<uint8_t>& drawn, const CropClip& cc) override {
    // Over the label sets on the device (no voxel read; LabelMap.h's rule, as the CPU backend).
    const bool changed = cls_.classifyLabels(ls, drawn, cc, stream_);
    classifiedSinceRender_ = true;
    distMarksStale_ = true;
    return changed;
  }
  double subMaskShare() const override { return cls_.subMasks() ? cls_.setFraction : 1.0; }
  // Sparse residency loads the bricks the current occupancy needs: a structure that visits
  // more would sample bricks that are not resident.
  bool lastClassifyOnlyEmptied() const override { return !cls_.grew && !pool_.active(); }
  double lastClassifyWaitSeconds() const override { return cls_.waitSeconds; }

  void setMemoryBudget(int64_t bytes, int poolBrick) override {
    budget_ = bytes > 0 ? bytes : 0;
    poolBrick_ = poolBrick > 0 ? poolBrick : kPoolBrick;
  }
  ResidencyStats residency() const override { return pool_.active() ? pool_.stats() : inCore_; }

  void setTransferTable(const std::vector<vec4f>& t, float lo, float scale) override {
    exec_.setTransferTable(t, lo, scale, stream_);
  }

  void build(const BuildParams& p, BuildStats& s) override {
    if (!haveOcc_) throw BackendError("CUDA backend: build() before classify()");
    auto t0 = std::chrono::steady_clock::now();
    const BuilderInfo& info = builderInfo(p.builder);
    traversal_ = info.traversal;
    tree_.numNodes = 0;
    tree_.height = 0;
    tree_.leaves = 0;
    hostTree_ = Tree{};
    hybridGridValid_ = false;
    d_distField_ = nullptr;
    s.builtOn = "cuda";
    if (info.extra == BuilderExtra::DistanceField) {
      // Tuning::distanceCap (1..127: bit 7 of the field marks sparse bricks): another cap (the
      // segments' overlaps against the leaps' length).
      const int cap = std::clamp(tuning_.distanceCap, 1, 127);
      d_distField_ =
          cuda::computeDistanceField(d_occ_[cur_].get(), bdims_, cap, dist_, stream_, tuning_.distanceSegments);
      // A field computed from the current occupancy carries no marks until the masks mark some
      // bricks sparse: right after an edit (no masks yet) the mark kernel would change nothing.
      if (cls_.brickStates()) cls_.markDistances(const_cast<uint8_t*>(d_distField_), stream_);
      distMarksStale_ = false;
    }
    if (info.cuda) {
      cuda::BuildContext ctx{{d_occ_[cur_].get(), bdims_, brick_, cellDims_, occupied_}, stream_, tree_, workspaces_};
      info.cuda(ctx, p);
      checkTreeHeight(p.builder, tree_.height);
    } else if (buildsTree(info)) {
      // Host builders on the downloaded occupancy; the tree (and Hybrid's grid) is uploaded.
      const OccupancyGrid& occ = occupancy();
      hostTree_ = buildTreeCPU(occ, p);
      uploadTree(hostTree_);
      if (info.extra == BuilderExtra::CoarseGrid) {
        OccupancyGrid coarse = coarsen(occ, std::max(1, kHybridCell / occ.brick));
        d_hybrid_.reserve(coarse.occ.size());
        SS_CUDA_CHECK(cudaMemcpyAsync(d_hybrid_.get(), coarse.occ.data(), coarse.occ.size(), cudaMemcpyHostToDevice,
                                      stream_));
        hybridDims_ = coarse.dims;
        hybridBrick_ = coarse.brick;
        hybridGridValid_ = true;
      }
      SS_CUDA_CHECK(cudaStreamSynchronize(stream_));
      s.builtOn = "cpu";
    }
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    s.nodes = tree_.numNodes;
    s.height = tree_.height;
    s.leaves = tree_.leaves;
  }

  /// Grid and DistanceGrid frames walk the parts of sparse bricks (GridParts) only where the set
  /// parts are at most this share of the occupied bricks' parts: on the H100 the part walk made
  /// the paper's stand-ins 5-26% slower where the share was 0.28 and more, and N-body
  /// 1024^3 / 2048^3 (shares 0.11 / 0.06) 1.12x / 1.59x faster (docs/results/h100-sub-brick-masks).
  /// Tuning::partsShare (default 0.2).

  void render(FrameView f, FilterMode filter, const float* depth, Image& out) override {
    // Sub-brick masks after an opacity edit: with part ranges (BrickClassification) the
    // classification computed them; without, the edit's own frame marches whole bricks (no
    // voxel mask kernel on the edit's path: 0.59 ms at N-body 2048^3) and the frame after
    // computes them.
    if (classifiedSinceRender_) {
      classifiedSinceRender_ = false;
    } else if (cls_.masksPending()) {
      cls_.refreshMasks(stream_);
      distMarksStale_ = true;
    }
    // Only a field that is drawn with takes marks (a build after the edit may have dropped it).
    if (distMarksStale_ && d_distField_) cls_.markDistances(const_cast<uint8_t*>(d_distField_), stream_);
    distMarksStale_ = false;
    f.traversal = traversal_;
    const double maxShare = tuning_.partsShare;
    const bool parts = traversal_ == TraversalKind::Grid && cls_.subMasks() && cls_.setFraction <= maxShare;
    if (traversal_ == TraversalKind::Hybrid && hybridGridValid_)
      f.grid = GridView{d_hybrid_.get(), hybridDims_, hybridBrick_};
    else if (parts) {
      f.traversal = TraversalKind::GridParts;
      f.grid = GridView{cls_.brickStates(), bdims_, brick_, d_distField_, nullptr, nullptr, cls_.subMasks()};
    } else
      f.grid = GridView{d_occ_[cur_].get(), bdims_, brick_, d_distField_};
    f.tree = TreeView{tree_.nodes.get(), tree_.numNodes};
    // In these modes every skipping builder marches the value ranges (render/Integrator.h, usesValueRanges).
    if (usesValueRanges(f.blend) && traversal_ != TraversalKind::Naive) {
      f.traversal = TraversalKind::Grid;
      f.grid = GridView{nullptr, bdims_, brick_, nullptr, cls_.d_vmin.get(), cls_.d_vmax.get()};
    }
    // Shadow rays skip with the finest structure this classification has, whatever the builder
    // and the frame's own traversal: the parts of sparse bricks where there are masks, and
    // DistanceGrid's leaps where it made them.
    if (scatterSkips(f, traversal_)) {
      const bool masks = cls_.subMasks() && cls_.brickStates();
      f.scatter.occ = GridView{masks ? cls_.brickStates() : d_occ_[cur_].get(), bdims_, brick_, d_distField_, nullptr,
                               nullptr, masks ? cls_.subMasks() : nullptr};
    }
    if (pool_.active() && f.sampling != kSampleTrilinear)
      throw BackendError("nearest and label-map sampling need the whole volume in device memory");
    if (pool_.active())
      pool_.update(poolNeedFor(f.blend, f.shade != 0 || f.gtf.mode != 0, tf_, f.avgLo, f.avgHi), cls_.d_occ[cls_.cur].get(),
                   cls_.generation, cls_.d_vmin.get(), cls_.d_vmax.get(), bdims_, brick_, stream_);
    const PoolView view = pool_.view();
    exec_.render(f, filter, depth, *vol_, pool_.active() ? &view : nullptr, out, stream_);
  }

  ~CudaBackend() override { finishPrefetch(); }

  // Time steps (Engine::prefetchVolume): the next step's voxels go to a second device volume on
  // a copy stream while the current step is drawn; setVolume(next) swaps the two volumes. A
  // pageable step is staged from a host thread (the staging's host copies would otherwise hold
  // the caller); a page-locked one's DMAs are queued from the caller.
  bool prefetchVolume(const Volume& next) override {
    if (prefetchPending_ && prefetchData_ == next.data) return true;  // started by setVolume (setNextVolume)
    finishPrefetch();
    prefetchPending_ = false;
    if (pool_.active() || !next.data || vol_->volume().byteSize() != next.byteSize()) return false;
    const int64_t bytes = int64_t(next.byteSize());
    if (!next_ || next_->volume().byteSize() != next.byteSize()) {
      // A second step on the device: within the budget set, else within the free memory less
      // what defaultBudget keeps back.
      if (budget_ > 0 ? 2 * bytes > budget_ : defaultBudget(next, brick_) < bytes) return false;
      next_ = std::make_unique<cuda::DeviceVolume>();
    }
    if (!copyStream_) copyStream_ = std::make_unique<cuda::Stream>();
    if (!prefetchDone_) prefetchDone_ = std::make_unique<cuda::Event>();
    if (!readersDone_) readersDone_ = std::make_unique<cuda::Event>();
    // The copy overwrites the step drawn before: after the work queued on the render stream.
    SS_CUDA_CHECK(cudaEventRecord(*readersDone_, stream_));
    SS_CUDA_CHECK(cudaStreamWaitEvent(*copyStream_, *readersDone_, 0));
    prefetchOk_ = false;
    prefetchData_ = next.data;
    prefetchPending_ = true;
    // The copy and its event; a failure leaves prefetchOk_ false (setVolume uploads the step itself).
    auto copy = [this](const Volume& v) {
      try {
        next_->upload(v, *copyStream_);
        SS_CUDA_CHECK(cudaEventRecord(*prefetchDone_, *copyStream_));
        prefetchOk_ = true;
      } catch (const std::exception&) {
        (void)cudaGetLastError();
      }
    };
    if (cuda::HostStaging::pageLocked(next.data)) {  // DMAs queued from here: no host copy to run
      copy(next);
      return true;
    }
    int device = 0;
    SS_CUDA_CHECK(cudaGetDevice(&device));
    prefetch_ = std::thread([copy, next, device] {
      if (cudaSetDevice(device) != cudaSuccess) {
        (void)cudaGetLastError();
        return;
      }
      copy(next);
    });
    return true;
  }
  bool lastVolumePrefetched() const override { return prefetchedLast_; }
  void setNextVolume(const Volume* next) override {
    haveNext_ = next != nullptr;
    nextVolume_ = next ? *next : Volume{};
  }

  bool setImageOnDevice(bool on) override { return exec_.setImageOnDevice(on); }
  const void* deviceImage() const override { return exec_.deviceImage(); }
  DeviceImageView deviceImageView() const override { return exec_.deviceImageView(); }
  void* deviceImageStream() const override {
    return exec_.hasDeviceImage() ? static_cast<void*>(static_cast<cudaStream_t>(stream_)) : nullptr;
  }
  void setTuning(const Tuning& t) override {
    tuning_ = t;
    exec_.setTuning(t);
    cls_.tuning = t;
  }
  double lastFrameDeviceSeconds() const override { return exec_.lastFrameDeviceSeconds(); }
  int64_t lastFrameQueuedShadowRays() const override { return exec_.lastFrameQueuedShadowRays(); }
  double lastFrameLongestBlockSeconds() const override { return exec_.lastFrameLongestBlockSeconds(); }
  bool brickValueRange(double& lo, double& hi) override {
    return !pool_.active() && cls_.valueRange(lo, hi, stream_);
  }
  UploadRates measureUpload(size_t bytes) override {
    DeviceBuffer<unsigned char> dst(bytes);
    std::vector<unsigned char> pageable(bytes, 1);
    cuda::PinnedBuffer pinned;
    pinned.reserve(bytes);
    std::memset(pinned.get(), 1, bytes);
    cuda::HostStaging staging;
    auto best = [&](auto&& copy) {
      double t = 1e30;
      for (int i = 0; i < 3; ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        copy();
        SS_CUDA_CHECK(cudaStreamSynchronize(stream_));
        t = std::min(t, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
      return t > 0 ? double(bytes) / t : 0.0;
    };
    UploadRates r;
    r.pinned = best([&] { SS_CUDA_CHECK(cudaMemcpyAsync(dst.get(), pinned.get(), bytes, cudaMemcpyHostToDevice, stream_)); });
    r.pageable = best([&] { SS_CUDA_CHECK(cudaMemcpyAsync(dst.get(), pageable.data(), bytes, cudaMemcpyHostToDevice, stream_)); });
    r.staged = best([&] { staging.copy(dst.get(), pageable.data(), bytes, stream_); });
    return r;
  }

  const OccupancyGrid& occupancy() override { return cls_.occupancy(stream_); }
  double occupiedFraction() override {
    return cls_.numBricks() ? double(cls_.occupied) / double(cls_.numBricks()) : 0.0;
  }

  Tree tree() override {
    Tree t;
    if (tree_.numNodes > 0) {
      t.nodes.resize(size_t(tree_.numNodes));
      SS_CUDA_CHECK(cudaMemcpyAsync(t.nodes.data(), tree_.nodes.get(), t.nodes.size() * sizeof(Node),
                                    cudaMemcpyDeviceToHost, stream_));
      SS_CUDA_CHECK(cudaStreamSynchronize(stream_));
    }
    t.height = tree_.height;
    t.leaves = tree_.leaves;
    return t;
  }

 private:
  /// Free device memory at setVolume, less what the rest of the backend may need (value
  /// ranges, occupancy, distance field, sub-brick masks and trees: 40 bytes per brick) and 1 GiB for images,
  /// textures' conversions and the builders' workspaces.
  static int64_t defaultBudget(const Volume& v, int brick) {
    size_t freeBytes = 0, total = 0;
    if (cudaMemGetInfo(&freeBytes, &total) != cudaSuccess) {
      (void)cudaGetLastError();
      return INT64_MAX;  // unknown: try in core (an allocation failure falls back to the CPU)
    }
    const vec3i cd = v.cellDims();
    const int b = std::max(1, brick);
    const int64_t bricks = int64_t((cd.x + b - 1) / b) * ((cd.y + b - 1) / b) * ((cd.z + b - 1) / b);
    const int64_t limit = cuda::deviceMemoryLimit();  // the testing cap, when set
    int64_t avail = int64_t(freeBytes) + cuda::liveDeviceBytes().load();
    if (limit >= 0) avail = std::min(avail, limit);
    return std::max<int64_t>(0, avail - bricks * 40 - (int64_t(1) << 30));
  }

  /// Waits for a prefetch's host thread (its copies may still be in flight on the copy stream).
  void finishPrefetch() {
    if (prefetch_.joinable()) prefetch_.join();
  }
  /// Whether `v` is the prefetched step: then the stream waits for its copies and it becomes the
  /// volume drawn (the volume drawn before keeps its allocation for the next prefetch).
  bool takePrefetched(const Volume& v) {
    finishPrefetch();
    prefetchPending_ = false;
    if (!prefetchOk_ || !next_ || v.data != prefetchData_ || next_->volume().byteSize() != v.byteSize()) return false;
    prefetchOk_ = false;
    SS_CUDA_CHECK(cudaStreamWaitEvent(stream_, *prefetchDone_, 0));
    std::swap(vol_, next_);
    return true;
  }

  void uploadTree(const Tree& t) {
    tree_.numNodes = int(t.nodes.size());
    tree_.height = t.height;
    tree_.leaves = t.leaves;
    if (t.nodes.empty()) return;
    tree_.nodes.reserve(t.nodes.size());
    SS_CUDA_CHECK(cudaMemcpyAsync(tree_.nodes.get(), t.nodes.data(), t.nodes.size() * sizeof(Node),
                                  cudaMemcpyHostToDevice, stream_));
  }

  cuda::Stream stream_;  // first: made first, destroyed last
  std::unique_ptr<cuda::DeviceVolume> vol_ = std::make_unique<cuda::DeviceVolume>();
  // Prefetched time steps (prefetchVolume): the second volume, its copy stream and host thread.
  std::unique_ptr<cuda::DeviceVolume> next_;
  std::unique_ptr<cuda::Stream> copyStream_;
  std::unique_ptr<cuda::Event> prefetchDone_;
  std::thread prefetch_;
  std::unique_ptr<cuda::Event> readersDone_;  ///< the render stream's work before a prefetch's copy
  bool prefetchOk_ = false;       ///< set by the thread before it ends (read after join)
  bool prefetchPending_ = false;  ///< a prefetch of prefetchData_ started and not taken yet
  bool haveNext_ = false;         ///< setNextVolume: the step after the next setVolume's
  Volume nextVolume_;
  const void* prefetchData_ = nullptr;
  bool prefetchedLast_ = false;   ///< the last setVolume took the prefetched step
  cuda::DevicePool pool_;
  int64_t budget_ = 0;       ///< setMemoryBudget (0: defaultBudget)
  ResidencyStats inCore_;    ///< residency() of an in-core volume
  TransferFunction tf_;      ///< the last classify()'s TF (the pool's MIP/MinIP rule reads it)
  static constexpr int kPoolBrick = 16;
  int poolBrick_ = kPoolBrick;
  cuda::BrickClassification cls_;
  cuda::CudaExecutor exec_;
  Tuning tuning_;  ///< setTuning (the executor and the classification hold copies)
  // The classification under the names build() reads (until the builder registry replaces its switch).
  DeviceBuffer<uint8_t> (&d_occ_)[2] = cls_.d_occ;
  const int& cur_ = cls_.cur;
  const bool& haveOcc_ = cls_.haveOcc;
  const int& brick_ = cls_.brick;
  const vec3i &cellDims_ = cls_.cellDims, &bdims_ = cls_.bdims;
  const int64_t& occupied_ = cls_.occupied;
  // What the builders leave for the render.
  TraversalKind traversal_ = TraversalKind::Naive;
  cuda::DeviceTree tree_;
  Tree hostTree_;
  cuda::WorkspaceStore workspaces_;  ///< the device builders' workspaces (BuildContext)
  DeviceBuffer<uint8_t> d_hybrid_;
  vec3i hybridDims_{0, 0, 0};
  int hybridBrick_ = 16;
  bool hybridGridValid_ = false;
  cuda::DistanceWorkspace dist_;
  const uint8_t* d_distField_ = nullptr;  ///< DistanceGrid's field (in dist_) for the current occupancy
  bool classifiedSinceRender_ = false;     ///< classify() ran since the last render()
  bool distMarksStale_ = false;            ///< d_distField_'s marks (if any) predate the brick states
};

}  // namespace

bool cudaAvailable(std::string* why) {
  int n = 0;
  cudaError_t e = cudaGetDeviceCount(&n);
  if (e != cudaSuccess) {
    (void)cudaGetLastError();
    if (why) *why = std::string("no usable CUDA device (") + cudaGetErrorName(e) + ": " + cudaGetErrorString(e) + ")";
    return false;
  }
  if (n == 0) {
    if (why) *why = "no CUDA device found";
    return false;
  }
  if (why) why->clear();
  return true;
}

int64_t cudaDeviceBytesInUse() { return cuda::liveDeviceBytes().load(); }

void* allocatePageLockedRaw(size_t bytes) {
  void* p = nullptr;
  if (bytes > 0 && cudaMallocHost(&p, bytes) == cudaSuccess) return p;
  (void)cudaGetLastError();
  return nullptr;
}

void freePageLocked(void* p) {
  if (p) cudaFreeHost(p);
}

std::shared_ptr<unsigned char> allocatePageLocked(size_t bytes) {
  void* p = allocatePageLockedRaw(bytes);
  if (!p) return nullptr;
  return std::shared_ptr<unsigned char>(static_cast<unsigned char*>(p), [](unsigned char* q) { freePageLocked(q); });
}

std::unique_ptr<Backend> makeCudaBackend() {
  std::string why;
  if (!cudaAvailable(&why)) throw BackendError(why);
  return std::make_unique<CudaBackend>();
}

}  // namespace spaceskip

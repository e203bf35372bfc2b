// Sparse residency: a volume cut into pool bricks of which only those the frame can need are
// held in a pool (device memory for the CUDA backend), found through a per-brick table.
// The rules here are shared by the host and the device (SS_FUNC): which pool bricks a frame
// needs (from classification's per-brick occupancy and value ranges, the blend mode and the
// gradient's reach), how a sample finds its voxels (PoolSampler, bit-identical to
// ArraySampler), and the host-side bookkeeping (BrickResidency: slots, LRU eviction, uploads).
// See DESIGN.md "Sparse residency".
#pragma once
#include "Classification.h"
#include "TransferFunction.h"
#include "Volume.h"
#include "render/Integrator.h"  // ArraySampler, voxelValue

#include <cstdint>
#include <string>
#include <vector>

namespace spaceskip {

/// The volume cut into pool bricks of `brick` cells per axis (a multiple of classification's
/// brick), each stored as (brick+1)^3 voxels: its cells plus the +1 apron a trilinear sample
/// reads (clamped at the volume's far faces). Brick (x,y,z) has index x + bdims.x*(y + bdims.y*z).
struct PoolLayout {
  int brick = 32;
  vec3l dims{0, 0, 0};  ///< voxels of the volume
  vec3i bdims{0, 0, 0};  ///< pool bricks per axis

  SS_FUNC int64_t count() const { return int64_t(bdims.x) * bdims.y * bdims.z; }
  SS_FUNC int64_t edge() const { return int64_t(brick) + 1; }
  /// Voxels one slot holds.
  SS_FUNC int64_t slotVoxels() const { return edge() * edge() * edge(); }
};

/// The layout for a volume of `dims` voxels classified in bricks of `classBrick` cells: pool
/// bricks of the multiple of classBrick nearest to `poolBrick` (at least classBrick).
PoolLayout makePoolLayout(vec3l dims, int classBrick, int poolBrick = 32);

/// What a frame needs resident, per classification brick (BlendMode decides; poolNeedFor()):
/// Occupancy: the brick is occupied (composite, slice, additive: a sample can have opacity);
/// Above: its largest value exceeds `lo` (MIP: below lo every value is transparent, so a
/// brick wholly below cannot decide a visible maximum); Below: its smallest value is under `hi`
/// (MinIP); Inside: its range meets [lo, hi] (average intensity); All: every brick (isosurface,
/// whose crossings between bricks read values the ranges do not bound).
/// `reach` cells around a needed brick are needed too: 1 when shading (the gradient's central
/// differences sample one voxel beyond the sample).
enum class PoolNeed : int { Occupancy, Above, Below, Inside, All };
struct PoolNeedRule {
  PoolNeed need = PoolNeed::Occupancy;
  float lo = 0, hi = 0;
  int reach = 0;
  bool operator==(const PoolNeedRule& o) const {
    return need == o.need && lo == o.lo && hi == o.hi && reach == o.reach;
  }
  bool operator!=(const PoolNeedRule& o) const { return !(*this == o); }
};

/// Is classification brick i (occupancy byte, value range [vmin, vmax]) needed under `r`?
/// A brick of NaN only (vmin > vmax) is never needed: its samples are NaN, i.e. transparent.
SS_FUNC bool classBrickNeeded(const PoolNeedRule& r, uint8_t occ, float vmin, float vmax) {
  switch (r.need) {
    case PoolNeed::Occupancy: return occ != 0;
    case PoolNeed::Above: return vmin <= vmax && vmax > r.lo;
    case PoolNeed::Below: return vmin <= vmax && vmin < r.hi;
    case PoolNeed::Inside: return vmin <= vmax && vmax >= r.lo && vmin <= r.hi;
    case PoolNeed::All: return vmin <= vmax;
  }
  return true;
}

/// Pool brick p of `L` is needed when a classification brick (of `cbrick` cells, `cdims` per
/// axis, arrays indexed x fastest) within its cells widened by r.reach on each side is needed.
/// One CUDA thread per pool brick runs it as it is; the host loops over it (oneTBB).
SS_FUNC bool poolBrickNeeded(int64_t p, const PoolLayout& L, vec3i cdims, int cbrick, const uint8_t* occ,
                             const float* vmin, const float* vmax, const PoolNeedRule& r) {
  const int64_t px = p % L.bdims.x, py = (p / L.bdims.x) % L.bdims.y, pz = p / (int64_t(L.bdims.x) * L.bdims.y);
  const int64_t P[3] = {px, py, pz};
  const int64_t cd[3] = {cdims.x, cdims.y, cdims.z};
  int64_t lo[3], hi[3];  // classification bricks [lo, hi] overlapping the widened cells
  for (int a = 0; a < 3; ++a) {
    int64_t c0 = P[a] * L.brick - r.reach, c1 = (P[a] + 1) * L.brick - 1 + r.reach;  // cells, inclusive
    c0 = c0 < 0 ? 0 : c0;
    lo[a] = c0 / cbrick;
    hi[a] = c1 / cbrick;
    hi[a] = hi[a] > cd[a] - 1 ? cd[a] - 1 : hi[a];
  }
  for (int64_t z = lo[2]; z <= hi[2]; ++z)
    for (int64_t y = lo[1]; y <= hi[1]; ++y)
      for (int64_t x = lo[0]; x <= hi[0]; ++x) {
        const int64_t i = x + cd[0] * (y + cd[1] * z);
        if (classBrickNeeded(r, occ ? occ[i] : uint8_t(1), vmin[i], vmax[i])) return true;
      }
  return false;
}

/// The rule a frame of blend mode `mode` (shaded or not) needs, for the TF whose opacity
/// classification used (`tf`, in sampled units).
PoolNeedRule poolNeedFor(BlendMode mode, bool shade, const TransferFunction& tf, float avgLo, float avgHi);

/// The value PoolSampler gives a non-resident sample under rule `r`: MIP's bound `r.lo` (every
/// non-needed brick lies at or below it, and it maps to no opacity), MinIP's `r.hi`, else NaN.
SS_FUNC float poolFill(const PoolNeedRule& r) {
  if (r.need == PoolNeed::Above && r.lo > -INFINITY && r.lo < INFINITY) return r.lo;
  if (r.need == PoolNeed::Below && r.hi > -INFINITY && r.hi < INFINITY) return r.hi;
  return NAN;
}

/// Exact trilinear sampling through the pool: the same voxels and arithmetic as ArraySampler
/// (Integrator.h), so a resident sample is bit-identical to the in-core one. A sample whose
/// pool brick is not resident (table entry < 0) reads `fill` (poolFill): NaN, transparent and
/// not counted, or for MIP (MinIP) the rule's bound, a value every non-resident sample is at
/// most (at least) and that maps to no opacity, so the running maximum (minimum) lets the
/// value-range traversal skip the empty bricks as in core; the residency rule guarantees that
/// such a sample cannot change the image.
template <class T>
struct PoolSampler {
  const T* pool;          ///< slots of (brick+1)^3 voxels, x fastest
  const int32_t* table;   ///< pool brick -> slot, -1 when not resident
  int64_t nx, ny, nz;     ///< voxels of the volume
  int brick;
  int bx, by;             ///< pool bricks along x and y
  float fill;             ///< the value of a non-resident sample

  SS_FUNC float sample(vec3f p) const {
    int64_t x0, x1, y0, y1, z0, z1;
    float fx, fy, fz;
    ArraySampler<T>::axis(p.x, nx, x0, x1, fx);
    ArraySampler<T>::axis(p.y, ny, y0, y1, fy);
    ArraySampler<T>::axis(p.z, nz, z0, z1, fz);
    const int64_t Px = x0 / brick, Py = y0 / brick, Pz = z0 / brick;
    const int32_t slot = table[Px + int64_t(bx) * (Py + int64_t(by) * Pz)];
    if (slot < 0) return fill;
    const int64_t e = int64_t(brick) + 1;
    const T* d = pool + int64_t(slot) * e * e * e;
    // Local voxel indices: x1 - x0 is 0 or 1 and x0 - Px*brick < brick, so all lie in the slot.
    const int64_t lx0 = x0 - Px * brick, lx1 = lx0 + (x1 - x0);
    const int64_t ly0 = y0 - Py * brick, ly1 = ly0 + (y1 - y0);
    const int64_t lz0 = z0 - Pz * brick, lz1 = lz0 + (z1 - z0);
    auto fetch = [&](int64_t i, int64_t j, int64_t k) { return voxelValue(d[i + e * (j + e * k)]); };
    return trilinear(fetch, lx0, lx1, ly0, ly1, lz0, lz1, fx, fy, fz);
  }
};

/// A pool as the render kernels read it: plain pointers (device or host) and the layout.
struct PoolView {
  const void* pool = nullptr;
  const int32_t* table = nullptr;
  vec3l dims{0, 0, 0};
  int brick = 0;
  vec3i bdims{0, 0, 0};
  float fill = NAN;
  template <class T>
  PoolSampler<T> sampler() const {
    return PoolSampler<T>{static_cast<const T*>(pool), table, dims.x, dims.y, dims.z, brick, bdims.x, bdims.y, fill};
  }
};

/// Copies pool brick p's (brick+1)^3 voxels (x fastest; indices past the volume's far faces
/// clamped to the last voxel) from `v` (one component, of type T) into dst.
template <class T>
void gatherBrick(const Volume& v, const PoolLayout& L, int64_t p, T* dst) {
  const T* src = static_cast<const T*>(v.data);
  const int64_t e = L.edge();
  const int64_t x0 = (p % L.bdims.x) * L.brick, y0 = ((p / L.bdims.x) % L.bdims.y) * L.brick,
                z0 = (p / (int64_t(L.bdims.x) * L.bdims.y)) * L.brick;
  for (int64_t k = 0; k < e; ++k) {
    const int64_t z = z0 + k < v.dims.z ? z0 + k : v.dims.z - 1;
    for (int64_t j = 0; j < e; ++j) {
      const int64_t y = y0 + j < v.dims.y ? y0 + j : v.dims.y - 1;
      const T* line = src + v.dims.x * (y + v.dims.y * z);
      T* out = dst + e * (j + e * k);
      const int64_t run = x0 + e <= v.dims.x ? e : v.dims.x - x0;  // in-volume voxels of the row
      for (int64_t i = 0; i < run; ++i) out[i] = line[x0 + i];
      for (int64_t i = run; i < e; ++i) out[i] = line[v.dims.x - 1];
    }
  }
}

/// Gathers the pool bricks `bricks` into dst (slot after slot, in that order), in parallel.
void gatherBricks(const Volume& v, const PoolLayout& L, const int64_t* bricks, size_t n, void* dst);

/// Host-side residency bookkeeping of a pool of `capacity` slots: which pool brick lives in
/// which slot, and which to upload or evict when the needed set changes. Bricks no longer
/// needed stay resident while slots allow (evicted least recently needed first), so a TF edit
/// that brings them back costs no upload.
class BrickResidency {
 public:
  void reset(int64_t bricks, int64_t capacity);
  /// What a needed set asks of the pool before update(): bricks needed, of those not
  /// resident, and free slots.
  struct Demand {
    int64_t needed = 0, missing = 0, free = 0;
  };
  Demand demand(const uint8_t* needed) const;
  /// More slots (>= capacity()); the new ones are free.
  void grow(int64_t capacity);
  /// What update() decided: uploads (brick, slot) sorted by slot; `fits` false when the needed
  /// bricks exceed the capacity (then nothing changed).
  struct Plan {
    std::vector<int64_t> bricks;  ///< to upload, in slot order
    std::vector<int32_t> slots;
    int64_t needed = 0;
    int64_t evicted = 0;
    bool fits = true;
  };
  /// `needed[p]` != 0 for the pool bricks the next frame needs.
  Plan update(const uint8_t* needed);
  /// Pool brick -> slot (-1: not resident): the table the sampler reads.
  const std::vector<int32_t>& table() const { return table_; }
  int64_t capacity() const { return capacity_; }
  int64_t resident() const { return resident_; }
  int64_t bricks() const { return int64_t(table_.size()); }

 private:
  std::vector<int32_t> table_;
  std::vector<int64_t> owner_;     ///< slot -> pool brick, -1 when free
  std::vector<uint64_t> lastUsed_; ///< pool brick -> last update() that needed it
  uint64_t epoch_ = 0;
  int64_t capacity_ = 0, resident_ = 0;
};

/// The pool in host memory: the CPU backend's sparse residency (under an explicit budget), the
/// same rules and bookkeeping as the device pool, so CI checks them end to end without a GPU.
class HostPool {
 public:
  void init(const Volume& v, int classBrick, int poolBrick, int64_t budgetBytes);
  void release() { *this = HostPool(); }
  bool active() const { return active_; }
  /// As DevicePool::update, over host arrays (`occ`, ranges of `cbrick`-cell bricks); throws
  /// std::runtime_error when the needed bricks exceed the pool.
  void update(const PoolNeedRule& r, const uint8_t* occ, uint64_t generation, const float* vmin, const float* vmax,
              vec3i cdims, int cbrick);
  PoolView view() const {
    return PoolView{pool_.data(), res_.table().data(), vol_.dims, layout_.brick, layout_.bdims, poolFill(rule_)};
  }
  const ResidencyStats& stats() const { return stats_; }

 private:
  bool active_ = false;
  Volume vol_;
  PoolLayout layout_;
  BrickResidency res_;
  std::vector<double> pool_;  ///< slots (double-aligned for every voxel type)
  int64_t maxCapacity_ = 0;
  std::vector<uint8_t> needed_;
  PoolNeedRule rule_;
  uint64_t generation_ = ~uint64_t(0);
  bool valid_ = false;
  ResidencyStats stats_;
};

/// Pool capacity (slots) a budget allows for `v` in layout `L`: at most one per pool brick.
int64_t poolCapacity(const Volume& v, const PoolLayout& L, int64_t budgetBytes);
/// The capacity a pool of `capacity` slots (at most `maxCapacity`, the budget's) grows to for
/// demand `d`: unchanged when the missing bricks fit its free slots; else twice as large, or
/// the needed bricks plus a quarter, or what the missing bricks need, whichever is largest,
/// within the budget (beyond it the least recently needed bricks are evicted). Pools grow with
/// what the views need: memory is taken only for what a render needs, and bricks a later edit
/// may bring back stay cached while the budget allows.
int64_t grownCapacity(const BrickResidency::Demand& d, int64_t capacity, int64_t maxCapacity);
/// The statistics of a freshly laid out pool (no slots yet; `maxCapacity` the budget's).
ResidencyStats poolStats(const Volume& v, const PoolLayout& L, int64_t maxCapacity, int64_t budgetBytes);
/// The message when a frame's needed bricks exceed the pool.
std::string poolOverflowMessage(const Volume& v, const PoolLayout& L, int64_t needed, int64_t budgetBytes);

}  // namespace spaceskip

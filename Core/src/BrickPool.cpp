// Sparse residency on the host: the pool layout, the rule a frame's blend mode needs, brick
// gathering (oneTBB) and the slot bookkeeping with LRU eviction (BrickPool.h).
#include "spaceskip/BrickPool.h"
#include "spaceskip/PoolPlan.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <initializer_list>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace spaceskip {

PoolLayout makePoolLayout(vec3l dims, int classBrick, int poolBrick) {
  if (classBrick < 1) throw std::invalid_argument("pool layout: classification brick must be positive");
  PoolLayout L;
  const int k = std::max(1, (poolBrick + classBrick / 2) / classBrick);
  L.brick = classBrick * k;
  L.dims = dims;
  auto bricksAlong = [&](int64_t n) {
    const int64_t cells = n > 1 ? n - 1 : 1;
    return int((cells + L.brick - 1) / L.brick);
  };
  L.bdims = vec3i{bricksAlong(dims.x), bricksAlong(dims.y), bricksAlong(dims.z)};
  return L;
}

PoolNeedRule poolNeedFor(BlendMode mode, bool shade, const TransferFunction& tf, float avgLo, float avgHi) {
  PoolNeedRule r;
  r.reach = shade ? 1 : 0;
  switch (mode) {
    case BlendMode::Composite:
    case BlendMode::Slice:
    case BlendMode::Additive:  // a transparent sample adds opacity * value = 0
      r.need = PoolNeed::Occupancy;
      return r;
    case BlendMode::AverageIntensity:
      r.need = PoolNeed::Inside;
      r.lo = avgLo;
      r.hi = avgHi;
      return r;
    case BlendMode::MaximumIntensity:
    case BlendMode::MinimumIntensity: {
      // The lookup blends entries floor(x) and floor(x)+1 of x = (v - lo) * scale: a value is
      // visible only when x > first - 1 (x < last + 1), first (last) being the first (last)
      // entry with opacity; one more entry absorbs float rounding.
      const int size = int(tf.table.size());
      int first = -1, last = -1;
      for (int i = 0; i < size; ++i)
        if (tf.table[size_t(i)].w > 0.f) {
          if (first < 0) first = i;
          last = i;
        }
      float lo = 0, scale = 1;
      tableMapping(tf, size, lo, scale);
      if (mode == BlendMode::MaximumIntensity) {
        r.need = PoolNeed::Above;
        r.lo = first < 0 ? INFINITY : first <= 1 ? -INFINITY : float(double(lo) + double(first - 2) / double(scale));
      } else {
        r.need = PoolNeed::Below;
        r.hi = last < 0 ? -INFINITY
                        : last >= size - 1 ? INFINITY : float(double(lo) + double(last + 2) / double(scale));
      }
      return r;
    }
    default: r.need = PoolNeed::All; return r;  // isosurface
  }
}

void gatherBricks(const Volume& v, const PoolLayout& L, const int64_t* bricks, size_t n, void* dst) {
  if (v.components != 1) throw std::invalid_argument("gatherBricks: one component only");
  dispatchVoxelType(v.type, [&](auto t) {
    using T = decltype(t);
    T* out = static_cast<T*>(dst);
    const int64_t slot = L.slotVoxels();
    tbb::parallel_for(size_t(0), n, [&](size_t i) { gatherBrick<T>(v, L, bricks[i], out + int64_t(i) * slot); });
  });
}

void BrickResidency::reset(int64_t bricks, int64_t capacity) {
  if (bricks < 0 || capacity < 0) throw std::invalid_argument("BrickResidency: negative size");
  capacity = std::min<int64_t>(capacity, int64_t(INT32_MAX));
  table_.assign(size_t(bricks), -1);
  lastUsed_.assign(size_t(bricks), 0);
  owner_.assign(size_t(capacity), -1);
  epoch_ = 0;
  capacity_ = capacity;
  resident_ = 0;
}

BrickResidency::Demand BrickResidency::demand(const uint8_t* needed) const {
  Demand d;
  for (int64_t p = 0; p < bricks(); ++p)
    if (needed[p]) {
      ++d.needed;
      if (table_[size_t(p)] < 0) ++d.missing;
    }
  d.free = capacity_ - resident_;
  return d;
}

void BrickResidency::grow(int64_t capacity) {
  capacity = std::min<int64_t>(capacity, int64_t(INT32_MAX));
  if (capacity <= capacity_) return;
  owner_.resize(size_t(capacity), -1);
  capacity_ = capacity;
}

int64_t grownCapacity(const BrickResidency::Demand& d, int64_t capacity, int64_t maxCapacity) {
  if (d.missing <= d.free) return capacity;
  const int64_t want = std::max({2 * capacity, d.needed + d.needed / 4, capacity + d.missing - d.free});
  return std::max(capacity, std::min(want, maxCapacity));
}

BrickResidency::Plan BrickResidency::update(const uint8_t* needed) {
  Plan plan;
  const int64_t n = bricks();
  ++epoch_;
  std::vector<int64_t> missing;
  for (int64_t p = 0; p < n; ++p) {
    if (!needed[p]) continue;
    ++plan.needed;
    if (table_[size_t(p)] < 0) missing.push_back(p);
  }
  if (plan.needed > capacity_) {
    plan.fits = false;
    return plan;
  }
  for (int64_t p = 0; p < n; ++p)
    if (needed[p]) lastUsed_[size_t(p)] = epoch_;
  // Free slots first, then the least recently needed resident bricks the frame does not need.
  std::vector<int32_t> freeSlots;
  for (int64_t s = 0; s < capacity_ && freeSlots.size() < missing.size(); ++s)
    if (owner_[size_t(s)] < 0) freeSlots.push_back(int32_t(s));
  if (freeSlots.size() < missing.size()) {
    std::vector<int32_t> victims;
    for (int64_t s = 0; s < capacity_; ++s) {
      const int64_t p = owner_[size_t(s)];
      if (p >= 0 && lastUsed_[size_t(p)] != epoch_) victims.push_back(int32_t(s));
    }
    const size_t want = missing.size() - freeSlots.size();
    std::partial_sort(victims.begin(), victims.begin() + std::min(want, victims.size()), victims.end(),
                      [&](int32_t a, int32_t b) {
                        return lastUsed_[size_t(owner_[size_t(a)])] < lastUsed_[size_t(owner_[size_t(b)])];
                      });
    for (size_t i = 0; i < want; ++i) {  // plan.needed <= capacity: enough victims exist
      const int32_t s = victims[i];
      table_[size_t(owner_[size_t(s)])] = -1;
      owner_[size_t(s)] = -1;
      --resident_;
      ++plan.evicted;
      freeSlots.push_back(s);
    }
  }
  std::sort(freeSlots.begin(), freeSlots.end());
  plan.bricks.reserve(missing.size());
  plan.slots.reserve(missing.size());
  for (size_t i = 0; i < missing.size(); ++i) {
    const int32_t s = freeSlots[i];
    table_[size_t(missing[i])] = s;
    owner_[size_t(s)] = missing[i];
    ++resident_;
    plan.bricks.push_back(missing[i]);
    plan.slots.push_back(s);
  }
  return plan;
}

int64_t poolCapacity(const Volume& v, const PoolLayout& L, int64_t budgetBytes) {
  const int64_t slotBytes = L.slotVoxels() * int64_t(voxelSize(v.type));
  return std::min<int64_t>(L.count(), std::max<int64_t>(0, budgetBytes / slotBytes));
}

ResidencyStats poolStats(const Volume& v, const PoolLayout& L, int64_t maxCapacity, int64_t budgetBytes) {
  ResidencyStats s;
  s.sparse = true;
  s.poolBrick = L.brick;
  s.bricks = L.count();
  s.maxCapacity = maxCapacity;
  s.budgetBytes = budgetBytes;
  (void)v;
  return s;
}

std::string poolOverflowMessage(const Volume& v, const PoolLayout& L, int64_t needed, int64_t budgetBytes) {
  const double mib = double(1 << 20);
  const double bytes = double(needed) * double(L.slotVoxels()) * double(voxelSize(v.type));
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "the bricks this view needs (%lld of %lld pool bricks, %.0f MiB) exceed the memory budget (%.0f MiB)",
                (long long)needed, (long long)L.count(), bytes / mib, double(budgetBytes) / mib);
  return buf;
}

void HostPool::init(const Volume& v, int classBrick, int poolBrick, int64_t budgetBytes) {
  release();
  if (v.components != 1) throw std::invalid_argument("sparse residency holds one-component volumes only");
  vol_ = v;
  layout_ = makePoolLayout(v.dims, classBrick, poolBrick);
  maxCapacity_ = poolCapacity(v, layout_, budgetBytes);
  res_.reset(layout_.count(), 0);
  pool_.clear();
  needed_.assign(size_t(layout_.count()), 0);
  stats_ = poolStats(v, layout_, maxCapacity_, budgetBytes);
  active_ = true;
}

void HostPool::update(const PoolNeedRule& r, const uint8_t* occ, uint64_t generation, const float* vmin,
                      const float* vmax, vec3i cdims, int cbrick) {
  if (!beginPoolUpdate(valid_, rule_, generation_, r, generation, stats_)) return;
  const auto t0 = std::chrono::steady_clock::now();
  const int64_t n = layout_.count();
  tbb::parallel_for(int64_t(0), n, [&](int64_t p) {
    needed_[size_t(p)] = poolBrickNeeded(p, layout_, cdims, cbrick, occ, vmin, vmax, r) ? 1 : 0;
  });
  valid_ = false;  // until the uploads are done
  const BrickResidency::Plan plan = planPoolUpdate(
      res_, needed_.data(), maxCapacity_, vol_, layout_, stats_,
      [&](int64_t slots) {
        const size_t bytes = size_t(slots * layout_.slotVoxels()) * voxelSize(vol_.type);
        pool_.resize((bytes + sizeof(double) - 1) / sizeof(double), 0.0);  // keeps the resident slots
        return true;
      },
      [](const std::string& m) { throw std::runtime_error(m); });
  dispatchVoxelType(vol_.type, [&](auto t) {
    using T = decltype(t);
    T* pool = reinterpret_cast<T*>(pool_.data());
    const int64_t slot = layout_.slotVoxels();
    tbb::parallel_for(size_t(0), plan.bricks.size(), [&](size_t i) {
      gatherBrick<T>(vol_, layout_, plan.bricks[i], pool + int64_t(plan.slots[i]) * slot);
    });
  });
  rule_ = r;
  generation_ = generation;
  valid_ = true;
  finishPoolUpdate(res_, plan, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), stats_);
}

bool beginPoolUpdate(bool valid, const PoolNeedRule& lastRule, uint64_t lastGeneration, const PoolNeedRule& r,
                     uint64_t generation, ResidencyStats& stats) {
  stats.uploaded = stats.evicted = 0;
  stats.updateSeconds = 0;
  return !(valid && r == lastRule && (r.need != PoolNeed::Occupancy || generation == lastGeneration));
}

BrickResidency::Plan planPoolUpdate(BrickResidency& res, const uint8_t* needed, int64_t maxCapacity, const Volume& v,
                                    const PoolLayout& L, ResidencyStats& stats,
                                    const std::function<bool(int64_t)>& grow,
                                    const std::function<void(const std::string&)>& overflow) {
  const BrickResidency::Demand demand = res.demand(needed);
  stats.needed = demand.needed;
  if (demand.needed > maxCapacity) overflow(poolOverflowMessage(v, L, demand.needed, stats.budgetBytes));
  const int64_t cap = grownCapacity(demand, res.capacity(), maxCapacity);
  if (cap > res.capacity()) {
    if (grow(cap)) res.grow(cap);
    else if (demand.needed > res.capacity()) overflow(poolOverflowMessage(v, L, demand.needed, stats.budgetBytes));
  }
  const int64_t slotBytes = L.slotVoxels() * int64_t(voxelSize(v.type));
  stats.capacity = res.capacity();
  stats.poolBytes = res.capacity() * slotBytes;
  BrickResidency::Plan plan = res.update(needed);
  if (!plan.fits) overflow(poolOverflowMessage(v, L, plan.needed, stats.budgetBytes));
  return plan;
}

void finishPoolUpdate(const BrickResidency& res, const BrickResidency::Plan& plan, double seconds,
                      ResidencyStats& stats) {
  stats.uploaded = int64_t(plan.bricks.size());
  stats.evicted = plan.evicted;
  stats.resident = res.resident();
  stats.updateSeconds = seconds;
}

}  // namespace spaceskip

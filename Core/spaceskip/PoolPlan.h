// The residency step both pools share (HostPool in host memory, cuda::DevicePool on the device):
// the needed set's demand against the budget, the pool's growth, the LRU plan and the statistics.
// The pools keep only what differs: how the needed set is computed, how storage grows, how
// bricks are uploaded.
#pragma once
#include "BrickPool.h"

#include <functional>
#include <string>

namespace spaceskip {

/// Starts a frame's residency update: clears the last frame's upload figures in `stats` and
/// says whether anything is to do: not when the last update (`valid`) was for the same rule and,
/// for the occupancy rule, the same classification `generation` (the value-range rules depend on
/// the volume's ranges only).
bool beginPoolUpdate(bool valid, const PoolNeedRule& lastRule, uint64_t lastGeneration, const PoolNeedRule& r,
                     uint64_t generation, ResidencyStats& stats);

/// Plans the update for `needed` (one byte per pool brick of `L`). `overflow(message)` is called,
/// and must throw, when the needed bricks exceed `maxCapacity` (the budget's slots) or a pool
/// that could not grow. `grow(slots)` is asked for a larger pool when grownCapacity says so; it
/// returns false when the storage cannot grow (the pool then stays and evicts). Fills `stats`'
/// needed, capacity and poolBytes; the plan's uploads are the caller's to do.
BrickResidency::Plan planPoolUpdate(BrickResidency& res, const uint8_t* needed, int64_t maxCapacity, const Volume& v,
                                    const PoolLayout& L, ResidencyStats& stats,
                                    const std::function<bool(int64_t)>& grow,
                                    const std::function<void(const std::string&)>& overflow);

/// The statistics of an update whose uploads are done, which took `seconds`.
void finishPoolUpdate(const BrickResidency& res, const BrickResidency::Plan& plan, double seconds,
                      ResidencyStats& stats);

}  // namespace spaceskip

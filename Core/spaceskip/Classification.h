// Conservative classification: per-brick value ranges (once per volume) and per-brick
// occupancy (once per opacity edit). See DESIGN.md "Conservative classification".
#pragma once
#include "CropClip.h"
#include "TransferFunction.h"
#include "Tuning.h"
#include "Volume.h"

#include <cstdint>
#include <type_traits>
#include <vector>

namespace spaceskip {

/// Min/max of the voxels a trilinear sample inside each brick of `brick`^3 cells can touch
/// (of the opacity channel with dependent components, which alone decides what is empty):
/// cells [b*B, (b+1)*B) use voxels [b*B, (b+1)*B] (the +1 halo). NaN voxels are skipped
/// (a sample touching one is NaN, which the integrator treats as transparent).
struct RangeGrid {
  int brick = 8;
  vec3i cellDims{0, 0, 0};
  vec3i dims{0, 0, 0};  ///< bricks per axis
  std::vector<float> vmin, vmax;

  int64_t size() const { return int64_t(dims.x) * dims.y * dims.z; }
  int64_t index(int x, int y, int z) const { return x + int64_t(dims.x) * (y + int64_t(dims.y) * z); }
  /// Cell-space box of brick (x,y,z), clamped to the volume.
  box3i brickBox(int x, int y, int z) const;
};

/// Voxels [v0, v1] along an axis of n voxels that brick b's cells [b*B, (b+1)*B) read: the +1
/// halo of trilinear sampling, clamped.
SS_FUNC void brickVoxelSpan(int64_t b, int brick, int64_t n, int64_t& v0, int64_t& v1) {
  v0 = b * brick;
  v1 = v0 + brick < n - 1 ? v0 + brick : n - 1;
}

/// Folds voxels line[x0..x1] into [lo, hi], skipping NaN. `NC` > 1: interleaved tuples of NC
/// components, `line` already points at the wanted component (dependent components: the opacity
/// channel), so voxel x is line[x * NC].
template <class T, int NC = 1>
SS_FUNC void foldRange(const T* line, int64_t x0, int64_t x1, float& lo, float& hi) {
  float l = lo, h = hi;
  for (int64_t x = x0; x <= x1; ++x) {
    const float v = float(line[x * NC]);
    if (v != v) continue;  // NaN
    l = v < l ? v : l;
    h = v > h ? v : h;
  }
  lo = l;
  hi = h;
}

/// RangeGrid's rule for brick (bx, by, bz) of a volume of `dims` voxels at `data`: min/max over
/// its voxels with the +1 halo, NaN skipped; (+inf, -inf) when all are NaN. One CUDA thread per
/// brick runs it as it is; the oneTBB twin folds the same spans in line order, one pass per row.
/// `NC` > 1: tuples of NC components, the last (the opacity channel) is the one ranged.
template <class T, int NC = 1>
SS_FUNC void brickRange(const T* data, vec3l dims, int brick, int64_t bx, int64_t by, int64_t bz, float& lo,
                        float& hi) {
  int64_t x0, x1, y0, y1, z0, z1;
  brickVoxelSpan(bx, brick, dims.x, x0, x1);
  brickVoxelSpan(by, brick, dims.y, y0, y1);
  brickVoxelSpan(bz, brick, dims.z, z0, z1);
  lo = INFINITY;
  hi = -INFINITY;
  for (int64_t z = z0; z <= z1; ++z)
    for (int64_t y = y0; y <= y1; ++y)
      foldRange<T, NC>(data + (dims.x * (y + dims.y * z)) * NC + (NC - 1), x0, x1, lo, hi);
}

/// Calls f(std::integral_constant<int, NC>()) for a volume's component count (1, 2 or 4).
template <class F>
decltype(auto) dispatchComponents(int components, F&& f) {
  switch (components) {
    case 2: return f(std::integral_constant<int, 2>());
    case 4: return f(std::integral_constant<int, 4>());
    default: break;
  }
  return f(std::integral_constant<int, 1>());
}

/// Parallel (oneTBB) computation of the range grid. A warped volume (AxisWarp.h): the virtual
/// lattice's bricks, each the union of the grid's bricks its samples read (remapRangeGrid).
RangeGrid computeRangeGrid(const Volume& v, int brick = 8);

/// The range grid of warp `w`'s virtual lattice from the range grid `grid` of the grid's own
/// index space (the same point counts and brick size): virtual brick b's range is the union of
/// the ranges of the grid bricks holding the cells that samples in b read (AxisWarp::cellSpan),
/// so that it bounds every sample inside b, as a brick's range does for an image.
RangeGrid remapRangeGrid(const RangeGrid& grid, const AxisWarp& w);

/// One byte per brick: 1 when some sample inside can have opacity > 0 and be drawn.
struct OccupancyGrid {
  int brick = 8;
  vec3i cellDims{0, 0, 0};
  vec3i dims{0, 0, 0};
  std::vector<uint8_t> occ;
  int64_t occupied = 0;

  int64_t size() const { return int64_t(dims.x) * dims.y * dims.z; }
  int64_t index(int x, int y, int z) const { return x + int64_t(dims.x) * (y + int64_t(dims.y) * z); }
  bool at(int x, int y, int z) const { return occ[size_t(index(x, y, z))] != 0; }
  box3i brickBox(int x, int y, int z) const;
  double occupancy() const { return size() ? double(occupied) / double(size()) : 0.0; }
};

/// Brick `i` (x fastest) of the grid: occupied when its value range can have opacity > 0 under
/// `rmq` and a drawn sample can lie in it (brickMayBeDrawn). Both backends classify with this.
template <class RangeMax>
SS_FUNC bool brickOccupied(int64_t i, float vmin, float vmax, const RangeMax& rmq, vec3i dims, int brick,
                           vec3i cellDims, const CropClip& cc) {
  if (!(rmq.query(vmin, vmax) > 0.f)) return false;
  if (!cc.active()) return true;
  const vec3i b{int(i % dims.x), int((i / dims.x) % dims.y), int(i / (int64_t(dims.x) * dims.y))};
  return brickMayBeDrawn(brickCellBox(b, brick, cellDims), cc);
}

/// Re-classifies bricks (never voxels) against the TF's opacity and what cropping and clipping
/// leave drawn (oneTBB).
OccupancyGrid classify(const RangeGrid& ranges, const TransferFunction& tf, const CropClip& cc = CropClip{});

/// Sub-brick masks: each occupied brick split into kSubPerAxis^3 = 64 parts of brick/4 cells a
/// side, one bit each (x fastest), set when some sample inside the part can have opacity > 0:
/// the brick rule (brickRange's +1 halo, OpacityRangeMaxView::query) on the part's own voxels.
/// The grid traversal GridPartsIter walks an occupied brick's parts and marches only the set
/// ones, so a brick that a few particles touch costs the samples of those parts, not of the
/// whole brick. Recomputed after every opacity edit (the CUDA backend on the frame after the
/// edit's), for the occupied bricks only;
/// only where a brick has 4 parts of >= 2 cells a side (brick 8, 12, 16, ...), one component,
/// the voxels in core.
/// (kSubPerAxis and usesSubMasks: Types.h, which the render headers read.)

/// Part k (x fastest, 0..63) of brick (bx, by, bz) of `brick` cells in a volume of `dims`
/// voxels (`cellDims` cells): can a sample inside it have opacity > 0? `voxel(x, y, z)` gives
/// a voxel's value as float (global indices). NaN voxels are skipped, as in brickRange. A part
/// with no cell inside the volume: false.
/// Whether part k of brick (bx, by, bz) has a cell of the volume (else its bit is never set).
SS_FUNC bool subPartInVolume(vec3i cellDims, int brick, int64_t bx, int64_t by, int64_t bz, int k) {
  const int s = brick / kSubPerAxis;
  return bx * brick + (k & 3) * s < cellDims.x && by * brick + ((k >> 2) & 3) * s < cellDims.y &&
         bz * brick + (k >> 4) * s < cellDims.z;
}

/// The value range [lo, hi] of part k's voxels (its cells with the +1 halo, clamped), NaN
/// skipped ((+inf, -inf) when all are NaN); false for a part with no cell of the volume.
/// `voxel(x, y, z)` gives a voxel's value as float (global indices).
template <class Voxel>
SS_FUNC bool subPartRangeWith(const Voxel& voxel, vec3l dims, vec3i cellDims, int brick, int64_t bx, int64_t by,
                              int64_t bz, int k, float& lo, float& hi) {
  lo = INFINITY;
  hi = -INFINITY;
  if (!subPartInVolume(cellDims, brick, bx, by, bz, k)) return false;
  const int s = brick / kSubPerAxis;
  const int64_t c0[3] = {bx * brick + (k & 3) * s, by * brick + ((k >> 2) & 3) * s, bz * brick + (k >> 4) * s};
  const int64_t n[3] = {dims.x, dims.y, dims.z};
  int64_t v1[3];
  for (int a = 0; a < 3; ++a) v1[a] = c0[a] + s < n[a] - 1 ? c0[a] + s : n[a] - 1;
  for (int64_t z = c0[2]; z <= v1[2]; ++z)
    for (int64_t y = c0[1]; y <= v1[1]; ++y)
      for (int64_t x = c0[0]; x <= v1[0]; ++x) {
        const float v = voxel(x, y, z);
        if (v != v) continue;  // NaN
        lo = v < lo ? v : lo;
        hi = v > hi ? v : hi;
      }
  return true;
}

template <class Voxel, class RangeMax>
SS_FUNC bool subPartSetWith(const Voxel& voxel, vec3l dims, vec3i cellDims, int brick, int64_t bx, int64_t by, int64_t bz,
                            int k, const RangeMax& rmq) {
  float lo, hi;
  return subPartRangeWith(voxel, dims, cellDims, brick, bx, by, bz, k, lo, hi) && rmq.query(lo, hi) > 0.f;
}

/// subPartRangeWith on the voxels of a volume in memory.
template <class T>
SS_FUNC bool subPartRange(const T* data, vec3l dims, vec3i cellDims, int brick, int64_t bx, int64_t by, int64_t bz, int k,
                          float& lo, float& hi) {
  auto voxel = [&](int64_t x, int64_t y, int64_t z) { return float(data[x + dims.x * (y + dims.y * z)]); };
  return subPartRangeWith(voxel, dims, cellDims, brick, bx, by, bz, k, lo, hi);
}

/// subPartSetWith on the voxels of a volume in memory.
template <class T, class RangeMax>
SS_FUNC bool subPartSet(const T* data, vec3l dims, vec3i cellDims, int brick, int64_t bx, int64_t by, int64_t bz, int k,
                        const RangeMax& rmq) {
  auto voxel = [&](int64_t x, int64_t y, int64_t z) { return float(data[x + dims.x * (y + dims.y * z)]); };
  return subPartSetWith(voxel, dims, cellDims, brick, bx, by, bz, k, rmq);
}

/// The mask of brick (bx, by, bz): subPartSet of its 64 parts. One CUDA warp computes it two
/// parts a lane; the oneTBB twin one brick at a time.
template <class T, class RangeMax>
SS_FUNC uint64_t subBrickMask(const T* data, vec3l dims, vec3i cellDims, int brick, int64_t bx, int64_t by, int64_t bz,
                              const RangeMax& rmq) {
  uint64_t mask = 0;
  for (int k = 0; k < kSubPerAxis * kSubPerAxis * kSubPerAxis; ++k)
    if (subPartSet(data, dims, cellDims, brick, bx, by, bz, k, rmq)) mask |= uint64_t(1) << k;
  return mask;
}

/// Walking a brick's parts pays where few are set (particles); where many are, the walk costs
/// more than the samples it saves (measured on the H100: docs/results/h100-sub-brick-masks). So each
/// occupied brick gets a state byte: kBrickWhole (march it whole) or kBrickParts (walk the set
/// parts of its mask), the latter when at most `maxSet` of the 64 parts are set. Bit 7 marks
/// "parts" in the state and in DistanceGrid's field alike (distances are <= kMaxSkipDistance),
/// so the traversal learns it from the byte it reads anyway and loads the mask only then.
constexpr uint8_t kBrickEmpty = 0, kBrickWhole = 1, kBrickParts = kBrickPartsBit | 1;  // kBrickPartsBit: Types.h
SS_FUNC int popcount64(uint64_t m) {
#ifdef __CUDA_ARCH__
  return __popcll(m);
#else
  return __builtin_popcountll(m);
#endif
}
SS_FUNC uint8_t subBrickState(bool occupied, uint64_t mask, int maxSet) {
  return !occupied ? kBrickEmpty : popcount64(mask) <= maxSet ? kBrickParts : kBrickWhole;
}
/// DistanceGrid's byte for a brick at distance `dist` (its field) in `state`: an occupied brick
/// (distance 0) walks its parts when its state says so, or when it is empty now (a field built
/// before an edit that emptied it: its mask is 0, so nothing of it is marched).
SS_FUNC uint8_t markedDistance(uint8_t dist, uint8_t state) {
  const uint8_t d = uint8_t(dist & 0x7f);
  return d == 0 && (state == kBrickEmpty || (state & kBrickPartsBit)) ? uint8_t(kBrickPartsBit) : d;
}

/// The masks and states of `occ` (one per brick, x fastest) for the voxels of `v` and `tf`
/// (oneTBB); empty when `t.subMasks` or usesSubMasks(occ.brick) is false or `v` has several
/// components.
struct SubMasks {
  std::vector<uint64_t> mask;
  std::vector<uint8_t> state;
  double share = 1.0;  ///< set parts over all parts of the occupied bricks
};
SubMasks computeSubMasks(const Volume& v, const OccupancyGrid& occ, const TransferFunction& tf,
                         const Tuning& t = Tuning{});
/// The CUDA backend's masks for `v` classified against `tf` at `brick` (tests): `path` 0 from the
/// voxels (the next frame's kernel), 1 from the part ranges stored at setVolume in the
/// classification, 2 from them on the next frame (*rangeBytes says what they take, 0 when none
/// are stored: then the voxels). Throws BackendError without a device.
SubMasks computeSubMasksCuda(const Volume& v, const TransferFunction& tf, int brick, int path,
                             size_t* rangeBytes = nullptr);
/// The most set parts a brick may have to be walked part by part (subBrickState):
/// Tuning::subMaskMaxSet clamped to 0..64. The default 40 of 64: on the H100 1.02-1.06x kernel
/// fps over 24 where frames walk parts, N-body 1024^3 and 2048^3, the other stand-ins unchanged;
/// the oneTBB frames of the 11 stand-ins at 1/8 scale 0.99-1.11x, geometric mean 1.05, in
/// adjacent processes (docs/results/h100-tf-edit).
inline int subMaskMaxSet(const Tuning& t) { return t.subMaskMaxSet < 0 ? 0 : t.subMaskMaxSet > 64 ? 64 : t.subMaskMaxSet; }

}  // namespace spaceskip

// Label maps (segmentations): integer voxels are label ids, each label drawn with its own colour
// and opacity, values without a label transparent. Sampling never invents a label
// (render/LabelSampler.h); skipping keeps per brick the set of labels its samples can read, so a
// label's visibility or opacity edit re-classifies bricks over those sets, never voxels.
#pragma once
#include "Classification.h"
#include "CropClip.h"
#include "TransferFunction.h"
#include "Volume.h"

#include <cstdint>
#include <vector>

namespace spaceskip {

// LabelSampling (Types.h): how a label map is sampled.

/// One label: its id (the voxel value), colour, opacity (per unit distance, as a TF's) and
/// visibility.
struct Label {
  int id = 0;
  float r = 1, g = 1, b = 1;
  float opacity = 1;
  bool visible = true;
};

/// The labels a label map is drawn with; voxel values without an entry are transparent. A later
/// entry for the same id replaces an earlier one.
struct LabelTable {
  std::vector<Label> labels;
  double unitDistance = 1;  ///< the distance `opacity` is accumulated over (world units)
  bool operator==(const LabelTable& o) const;
  bool operator!=(const LabelTable& o) const { return !(*this == o); }
};

/// Whether voxels of this type can be label ids (8- and 16-bit integers).
inline bool isLabelType(VoxelType t) {
  return t == VoxelType::UInt8 || t == VoxelType::Int8 || t == VoxelType::UInt16 || t == VoxelType::Int16;
}

/// Per brick (RangeGrid's bricks, x fastest) the sorted distinct values of the voxels its samples
/// can read: cells [b*B, (b+1)*B) with the +1 halo (brickVoxelSpan), which holds the nearest voxel
/// and all 8 corners of any sample inside. Values as indices value - lo into [lo, hi], the
/// volume's value range. CSR: brick i's labels are labels[offset[i] .. offset[i+1]).
struct LabelSets {
  int brick = 8;
  vec3i cellDims{0, 0, 0};
  vec3i dims{0, 0, 0};  ///< bricks per axis
  int lo = 0, hi = -1;  ///< the volume's value range (hi < lo: no volume)
  std::vector<int64_t> offset;
  std::vector<uint16_t> labels;
  int64_t size() const { return int64_t(dims.x) * dims.y * dims.z; }
  int valueCount() const { return hi >= lo ? hi - lo + 1 : 0; }
};

/// One pass over the voxels of a one-component volume of isLabelType (oneTBB). Throws
/// std::invalid_argument for other volumes.
LabelSets computeLabelSets(const Volume& v, int brick = 8);

/// Brick `i` is occupied when some label in its set is drawn (drawn[label index] != 0) and a drawn
/// sample can lie in it (brickMayBeDrawn). O(labels in the brick), no voxel read.
SS_FUNC bool brickLabelsOccupied(int64_t i, const int64_t* offset, const uint16_t* labels, const uint8_t* drawn,
                                 vec3i dims, int brick, vec3i cellDims, const CropClip& cc) {
  bool any = false;
  for (int64_t k = offset[i]; k < offset[i + 1] && !any; ++k) any = drawn[labels[k]] != 0;
  if (!any) return false;
  if (!cc.active()) return true;
  const vec3i b{int(i % dims.x), int((i / dims.x) % dims.y), int(i / (int64_t(dims.x) * dims.y))};
  return brickMayBeDrawn(brickCellBox(b, brick, cellDims), cc);
}

/// The occupancy of `s` for the per-value flags `drawn` (valueCount() of them), oneTBB.
OccupancyGrid classifyLabels(const LabelSets& s, const std::vector<uint8_t>& drawn, const CropClip& cc = CropClip{});

/// Per value in [s.lo, s.hi]: 1 when `t` has a visible label of opacity > 0 with that id.
std::vector<uint8_t> drawnLabels(const LabelTable& t, int lo, int hi);

/// The transfer function a label map is drawn with: one entry per value in [lo, hi] (rangeMin lo,
/// rangeMax hi, so entry x = v - lo exactly), the label's colour and opacity where it is visible,
/// else transparent. The integrator reads it with labelLookup (no blend between entries).
TransferFunction labelTransferFunction(const LabelTable& t, int lo, int hi);

}  // namespace spaceskip

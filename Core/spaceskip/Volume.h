// A uniform-grid scalar volume: 64-bit dims, voxel type, spacing/origin/direction.
#pragma once
#include "AxisWarp.h"
#include "Math.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace spaceskip {

enum class VoxelType : int { UInt8, Int8, UInt16, Int16, Float32, Float64 };

size_t voxelSize(VoxelType t);
const char* voxelTypeName(VoxelType t);
/// Parses "uint8", "int16", "float", "float32", "double", ... ; returns false if unknown.
bool parseVoxelType(const std::string& s, VoxelType& out);

/// The one switch over voxel types: calls f(T()) with T the C++ type of `t` (uint8_t, int8_t,
/// uint16_t, int16_t, float, double) and returns what it returns.
template <class F>
decltype(auto) dispatchVoxelType(VoxelType t, F&& f) {
  switch (t) {
    case VoxelType::UInt8: break;
    case VoxelType::Int8: return f(int8_t());
    case VoxelType::UInt16: return f(uint16_t());
    case VoxelType::Int16: return f(int16_t());
    case VoxelType::Float32: return f(float());
    case VoxelType::Float64: return f(double());
  }
  return f(uint8_t());
}

/// Host volume. Either owns its voxels (`storage`) or borrows a caller's buffer (`data`).
/// Voxel (i,j,k) lives at i + dims.x*(j + dims.y*k) with 64-bit arithmetic.
/// With `components` > 1 the voxels are interleaved tuples (component c of voxel n at
/// n*components + c) rendered as vtkVolumeProperty's dependent components
/// (IndependentComponentsOff): 2 = colour value + opacity value, 4 = RGB + opacity value; the
/// last component is always the one opacity (and so classification) reads. With a 2-D transfer
/// function (TransferFunction::table2D), 2 = its x value + its y value (a second array).
struct Volume {
  vec3l dims{0, 0, 0};
  VoxelType type = VoxelType::UInt8;
  double spacing[3] = {1, 1, 1};
  double origin[3] = {0, 0, 0};
  /// Row-major 3x3 direction matrix (VTK's vtkImageData::GetDirectionMatrix layout).
  double direction[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const void* data = nullptr;
  std::shared_ptr<std::vector<unsigned char>> storage;
  int components = 1;  ///< 1, 2 or 4 (see above; validate() refuses others)
  /// A rectilinear grid's coordinates (AxisWarp.h), or none: a uniform image. With a warp,
  /// spacing/origin/direction describe the virtual lattice over the grid's bounds and the
  /// voxels are the grid's points; one component.
  std::shared_ptr<const AxisWarp> warp;

  int64_t voxelCount() const { return dims.x * dims.y * dims.z; }
  size_t byteSize() const { return size_t(voxelCount()) * size_t(components) * voxelSize(type); }
  /// The component opacity and classification read: the last one.
  int opacityComponent() const { return components - 1; }
  /// Number of cells per axis. An axis of one voxel gets one cell of constant value, so that
  /// 1xNxM volumes render as a slab one spacing thick instead of vanishing.
  vec3i cellDims() const;
  /// Index space -> world (origin + direction * (index * spacing)).
  mat4 indexToWorld() const;
  /// World-space corners of the rendered box.
  void worldBounds(double bounds[6]) const;
  double value(int64_t i, int64_t j, int64_t k) const;
  /// Finite min/max of the voxels (NaN and +-Inf skipped); false if no finite voxel exists.
  /// With several components: over all of them.
  bool scalarRange(double& lo, double& hi) const;
  /// The same over component `c` only.
  bool componentRange(int c, double& lo, double& hi) const;
  /// Allocates owned storage of dims*voxelSize bytes (zeroed). Throws std::runtime_error when a
  /// dimension is not positive or the byte count overflows 64 bits (see checkedByteSize).
  void allocate(vec3l d, VoxelType t, int components = 1);
  unsigned char* mutableData() { return storage ? storage->data() : nullptr; }
};

/// Throws std::runtime_error on bad dims (non-positive, > 2^30 voxels per axis, or a voxel or
/// byte count that overflows 64 bits), missing data, non-positive/non-finite spacing, or a
/// component count other than 1, 2 or 4.
void validate(const Volume& v);

/// Largest axis length any volume may have (cell indices are 32-bit in the traversals).
constexpr int64_t kMaxAxisVoxels = int64_t(1) << 30;

/// Default cap on a volume's voxel bytes for readers and generators: min(64 GiB, physical
/// memory). Callers raise or lower it through ReadLimits::maxBytes (the CLI: --max-volume-bytes
/// or SPACESKIP_MAX_VOLUME_BYTES, Core/cli/Environment.h).
uint64_t defaultMaxVolumeBytes();

/// dims.x*dims.y*dims.z*voxelSize(t), checked: throws std::runtime_error starting with `what`
/// when a dimension is not positive or exceeds kMaxAxisVoxels, the product overflows 64 bits,
/// or it exceeds maxBytes (the message names the cap and how to raise it).
uint64_t checkedByteSize(vec3l dims, VoxelType t, uint64_t maxBytes, const std::string& what);

/// Min/max of `count` values of type `t` at `data`, every `stride`-th one (a component of
/// interleaved tuples), in one oneTBB pass: the finite values only (`finiteOnly`), else every
/// value but NaN (vtkDataArray::GetRange's rule; GetFiniteRange's is the former). False when no
/// value counts (lo > hi then).
bool valueRange(VoxelType t, const void* data, int64_t count, int64_t stride, bool finiteOnly, double& lo,
                double& hi);

}  // namespace spaceskip

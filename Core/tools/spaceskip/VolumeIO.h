// Reading and writing volumes: Open SciVis raw naming (name_XxYxZ_type.raw) and NRRD.
#pragma once
#include "spaceskip/Volume.h"

#include <cstdint>
#include <istream>
#include <string>

namespace spaceskip {

/// What a reader accepts before it allocates anything (README, "Input files"). Every claimed
/// size is checked for overflow, against maxBytes, and against the bytes actually present.
struct ReadLimits {
  uint64_t maxBytes = defaultMaxVolumeBytes();  ///< voxel bytes of one volume
  size_t maxHeaderLine = 4096;                  ///< bytes of one NRRD header line
  size_t maxHeaderBytes = size_t(1) << 20;      ///< bytes of a whole NRRD header
};

/// Loads a .raw (dims and type parsed from the file name) or a .nrrd/.nhdr file.
/// Throws std::runtime_error with a message naming the file and the problem (and the field).
/// Only regular files are read (no devices or pipes); trailing bytes after the voxels are an error.
Volume loadVolume(const std::string& path, const ReadLimits& limits = ReadLimits{});
Volume loadRaw(const std::string& path, const ReadLimits& limits = ReadLimits{});
Volume loadNrrd(const std::string& path, const ReadLimits& limits = ReadLimits{});

/// Parses "name_256x256x128_uint8.raw" style names; returns false when the name does not match
/// (including numbers that do not fit 64 bits). Dims are not range-checked: see checkedByteSize.
bool parseRawName(const std::string& fileName, vec3l& dims, VoxelType& type);
/// The raw reader on a stream holding exactly `available` bytes; `name` gives dims and type.
Volume readRaw(std::istream& in, uint64_t available, const std::string& name, const ReadLimits& limits);

/// A parsed NRRD header (fields may come in any order; interpreted after the blank line).
struct NrrdHeader {
  vec3l dims{1, 1, 1};
  VoxelType type = VoxelType::UInt8;
  bool bigEndian = false;
  double spacing[3] = {1, 1, 1};
  double origin[3] = {0, 0, 0};
  double direction[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::string dataFile;     ///< detached data ("data file:"), empty when attached
  uint64_t headerBytes = 0; ///< bytes up to and including the blank line (attached data starts here)
  uint64_t voxelBytes = 0;  ///< checked dims * voxel size, <= limits.maxBytes
};
/// Reads the header from `in` (positioned at the magic line); `name` is used in messages.
NrrdHeader readNrrdHeader(std::istream& in, const std::string& name, const ReadLimits& limits);
/// Reads the voxels that `h` describes from `in`, which must hold exactly h.voxelBytes of the
/// `available` bytes left (fewer: "too short", more: "trailing bytes"); nothing is allocated before.
Volume readNrrdData(const NrrdHeader& h, std::istream& in, uint64_t available, const std::string& name);

void saveNrrd(const Volume& v, const std::string& path);
void saveRaw(const Volume& v, const std::string& path);

}  // namespace spaceskip

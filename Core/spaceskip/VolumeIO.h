// Reading and writing volumes: Open SciVis raw naming (name_XxYxZ_type.raw) and NRRD.
#pragma once
#include "Volume.h"

#include <string>

namespace spaceskip {

/// Loads a .raw (dims and type parsed from the file name) or a .nrrd file.
/// Throws std::runtime_error with a message naming the file and the problem.
Volume loadVolume(const std::string& path);
Volume loadRaw(const std::string& path);
Volume loadNrrd(const std::string& path);
/// Parses "name_256x256x128_uint8.raw" style names; returns false when the name does not match.
bool parseRawName(const std::string& fileName, vec3l& dims, VoxelType& type);
void saveNrrd(const Volume& v, const std::string& path);
void saveRaw(const Volume& v, const std::string& path);

}  // namespace spaceskip

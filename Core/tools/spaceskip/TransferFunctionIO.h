// Transfer-function text files (optional "range LO HI", "size N", "unit U" lines, then
// "value r g b a" lines), read with bounded input.
#pragma once
#include "spaceskip/TransferFunction.h"

#include <cstdint>
#include <istream>
#include <string>

namespace spaceskip {

/// Bounds on a transfer-function file: nothing in it can make the reader loop or allocate much.
struct TFReadLimits {
  size_t maxLine = 4096;                    ///< bytes per line
  uint64_t maxFileBytes = uint64_t(16) << 20;  ///< bytes of the whole file
  int maxTableSize = 1 << 16;               ///< "size N" entries
  size_t maxPoints = size_t(1) << 16;       ///< control points
};

/// Parses the text format: '#' comments, optional "range LO HI", "size N", "unit U" lines, then
/// "value r g b a" lines (all finite; r g b a in [0, 1]); each line exactly its fields.
/// Throws std::runtime_error "NAME:LINE: ..." on any error.
TransferFunction readTransferFunction(std::istream& in, const std::string& name, double lo, double hi,
                                      const TFReadLimits& limits = TFReadLimits{});
/// The same from a regular file (devices and pipes are refused).
TransferFunction loadTransferFunction(const std::string& path, double lo, double hi,
                                      const TFReadLimits& limits = TFReadLimits{});

}  // namespace spaceskip

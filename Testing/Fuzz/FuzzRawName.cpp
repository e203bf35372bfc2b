// libFuzzer harness: raw volume names (NAME_XxYxZ_TYPE.raw) and the size check against the bytes.
#include "FuzzCommon.h"
#include "spaceskip/VolumeIO.h"

#include <sstream>
#include <stdexcept>

using namespace spaceskip;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider p(data, size);
  std::string name;
  if (p.ConsumeBool()) {
    // Structured: dims from edge values, so products that overflow are reached at once.
    static const char* const types[] = {"uint8", "int8", "uint16", "int16", "float32", "float64", "float", "double",
                                        "uchar", "complex", ""};
    name = p.ConsumeRandomLengthString(16) + "_" + fuzz::edgeInteger(p) + "x" + fuzz::edgeInteger(p) + "x" +
           fuzz::edgeInteger(p) + "_" + types[p.ConsumeIntegralInRange<size_t>(0, 10)] +
           (p.ConsumeIntegralInRange(0, 15) ? ".raw" : "");
  } else {
    name = p.ConsumeRandomLengthString(128);
  }
  const std::string bytes = p.ConsumeRemainingBytesAsString();
  vec3l dims;
  VoxelType type;
  // Digits only: a parsed name never has a negative axis (0 parses, and must not load below).
  if (parseRawName(name, dims, type) && (dims.x < 0 || dims.y < 0 || dims.z < 0)) __builtin_trap();
  ReadLimits limits;
  limits.maxBytes = fuzz::kFuzzMaxBytes;
  std::istringstream in(bytes);
  try {
    Volume v = readRaw(in, bytes.size(), name, limits);
    // Accepted: the claimed size must be exactly the bytes present.
    if (!fuzz::sizeMatches(v.dims.x, v.dims.y, v.dims.z, voxelSize(v.type), bytes.size())) __builtin_trap();
  } catch (const std::runtime_error&) {
    // A clear error is the expected outcome for most inputs.
  }
  return 0;
}

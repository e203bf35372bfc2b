// libFuzzer harness: NRRD headers and attached data, from memory (readNrrdHeader/readNrrdData).
#include "FuzzCommon.h"
#include "spaceskip/VolumeIO.h"

#include <sstream>
#include <utility>
#include <vector>
#include <stdexcept>

using namespace spaceskip;

namespace {
const char* pick(FuzzedDataProvider& p, const char* const* list, size_t n) {
  return list[p.ConsumeIntegralInRange<size_t>(0, n - 1)];
}
#define SS_PICK(p, list) pick(p, list, sizeof(list) / sizeof(list[0]))

/// A value for any field: edge integers, reals, vectors, keywords or free text.
std::string anyValue(FuzzedDataProvider& p) {
  static const char* const words[] = {"uint8", "uchar", "int16", "unsigned short int", "float", "double", "int32",
                                      "block", "raw", "gzip", "ascii", "little", "big", "LIST", "domain", "none",
                                      "RAS", "left-posterior-superior", "cell", "node", "domain domain domain",
                                      "RGB-color domain domain", "domain vector domain", "stub domain domain"};
  std::string v;
  const int count = p.ConsumeIntegralInRange(0, 4);
  switch (p.ConsumeIntegralInRange(0, 4)) {
    case 0:
      for (int k = 0; k < count; ++k) v += (k ? " " : "") + fuzz::edgeInteger(p);
      break;
    case 1:
      for (int k = 0; k < count; ++k) v += (k ? " " : "") + fuzz::edgeReal(p);
      break;
    case 2:
      for (int k = 0; k < count; ++k)
        v += (k ? " (" : "(") + fuzz::edgeReal(p) + "," + fuzz::edgeReal(p) + "," + fuzz::edgeReal(p) + ")";
      break;
    case 3: v = SS_PICK(p, words); break;
    default: v = p.ConsumeRandomLengthString(32); break;
  }
  return v;
}

/// A header that is valid but for a few choices: the required fields (each sometimes left out)
/// with sizes from edge values, in random order, plus random extra fields, duplicates and
/// unknown ones. Reaches the size rules (overflow, cap, bytes present) far more often than
/// random bytes, which seldom assemble four consistent fields.
std::string structuredHeader(FuzzedDataProvider& p) {
  static const char* const types[] = {"uint8", "uchar", "signed char", "int16", "short", "unsigned short int",
                                      "float", "double", "int32", "block"};
  static const char* const fields[] = {"dimension", "type", "sizes", "encoding", "endian", "spacings",
                                       "space directions", "space origin", "space dimension", "space",
                                       "data file", "datafile", "byte skip", "line skip", "kinds", "content",
                                       "centers", "labels", "unknown field", "key", "SIZES", "block size"};
  const int dim = p.ConsumeIntegralInRange(1, 3);
  const int sizeCount = p.ConsumeIntegralInRange(0, 7) ? dim : p.ConsumeIntegralInRange(0, 4);
  std::string sizes;
  for (int k = 0; k < sizeCount; ++k) sizes += (k ? " " : "") + (p.ConsumeBool() ? fuzz::edgeInteger(p) : std::to_string(p.ConsumeIntegralInRange(1, 16)));
  std::vector<std::string> lines = {
      "dimension: " + (p.ConsumeIntegralInRange(0, 15) ? std::to_string(dim) : fuzz::edgeInteger(p)),
      std::string("type: ") + SS_PICK(p, types), "sizes: " + sizes,
      std::string("encoding: ") + (p.ConsumeIntegralInRange(0, 15) ? "raw" : "gzip"),
      std::string("endian: ") + (p.ConsumeBool() ? "little" : "big")};
  for (auto it = lines.begin(); it != lines.end();)
    it = p.ConsumeIntegralInRange(0, 15) == 0 ? lines.erase(it) : it + 1;  // sometimes missing
  const int extra = p.ConsumeIntegralInRange(0, 4);
  for (int i = 0; i < extra; ++i)
    lines.push_back(std::string(SS_PICK(p, fields)) + (p.ConsumeIntegralInRange(0, 7) ? ": " : ":=") + anyValue(p));
  for (size_t i = lines.size(); i > 1; --i) std::swap(lines[i - 1], lines[p.ConsumeIntegralInRange<size_t>(0, i - 1)]);
  std::string h = std::string("NRRD000") + char('0' + p.ConsumeIntegralInRange(3, 6)) + "\n";
  for (const std::string& l : lines) h += l + "\n";
  if (p.ConsumeIntegralInRange(0, 15)) h += "\n";
  return h;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string file;
  if (size > 0 && data[0] == 'S') {
    FuzzedDataProvider p(data + 1, size - 1);
    file = structuredHeader(p);
    file += p.ConsumeRemainingBytesAsString();
  } else {
    file.assign(reinterpret_cast<const char*>(data), size);
  }
  ReadLimits limits;
  limits.maxBytes = fuzz::kFuzzMaxBytes;
  std::istringstream in(file);
  try {
    NrrdHeader h = readNrrdHeader(in, "fuzz.nrrd", limits);
    if (h.headerBytes > file.size() || h.voxelBytes > limits.maxBytes) __builtin_trap();
    if (h.dataFile.empty()) {
      Volume v = readNrrdData(h, in, file.size() - h.headerBytes, "fuzz.nrrd");
      // Accepted: exactly the bytes after the header, and a volume the engine accepts.
      if (!fuzz::sizeMatches(v.dims.x, v.dims.y, v.dims.z, voxelSize(v.type), file.size() - h.headerBytes))
        __builtin_trap();
      validate(v);
    }
  } catch (const std::runtime_error&) {
  }
  return 0;
}

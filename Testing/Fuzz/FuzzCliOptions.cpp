// libFuzzer harness: spaceskip command-line values (Options.cpp), as the CLI's commands read them.
#include "FuzzCommon.h"
#include "Options.h"

#include <stdexcept>
#include <vector>

using namespace spaceskip;
using namespace spaceskip::cli;

namespace {
/// Every value the commands parse, in the order they parse it; nothing is generated or loaded.
void parseLikeTheCommands(const Options& o) {
  const uint64_t cap = maxVolumeBytes(o);
  buildParams(o, o.get("--builder", "grid"));
  renderParams(o);
  backendKind(o);
  int w = 512, h = 512;
  imageSize(o, w, h);  // --size and the image budget (--max-image-bytes)
  double az, el, zoom;
  if (o.has("--camera")) parseCamera(o.get("--camera", ""), az, el, zoom);
  if (o.has("--dims")) checkGeneratorSize("menger", parseDims(o.get("--dims", ""), "--dims"), fuzz::kFuzzMaxBytes);
  o.getInt("--seed", 1, 0, 4294967295LL);
  o.getInt("--frames", 8, 1, 1000000);
  o.getInt("--build-reps", 1, 1, 1000000);
  o.getInt("--threads", 1, 1, 65536);
  o.getDouble("--max-diff", 1, 0, 255);
  for (const std::string& b : split(o.get("--builders", "naive,grid"), ',')) buildParams(o, benchItem(b).spec);
  std::string shape;
  vec3l dims;
  for (const std::string& s : o.positional)
    if (parseGeneratorSpec(s, std::min(cap, fuzz::kFuzzMaxBytes), shape, dims) &&
        (dims.x < 1 || dims.y < 1 || dims.z < 1))
      __builtin_trap();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider p(data, size);
  static const char* const opts[] = {"--dims", "--seed", "-o", "--builder", "--builders", "--leaf", "--mls", "--bins",
                                     "--brick", "--backend", "--threads", "--tf", "--size", "--camera",
                                     "--sample-distance", "--ert", "--filter", "--compare", "--max-diff", "--frames",
                                     "--build-reps", "--json", "--csv", "--max-volume-bytes", "--max-image-bytes", "--perspective",
                                     "--jitter", "--bogus", "gen:menger:", "gen:noise:"};
  std::vector<std::string> args{"spaceskip", "render"};
  const int n = p.ConsumeIntegralInRange(0, 16);
  for (int i = 0; i < n; ++i) {
    switch (p.ConsumeIntegralInRange(0, 4)) {
      case 0: args.push_back(opts[p.ConsumeIntegralInRange<size_t>(0, sizeof(opts) / sizeof(opts[0]) - 1)]); break;
      case 1: args.push_back(fuzz::edgeInteger(p)); break;
      case 2: args.push_back(fuzz::edgeReal(p)); break;
      case 3:
        args.push_back(fuzz::edgeInteger(p) + (p.ConsumeBool() ? "x" : ",") + fuzz::edgeInteger(p) +
                       (p.ConsumeBool() ? "x" + fuzz::edgeInteger(p) : ""));
        break;
      default: args.push_back(p.ConsumeRandomLengthString(24)); break;
    }
    // Glue generator specs to a size: gen:menger:N.
    if (args.size() >= 2 && args[args.size() - 2].rfind("gen:", 0) == 0 && args[args.size() - 2].back() == ':') {
      args[args.size() - 2] += args.back();
      args.pop_back();
    }
  }
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());
  try {
    parseLikeTheCommands(parseArgs(int(argv.size()), argv.data(), 2));
  } catch (const std::invalid_argument&) {
  } catch (const std::runtime_error&) {  // size caps
  }
  return 0;
}

// libFuzzer harness: transfer-function text files and presets over extreme scalar ranges.
#include "FuzzCommon.h"
#include "spaceskip/TransferFunctionIO.h"

#include <sstream>
#include <stdexcept>

using namespace spaceskip;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider p(data, size);
  const bool preset = p.ConsumeIntegralInRange(0, 3) == 0;
  double lo = 0, hi = 1;
  if (p.ConsumeBool()) {
    // Scalar ranges as a volume may report them (finite, possibly huge or degenerate).
    static const double k[] = {0, 1, -1, 255, 65535, 1e-300, -1e-300, 1e300, -1e300, 1.7976931348623157e308,
                               -1.7976931348623157e308, 4.9e-324};
    lo = k[p.ConsumeIntegralInRange<size_t>(0, 11)];
    hi = k[p.ConsumeIntegralInRange<size_t>(0, 11)];
    if (hi < lo) std::swap(lo, hi);
  }
  try {
    if (preset) {
      static const char* const names[] = {"ramp", "grayscale", "coolwarm", "band", "spike", "opaque", "zero", "nope"};
      const std::string name = p.ConsumeBool() ? names[p.ConsumeIntegralInRange(0, 7)] : p.ConsumeRandomLengthString(16);
      TransferFunction tf = TransferFunction::preset(name, lo, hi, p.ConsumeIntegralInRange(1, 4096));
      if (tf.table.empty()) __builtin_trap();
    } else {
      TFReadLimits limits;
      std::istringstream in(p.ConsumeRemainingBytesAsString());
      TransferFunction tf = readTransferFunction(in, "fuzz.tf", lo, hi, limits);
      if (tf.table.size() < 2 || tf.table.size() > size_t(limits.maxTableSize) || !(tf.unitDistance > 0)) __builtin_trap();
    }
  } catch (const std::runtime_error&) {
  } catch (const std::invalid_argument&) {  // unknown preset name
  }
  return 0;
}

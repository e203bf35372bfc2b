// Shared pieces of the libFuzzer harnesses: edge values that reach overflow and caps.
#pragma once
#include <fuzzer/FuzzedDataProvider.h>

#include <cstdint>
#include <string>

namespace spaceskip::fuzz {

/// Integers as text around every boundary the parsers check (axis 2^30, 2^31, 2^32, 2^63,
/// 2^64), plus malformed spellings; a byte fuzzer alone seldom builds these.
inline std::string edgeInteger(FuzzedDataProvider& p) {
  static const char* const k[] = {"0", "1", "2", "3", "7", "8", "9", "16", "255", "256", "1023", "1024", "4096",
                                  "65535", "65536", "1048576", "1073741823", "1073741824", "1073741825",
                                  "2147483647", "2147483648", "4294967295", "4294967296", "4294967297",
                                  "9223372036854775807", "9223372036854775808", "18446744073709551615",
                                  "18446744073709551616", "99999999999999999999", "-1", "-0",
                                  "-9223372036854775808", "+5", "1e3", "0x10", "12abc", "", " 4", "nan"};
  if (p.ConsumeBool()) return k[p.ConsumeIntegralInRange<size_t>(0, sizeof(k) / sizeof(k[0]) - 1)];
  return std::to_string(p.ConsumeIntegral<int64_t>());
}

/// Floating-point values as text, including non-finite and extreme ones.
inline std::string edgeReal(FuzzedDataProvider& p) {
  static const char* const k[] = {"0", "1", "-1", "0.5", "1e-6", "1e6", "1e308", "-1e308", "1e309", "4.9e-324",
                                  "inf", "-inf", "nan", "NaN", "+1", "1.", ".5", "1e", "--1", "0x1p3", ""};
  if (p.ConsumeBool()) return k[p.ConsumeIntegralInRange<size_t>(0, sizeof(k) / sizeof(k[0]) - 1)];
  return std::to_string(p.ConsumeFloatingPoint<double>());
}

/// Oracle independent of the reader: dims product * voxel size in floating point (it cannot
/// wrap like a 64-bit product) equals the bytes a reader accepted.
inline bool sizeMatches(int64_t x, int64_t y, int64_t z, size_t voxelBytes, size_t present) {
  return x > 0 && y > 0 && z > 0 && double(x) * double(y) * double(z) * double(voxelBytes) == double(present);
}

/// The harnesses never allocate what an input claims: readers get this cap.
constexpr uint64_t kFuzzMaxBytes = uint64_t(64) << 20;

}  // namespace spaceskip::fuzz

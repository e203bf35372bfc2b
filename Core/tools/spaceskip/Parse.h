// Strict number parsing for file headers and command-line values: the whole text or nothing.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace spaceskip {

/// Decimal integer, optional leading '-', no spaces, no trailing characters, no overflow.
bool parseInt64(std::string_view s, int64_t& out);
/// Decimal integer >= 0 (no sign), no overflow.
bool parseUInt64(std::string_view s, uint64_t& out);
/// Floating-point number (fixed or scientific, "inf"/"nan" only when allowNonFinite), whole text.
bool parseDouble(std::string_view s, double& out, bool allowNonFinite = false);
/// Byte count with an optional binary suffix: 1048576, 512K, 64M, 16G, 1T (K = 1024). No overflow.
bool parseByteCount(std::string_view s, uint64_t& out);
/// Splits on spaces and tabs, dropping empty tokens.
std::vector<std::string_view> splitWhitespace(std::string_view s);

}  // namespace spaceskip

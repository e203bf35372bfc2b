// Strict number parsing: std::from_chars over the whole text, so "12abc", " 12", "" and
// values out of range are refused instead of throwing (std::stoi) or half-parsing (>>).
#include "spaceskip/Parse.h"

#include <charconv>
#include <cmath>
#include <limits>

namespace spaceskip {

bool parseInt64(std::string_view s, int64_t& out) {
  if (s.empty()) return false;
  int64_t v = 0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v, 10);
  if (ec != std::errc() || end != s.data() + s.size()) return false;
  out = v;
  return true;
}

bool parseUInt64(std::string_view s, uint64_t& out) {
  if (s.empty() || s[0] == '-') return false;  // from_chars would not wrap, but say why early
  uint64_t v = 0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v, 10);
  if (ec != std::errc() || end != s.data() + s.size()) return false;
  out = v;
  return true;
}

bool parseDouble(std::string_view s, double& out, bool allowNonFinite) {
  if (s.empty()) return false;
  // from_chars refuses a leading '+'; users type it ("+1e6"), so allow exactly one.
  if (s[0] == '+') {
    s.remove_prefix(1);
    if (s.empty() || s[0] == '+' || s[0] == '-') return false;
  }
  double v = 0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v, std::chars_format::general);
  if (ec != std::errc() || end != s.data() + s.size()) return false;
  if (!allowNonFinite && !std::isfinite(v)) return false;
  out = v;
  return true;
}

bool parseByteCount(std::string_view s, uint64_t& out) {
  if (s.empty()) return false;
  int shift = 0;
  switch (s.back()) {
    case 'K': case 'k': shift = 10; break;
    case 'M': case 'm': shift = 20; break;
    case 'G': case 'g': shift = 30; break;
    case 'T': case 't': shift = 40; break;
    default: break;
  }
  if (shift) s.remove_suffix(1);
  uint64_t v = 0;
  if (!parseUInt64(s, v)) return false;
  if (shift && v > (std::numeric_limits<uint64_t>::max() >> shift)) return false;
  out = v << shift;
  return true;
}

std::vector<std::string_view> splitWhitespace(std::string_view s) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
    size_t j = i;
    while (j < s.size() && s[j] != ' ' && s[j] != '\t') ++j;
    if (j > i) out.push_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

}  // namespace spaceskip

// Transfer-function files with bounded lines, bounded sizes and strict numbers (issue 14): a
// device file, a huge "size" or "nan" in a file gives an error, not a hang, an allocation or UB.
#include "spaceskip/TransferFunctionIO.h"

#include "spaceskip/Parse.h"

#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace spaceskip {

namespace {
std::runtime_error lineError(const std::string& name, int lineNo, const std::string& what) {
  return std::runtime_error(name + ":" + std::to_string(lineNo) + ": " + what);
}
}  // namespace

TransferFunction readTransferFunction(std::istream& in, const std::string& name, double lo, double hi,
                                      const TFReadLimits& limits) {
  std::vector<TFPoint> pts;
  int64_t size = 1024;
  double unit = 1.0;
  std::string line;
  int lineNo = 0;
  uint64_t total = 0;
  std::streambuf* sb = in.rdbuf();
  for (bool more = true; more;) {
    line.clear();
    more = false;
    for (int c; (c = sb->sbumpc()) != std::char_traits<char>::eof();) {
      if (++total > limits.maxFileBytes)
        throw std::runtime_error(name + ": transfer-function file longer than " + std::to_string(limits.maxFileBytes) + " bytes");
      if (c == '\n') {
        more = true;
        break;
      }
      if (line.size() >= limits.maxLine)
        throw lineError(name, lineNo + 1, "line longer than " + std::to_string(limits.maxLine) + " bytes");
      line.push_back(char(c));
    }
    ++lineNo;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    auto tok = splitWhitespace(line);
    if (tok.empty() || tok[0][0] == '#') continue;
    if (tok[0] == "range") {
      if (tok.size() != 3 || !parseDouble(tok[1], lo) || !parseDouble(tok[2], hi) || !(hi >= lo))
        throw lineError(name, lineNo, "expected 'range LO HI' with finite LO <= HI");
    } else if (tok[0] == "size") {
      if (tok.size() != 2 || !parseInt64(tok[1], size) || size < 2 || size > limits.maxTableSize)
        throw lineError(name, lineNo, "expected 'size N' with 2 <= N <= " + std::to_string(limits.maxTableSize));
    } else if (tok[0] == "unit") {
      if (tok.size() != 2 || !parseDouble(tok[1], unit) || !(unit > 0))
        throw lineError(name, lineNo, "expected 'unit U' with finite U > 0");
    } else {
      double d[5];
      bool ok = tok.size() == 5;
      for (size_t i = 0; ok && i < 5; ++i) ok = parseDouble(tok[i], d[i]) && (i == 0 || (d[i] >= 0 && d[i] <= 1));
      if (!ok) throw lineError(name, lineNo, "expected 'value r g b a' (finite value; r, g, b, a in [0, 1])");
      if (pts.size() >= limits.maxPoints)
        throw lineError(name, lineNo, "more than " + std::to_string(limits.maxPoints) + " control points");
      pts.push_back(TFPoint{d[0], float(d[1]), float(d[2]), float(d[3]), float(d[4])});
    }
  }
  if (in.bad()) throw std::runtime_error(name + ": read error");
  if (pts.empty()) throw std::runtime_error(name + ": no control points");
  TransferFunction tf = TransferFunction::fromPoints(pts, lo, hi, int(size));
  tf.unitDistance = unit;
  return tf;
}

TransferFunction loadTransferFunction(const std::string& path, double lo, double hi, const TFReadLimits& limits) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throw std::runtime_error(path + ": cannot open transfer-function file");
  if (!fs::is_regular_file(st))
    throw std::runtime_error(path + ": not a regular file (device, pipe or directory): only regular files are read");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open transfer-function file");
  return readTransferFunction(in, path, lo, hi, limits);
}

}  // namespace spaceskip

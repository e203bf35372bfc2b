// Raw (Open SciVis naming) and NRRD (raw encoding, attached or detached data) I/O. Hostile input
// rules (issue 14): sizes are checked for overflow, against a cap and against the bytes present
// before anything is allocated; header lines are bounded; only regular files are read.
#include "spaceskip/VolumeIO.h"

#include "spaceskip/OutputFile.h"
#include "spaceskip/Parse.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <new>
#include <stdexcept>

namespace spaceskip {

namespace fs = std::filesystem;

namespace {
std::runtime_error ioError(const std::string& path, const std::string& what) {
  return std::runtime_error(path + ": " + what);
}

std::runtime_error fieldError(const std::string& path, const std::string& field, const std::string& what) {
  return std::runtime_error(path + ": NRRD field '" + field + "': " + what);
}

std::string baseName(const std::string& p) {
  size_t s = p.find_last_of('/');
  return s == std::string::npos ? p : p.substr(s + 1);
}

std::string dirName(const std::string& p) {
  size_t s = p.find_last_of('/');
  return s == std::string::npos ? std::string(".") : p.substr(0, s);
}

std::string dimsText(vec3l d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

/// Size of a regular file; devices, pipes and directories are refused (a read from /dev/zero
/// never ends, and a pipe has no size to check a header against).
uint64_t regularFileSize(const std::string& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throw ioError(path, "cannot open file (does not exist or is not accessible)");
  if (!fs::is_regular_file(st)) {
    const char* kind = fs::is_directory(st) ? "a directory" : fs::is_character_file(st) ? "a character device"
                       : fs::is_block_file(st) ? "a block device" : fs::is_fifo(st) ? "a pipe (FIFO)"
                       : fs::is_socket(st) ? "a socket" : "not a regular file";
    throw ioError(path, std::string("not a regular file (") + kind + "): only regular files are read");
  }
  const uintmax_t n = fs::file_size(path, ec);
  if (ec) throw ioError(path, "cannot read the file size: " + ec.message());
  return uint64_t(n);
}

/// Reads exactly n bytes of voxels, after the caller checked that the input holds exactly n.
void readExactly(std::istream& in, unsigned char* dst, uint64_t n, const std::string& path) {
  in.read(reinterpret_cast<char*>(dst), std::streamsize(n));
  if (uint64_t(in.gcount()) != n)
    throw ioError(path, "file too short: expected " + std::to_string(n) + " bytes of voxels, got " +
                            std::to_string(in.gcount()) + " (did it shrink while being read?)");
  if (in.peek() != std::char_traits<char>::eof())
    throw ioError(path, "trailing bytes after the " + std::to_string(n) + " bytes of voxels (did it grow while being read?)");
}

/// Volume::allocate; a std::bad_alloc becomes an error naming the file, the dims and the bytes.
void allocateVoxels(Volume& v, vec3l dims, VoxelType type, uint64_t bytes, const std::string& path) {
  try {
    v.allocate(dims, type);
  } catch (const std::bad_alloc&) {
    throw ioError(path, "out of memory allocating " + dimsText(dims) + " " + voxelTypeName(type) + " voxels (" +
                            std::to_string(bytes) + " bytes)");
  }
}

void swapBytes(Volume& v) {
  size_t s = voxelSize(v.type);
  if (s == 1) return;
  unsigned char* p = v.mutableData();
  for (size_t i = 0; i < v.byteSize(); i += s) std::reverse(p + i, p + i + s);
}

std::string trim(const std::string& s) {
  size_t a = s.find_first_not_of(" \t\r\n"), b = s.find_last_not_of(" \t\r\n");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
  return s;
}

/// One '\n'-terminated line of at most `maxLine` bytes (without the '\n' and a trailing '\r');
/// false at end of input with nothing read. `consumed` counts the bytes taken from `in`.
bool readBoundedLine(std::istream& in, std::string& line, size_t maxLine, uint64_t& consumed, const std::string& path) {
  line.clear();
  std::streambuf* sb = in.rdbuf();
  for (;;) {
    const int c = sb->sbumpc();
    if (c == std::char_traits<char>::eof()) {
      in.setstate(std::ios::eofbit);
      break;
    }
    ++consumed;
    if (c == '\n') {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      return true;
    }
    if (line.size() >= maxLine)
      throw ioError(path, "NRRD header line longer than " + std::to_string(maxLine) + " bytes: not a NRRD header");
    line.push_back(char(c));
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return !line.empty();
}

/// NRRD field identifiers (format.html, NRRD0001-0005), aliases folded to one spelling.
const std::map<std::string, std::string>& nrrdFields() {
  static const std::map<std::string, std::string> f = {
      {"dimension", "dimension"}, {"type", "type"}, {"block size", "block size"}, {"blocksize", "block size"},
      {"encoding", "encoding"}, {"endian", "endian"}, {"content", "content"}, {"min", "min"}, {"max", "max"},
      {"old min", "old min"}, {"oldmin", "old min"}, {"old max", "old max"}, {"oldmax", "old max"},
      {"data file", "data file"}, {"datafile", "data file"}, {"line skip", "line skip"}, {"lineskip", "line skip"},
      {"byte skip", "byte skip"}, {"byteskip", "byte skip"}, {"number", "number"}, {"sample units", "sample units"},
      {"sampleunits", "sample units"}, {"sizes", "sizes"}, {"spacings", "spacings"}, {"thicknesses", "thicknesses"},
      {"axis mins", "axis mins"}, {"axismins", "axis mins"}, {"axis maxs", "axis maxs"}, {"axismaxs", "axis maxs"},
      {"centers", "centers"}, {"centerings", "centers"}, {"labels", "labels"}, {"units", "units"},
      {"kinds", "kinds"}, {"space", "space"}, {"space dimension", "space dimension"},
      {"space units", "space units"}, {"space origin", "space origin"}, {"space directions", "space directions"},
      {"measurement frame", "measurement frame"}};
  return f;
}

bool nrrdVoxelType(const std::string& s, VoxelType& t) {
  // NRRD's spellings beyond parseVoxelType's (format.html, "type").
  static const std::map<std::string, VoxelType> extra = {
      {"signed short", VoxelType::Int16}, {"short int", VoxelType::Int16}, {"signed short int", VoxelType::Int16},
      {"unsigned short int", VoxelType::UInt16}};
  auto it = extra.find(lower(s));
  if (it != extra.end()) {
    t = it->second;
    return true;
  }
  return parseVoxelType(s, t);
}

/// "(x,y,z)" with `n` finite components.
bool parseVector(const std::string& s, int n, double* out) {
  std::string t = trim(s);
  if (t.size() < 2 || t.front() != '(' || t.back() != ')') return false;
  t = t.substr(1, t.size() - 2);
  int k = 0;
  size_t pos = 0;
  for (;;) {
    size_t c = t.find(',', pos);
    std::string item = trim(t.substr(pos, c == std::string::npos ? std::string::npos : c - pos));
    if (k >= n || !parseDouble(item, out[k])) return false;
    ++k;
    if (c == std::string::npos) break;
    pos = c + 1;
  }
  return k == n;
}

/// Space directions: "(a,b,c) (d,e,f) ..." or "none" per axis.
std::vector<std::string> splitVectors(const std::string& s) {
  std::vector<std::string> out;
  size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
    if (i >= s.size()) break;
    size_t j = s[i] == '(' ? s.find(')', i) : s.find_first_of(" \t", i);
    j = j == std::string::npos ? s.size() : (s[i] == '(' ? j + 1 : j);
    out.push_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

/// NRRD "kinds" (format.html): one per axis. Spatial kinds are read; an axis of one sample may
/// say stub or scalar; any kind whose samples are a voxel's components (colour, vector, list,
/// matrix) is refused: the reader makes scalar volumes, and reading such an axis as space would
/// draw the components side by side.
void checkKinds(const std::string& path, const std::string& text, int n, vec3l dims) {
  static const char* const spatial[] = {"domain", "space", "time", "???", "none"};
  static const char* const oneSample[] = {"stub", "scalar"};
  static const char* const components[] = {
      "list", "point", "vector", "covariant-vector", "normal", "complex", "2-vector", "3-color", "rgb-color",
      "hsv-color", "xyz-color", "4-color", "rgba-color", "3-vector", "3-gradient", "3-normal", "4-vector", "quaternion",
      "2d-symmetric-matrix", "2d-masked-symmetric-matrix", "2d-matrix", "2d-masked-matrix", "3d-symmetric-matrix",
      "3d-masked-symmetric-matrix", "3d-matrix", "3d-masked-matrix"};
  auto in = [](const std::string& k, const auto& list) {
    return std::find(std::begin(list), std::end(list), k) != std::end(list);
  };
  const auto tok = splitWhitespace(text);
  if (int(tok.size()) != n)
    throw fieldError(path, "kinds", std::to_string(tok.size()) + " values for dimension " + std::to_string(n));
  const int64_t size[3] = {dims.x, dims.y, dims.z};
  for (int a = 0; a < n; ++a) {
    const std::string given(tok[size_t(a)].substr(0, 40));
    const std::string k = lower(given);
    if (in(k, spatial) || (in(k, oneSample) && size[a] == 1)) continue;
    if (in(k, oneSample))
      throw fieldError(path, "kinds", "axis " + std::to_string(a) + " is '" + given + "' but has " +
                                          std::to_string(size[a]) + " samples (" + given + " means one)");
    if (in(k, components))
      throw fieldError(path, "kinds", "axis " + std::to_string(a) + " is '" + given + "' (" + std::to_string(size[a]) +
                                          " components per voxel): only scalar volumes are read; make one scalar "
                                          "per voxel first (e.g. unu project, or a magnitude)");
    throw fieldError(path, "kinds", "'" + given + "' is not a NRRD kind");
  }
}
}  // namespace

bool parseRawName(const std::string& fileName, vec3l& dims, VoxelType& type) {
  // NAME_XxYxZ_TYPE.raw: the last two '_'-separated fields before ".raw".
  std::string name = baseName(fileName);
  if (name.size() < 4 || name.compare(name.size() - 4, 4, ".raw") != 0) return false;
  name.resize(name.size() - 4);
  size_t t = name.rfind('_');
  if (t == std::string::npos || t == 0) return false;
  size_t d = name.rfind('_', t - 1);
  if (d == std::string::npos) return false;
  std::string dimStr = name.substr(d + 1, t - d - 1);
  int64_t v[3];
  size_t pos = 0;
  for (int i = 0; i < 3; ++i) {
    size_t end = dimStr.find('x', pos);
    if ((i < 2) != (end != std::string::npos)) return false;
    std::string num = dimStr.substr(pos, i < 2 ? end - pos : std::string::npos);
    // Digits only (no sign); parseInt64 refuses values beyond 64 bits instead of wrapping.
    if (num.empty() || num.find_first_not_of("0123456789") != std::string::npos || !parseInt64(num, v[i])) return false;
    pos = end + 1;
  }
  dims = vec3l{v[0], v[1], v[2]};
  return parseVoxelType(name.substr(t + 1), type);
}

namespace {
std::runtime_error rawNameError(const std::string& path) {
  return ioError(path, "cannot read dims/type from the name; expected NAME_XxYxZ_TYPE.raw "
                       "(X, Y, Z positive integers; TYPE: uint8, int8, uint16, int16, float32, float64)");
}
}  // namespace

Volume readRaw(std::istream& in, uint64_t available, const std::string& path, const ReadLimits& limits) {
  vec3l dims;
  VoxelType type;
  if (!parseRawName(path, dims, type)) throw rawNameError(path);
  const uint64_t bytes = checkedByteSize(dims, type, limits.maxBytes, path + ": dims in the name");
  if (available != bytes)
    throw ioError(path, "size " + std::to_string(available) + " bytes does not match " + dimsText(dims) + " " +
                            voxelTypeName(type) + " (" + std::to_string(bytes) + " bytes): " +
                            (available < bytes ? "file too short"
                                               : std::to_string(available - bytes) + " trailing bytes"));
  Volume v;
  allocateVoxels(v, dims, type, bytes, path);
  readExactly(in, v.mutableData(), bytes, path);
  return v;
}

Volume loadRaw(const std::string& path, const ReadLimits& limits) {
  vec3l dims;
  VoxelType type;
  // The name first: a bad name is the clearer error even when the file is missing.
  if (!parseRawName(path, dims, type)) throw rawNameError(path);
  const uint64_t size = regularFileSize(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ioError(path, "cannot open file");
  return readRaw(in, size, path, limits);
}

NrrdHeader readNrrdHeader(std::istream& in, const std::string& path, const ReadLimits& limits) {
  NrrdHeader h;
  uint64_t consumed = 0;
  std::string line;
  // The magic is bounded like every other line: a device or binary file is refused quickly.
  if (!readBoundedLine(in, line, std::min<size_t>(limits.maxHeaderLine, 64), consumed, path) ||
      line.size() != 8 || line.compare(0, 7, "NRRD000") != 0 || line[7] < '1' || line[7] > '5')
    throw ioError(path, "not a NRRD file (first line must be the magic NRRD0001..NRRD0005)");
  std::map<std::string, std::string> fields;  // canonical field -> description, interpreted below
  bool blankLine = false;
  int lineNo = 1;
  while (readBoundedLine(in, line, limits.maxHeaderLine, consumed, path)) {
    ++lineNo;
    if (consumed > limits.maxHeaderBytes)
      throw ioError(path, "NRRD header longer than " + std::to_string(limits.maxHeaderBytes) + " bytes");
    if (line.empty()) {
      blankLine = true;  // attached data follows
      break;
    }
    if (line[0] == '#') continue;
    const size_t c = line.find(':');
    if (c == std::string::npos || c == 0 || c + 1 >= line.size())
      throw ioError(path, "line " + std::to_string(lineNo) + ": malformed NRRD header line (expected 'field: value'): " +
                              line.substr(0, 80));
    if (line[c + 1] == '=') continue;  // key:=value pairs are free-form metadata
    if (line[c + 1] != ' ')
      throw ioError(path, "line " + std::to_string(lineNo) + ": malformed NRRD field (expected ': ' after the name): " +
                              line.substr(0, 80));
    const std::string key = lower(line.substr(0, c));
    auto known = nrrdFields().find(key);
    if (known == nrrdFields().end())
      throw ioError(path, "line " + std::to_string(lineNo) + ": unknown NRRD field '" + key.substr(0, 80) + "'");
    if (!fields.emplace(known->second, trim(line.substr(c + 2))).second)
      throw fieldError(path, known->second, "given more than once");
  }
  if (in.bad()) throw ioError(path, "read error in the NRRD header");
  h.headerBytes = consumed;

  auto need = [&](const char* f) -> const std::string& {
    auto it = fields.find(f);
    if (it == fields.end()) throw fieldError(path, f, "required field missing");
    return it->second;
  };
  auto has = [&](const char* f) { return fields.count(f) != 0; };

  int64_t dimension = 0;
  if (!parseInt64(need("dimension"), dimension) || dimension < 1 || dimension > 3)
    throw fieldError(path, "dimension", "'" + fields["dimension"] + "': only scalar volumes of dimension 1 to 3 are supported");
  const int n = int(dimension);
  if (!nrrdVoxelType(need("type"), h.type))
    throw fieldError(path, "type", "unsupported NRRD type '" + fields["type"] +
                                       "' (uint8, int8, uint16, int16, float, double)");
  {
    auto tok = splitWhitespace(need("sizes"));
    if (int(tok.size()) != n)
      throw fieldError(path, "sizes", std::to_string(tok.size()) + " values for dimension " + std::to_string(n));
    int64_t s[3] = {1, 1, 1};
    for (int i = 0; i < n; ++i)
      if (!parseInt64(tok[size_t(i)], s[i]) || s[i] <= 0)
        throw fieldError(path, "sizes", "'" + std::string(tok[size_t(i)].substr(0, 40)) +
                                            "' is not a positive 64-bit integer");
    h.dims = vec3l{s[0], s[1], s[2]};
  }
  if (has("kinds")) checkKinds(path, fields["kinds"], n, h.dims);
  const std::string enc = lower(need("encoding"));
  if (enc != "raw") throw fieldError(path, "encoding", "unsupported encoding '" + fields["encoding"] + "' (only raw)");
  if (has("endian")) {
    const std::string e = lower(fields["endian"]);
    if (e != "little" && e != "big") throw fieldError(path, "endian", "'" + fields["endian"] + "' is not little or big");
    h.bigEndian = e == "big";
  } else if (voxelSize(h.type) > 1) {
    throw fieldError(path, "endian", "required field missing (raw data of more than one byte per voxel)");
  }
  if (has("spacings") && has("space directions"))
    throw fieldError(path, "spacings", "may not be given together with 'space directions'");
  if (has("spacings")) {
    auto tok = splitWhitespace(fields["spacings"]);
    if (int(tok.size()) != n)
      throw fieldError(path, "spacings", std::to_string(tok.size()) + " values for dimension " + std::to_string(n));
    for (int i = 0; i < n; ++i) {
      double s = 0;
      if (!parseDouble(tok[size_t(i)], s, true) || std::isinf(s) || s <= 0)
        throw fieldError(path, "spacings", "'" + std::string(tok[size_t(i)].substr(0, 40)) +
                                               "' is not a positive finite number (or nan: unknown)");
      h.spacing[i] = std::isnan(s) ? 1.0 : s;  // nan: spacing unknown (format.html)
    }
  }
  if (has("space dimension")) {
    int64_t sd = 0;
    if (!parseInt64(fields["space dimension"], sd) || sd != 3)
      throw fieldError(path, "space dimension", "'" + fields["space dimension"] + "': only 3 is supported");
  }
  if (has("space directions")) {
    auto vecs = splitVectors(fields["space directions"]);
    if (int(vecs.size()) != n)
      throw fieldError(path, "space directions", std::to_string(vecs.size()) + " vectors for dimension " + std::to_string(n));
    for (int a = 0; a < n; ++a) {
      double d[3];
      if (!parseVector(vecs[size_t(a)], 3, d))
        throw fieldError(path, "space directions", "'" + vecs[size_t(a)].substr(0, 80) + "' is not a vector (x,y,z)");
      const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      if (!(len > 0) || !std::isfinite(len))
        throw fieldError(path, "space directions", "axis " + std::to_string(a) + " has a zero or non-finite length");
      h.spacing[a] = len;
      for (int r = 0; r < 3; ++r) h.direction[r * 3 + a] = d[r] / len;
    }
    // Axes beyond `dimension` keep their identity columns; all three must span space.
    const double* m = h.direction;
    const double det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
                       m[2] * (m[3] * m[7] - m[4] * m[6]);
    if (!(std::fabs(det) > 1e-9))
      throw fieldError(path, "space directions", "the axes are parallel (no volume)");
  }
  if (has("space origin") && !parseVector(fields["space origin"], 3, h.origin))
    throw fieldError(path, "space origin", "'" + fields["space origin"].substr(0, 80) + "' is not a point (x,y,z)");
  for (const char* skip : {"line skip", "byte skip"}) {
    int64_t k = 0;
    if (has(skip) && (!parseInt64(fields[skip], k) || k != 0))
      throw fieldError(path, skip, "'" + fields[skip] + "': only 0 is supported");
  }
  if (has("data file")) {
    const std::string& f = fields["data file"];
    // "LIST" and "printf-format min max step" name several files: not supported.
    if (f.empty() || f == "LIST" || f.find_first_of(" \t") != std::string::npos)
      throw fieldError(path, "data file", "'" + f.substr(0, 80) + "': only a single data file name is supported");
    h.dataFile = f;
  } else if (!blankLine) {
    throw ioError(path, "NRRD header not ended by a blank line and no 'data file' field: no voxel data");
  }
  h.voxelBytes = checkedByteSize(h.dims, h.type, limits.maxBytes, path + ": NRRD field 'sizes'");
  return h;
}

Volume readNrrdData(const NrrdHeader& h, std::istream& in, uint64_t available, const std::string& path) {
  if (available != h.voxelBytes)
    throw ioError(path, (available < h.voxelBytes ? "file too short: " : std::to_string(available - h.voxelBytes) +
                                                                              " trailing bytes: ") +
                            std::string("the header's sizes ") + dimsText(h.dims) + " of " + voxelTypeName(h.type) +
                            " need " + std::to_string(h.voxelBytes) + " bytes of voxels, the file has " +
                            std::to_string(available));
  Volume v;
  allocateVoxels(v, h.dims, h.type, h.voxelBytes, path);
  std::copy(h.spacing, h.spacing + 3, v.spacing);
  std::copy(h.origin, h.origin + 3, v.origin);
  std::copy(h.direction, h.direction + 9, v.direction);
  readExactly(in, v.mutableData(), h.voxelBytes, path);
  if (h.bigEndian) swapBytes(v);
  return v;
}

Volume loadNrrd(const std::string& path, const ReadLimits& limits) {
  const uint64_t size = regularFileSize(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ioError(path, "cannot open file");
  const NrrdHeader h = readNrrdHeader(in, path, limits);
  if (h.dataFile.empty()) return readNrrdData(h, in, size - h.headerBytes, path);
  if (size != h.headerBytes)
    throw ioError(path, std::to_string(size - h.headerBytes) +
                            " bytes after the header of a NRRD whose data is in 'data file'");
  const std::string p = h.dataFile[0] == '/' ? h.dataFile : dirName(path) + "/" + h.dataFile;
  const uint64_t dataSize = regularFileSize(p);
  std::ifstream df(p, std::ios::binary);
  if (!df) throw ioError(p, "cannot open the data file named in " + path);
  return readNrrdData(h, df, dataSize, p);
}

Volume loadVolume(const std::string& path, const ReadLimits& limits) {
  auto ends = [&](const char* s) {
    size_t n = std::strlen(s);
    return path.size() >= n && path.compare(path.size() - n, n, s) == 0;
  };
  if (ends(".nrrd") || ends(".nhdr")) return loadNrrd(path, limits);
  if (ends(".raw")) return loadRaw(path, limits);
  throw ioError(path, "unknown volume format (expected .raw named NAME_XxYxZ_TYPE.raw, or .nrrd)");
}

void saveNrrd(const Volume& v, const std::string& path) {
  OutputFile file(path);
  std::ostream& out = file.stream();
  static const char* nrrdType[] = {"uint8", "int8", "uint16", "int16", "float", "double"};
  out.precision(17);  // spacings round-trip exactly
  out << "NRRD0004\ntype: " << nrrdType[int(v.type)] << "\ndimension: 3\nsizes: " << v.dims.x << " "
      << v.dims.y << " " << v.dims.z << "\nspacings: " << v.spacing[0] << " " << v.spacing[1] << " "
      << v.spacing[2] << "\nencoding: raw\nendian: little\n\n";
  out.write(static_cast<const char*>(v.data), std::streamsize(v.byteSize()));
  file.commit();
}

void saveRaw(const Volume& v, const std::string& path) {
  OutputFile file(path);
  file.stream().write(static_cast<const char*>(v.data), std::streamsize(v.byteSize()));
  file.commit();
}

}  // namespace spaceskip

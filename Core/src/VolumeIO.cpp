// Raw (Open SciVis naming) and NRRD (raw encoding, attached or detached data) I/O.
#include "spaceskip/VolumeIO.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace spaceskip {

namespace {
std::runtime_error ioError(const std::string& path, const std::string& what) {
  return std::runtime_error(path + ": " + what);
}

std::string baseName(const std::string& p) {
  size_t s = p.find_last_of('/');
  return s == std::string::npos ? p : p.substr(s + 1);
}

std::string dirName(const std::string& p) {
  size_t s = p.find_last_of('/');
  return s == std::string::npos ? std::string(".") : p.substr(0, s);
}

void readExactly(std::istream& in, unsigned char* dst, size_t n, const std::string& path) {
  in.read(reinterpret_cast<char*>(dst), std::streamsize(n));
  if (size_t(in.gcount()) != n)
    throw ioError(path, "file too short: expected " + std::to_string(n) + " bytes of voxels, got " +
                            std::to_string(in.gcount()));
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
  long long v[3];
  size_t pos = 0;
  for (int i = 0; i < 3; ++i) {
    size_t end = dimStr.find('x', pos);
    if ((i < 2) != (end != std::string::npos)) return false;
    std::string num = dimStr.substr(pos, i < 2 ? end - pos : std::string::npos);
    if (num.empty() || num.find_first_not_of("0123456789") != std::string::npos || num.size() > 12) return false;
    v[i] = std::stoll(num);
    pos = end + 1;
  }
  dims = vec3l{v[0], v[1], v[2]};
  return parseVoxelType(name.substr(t + 1), type);
}

Volume loadRaw(const std::string& path) {
  Volume v;
  vec3l dims;
  VoxelType type;
  if (!parseRawName(path, dims, type))
    throw ioError(path, "cannot read dims/type from the name; expected NAME_XxYxZ_TYPE.raw "
                        "(TYPE: uint8, int8, uint16, int16, float32, float64)");
  if (dims.x <= 0 || dims.y <= 0 || dims.z <= 0) throw ioError(path, "empty extent in the name");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ioError(path, "cannot open file");
  in.seekg(0, std::ios::end);
  const auto fileSize = static_cast<long long>(in.tellg());
  in.seekg(0);
  v.allocate(dims, type);
  if (fileSize != static_cast<long long>(v.byteSize()))
    throw ioError(path, "size " + std::to_string(fileSize) + " bytes does not match " +
                            std::to_string(dims.x) + "x" + std::to_string(dims.y) + "x" +
                            std::to_string(dims.z) + " " + voxelTypeName(type) + " (" +
                            std::to_string(v.byteSize()) + " bytes)");
  readExactly(in, v.mutableData(), v.byteSize(), path);
  return v;
}

Volume loadNrrd(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ioError(path, "cannot open file");
  std::string line;
  if (!std::getline(in, line) || line.rfind("NRRD", 0) != 0) throw ioError(path, "not a NRRD file (no NRRD magic)");
  Volume v;
  bool haveType = false, haveSizes = false, bigEndian = false;
  int dimension = 0;
  vec3l dims{1, 1, 1};
  std::string encoding = "raw", dataFile;
  VoxelType type = VoxelType::UInt8;
  while (std::getline(in, line)) {
    line = trim(line);
    if (line.empty()) break;  // blank line ends the header
    if (line[0] == '#') continue;
    size_t c = line.find(':');
    if (c == std::string::npos) throw ioError(path, "malformed header line: " + line);
    std::string key = trim(line.substr(0, c)), val = trim(line.substr(c + 1));
    if (!val.empty() && val[0] == '=') val = trim(val.substr(1));  // key:=value
    std::transform(key.begin(), key.end(), key.begin(), [](unsigned char ch) { return std::tolower(ch); });
    std::istringstream vs(val);
    if (key == "type") {
      if (!parseVoxelType(val, type)) throw ioError(path, "unsupported NRRD type '" + val + "'");
      haveType = true;
    } else if (key == "dimension") {
      vs >> dimension;
      if (dimension < 1 || dimension > 3) throw ioError(path, "only 1-3 dimensional scalar NRRDs are supported");
    } else if (key == "sizes") {
      long long s[3] = {1, 1, 1};
      for (int i = 0; i < dimension; ++i)
        if (!(vs >> s[i])) throw ioError(path, "bad sizes: " + val);
      dims = vec3l{s[0], s[1], s[2]};
      haveSizes = true;
    } else if (key == "encoding") {
      encoding = val;
    } else if (key == "endian") {
      bigEndian = val == "big";
    } else if (key == "spacings") {
      for (int i = 0; i < dimension; ++i) vs >> v.spacing[i];
    } else if (key == "space origin") {
      std::string s = val;
      std::replace(s.begin(), s.end(), '(', ' ');
      std::replace(s.begin(), s.end(), ')', ' ');
      std::replace(s.begin(), s.end(), ',', ' ');
      std::istringstream os(s);
      os >> v.origin[0] >> v.origin[1] >> v.origin[2];
    } else if (key == "data file" || key == "datafile") {
      dataFile = val;
    }
  }
  if (!haveType || !haveSizes || dimension == 0) throw ioError(path, "header lacks type, dimension or sizes");
  if (encoding != "raw") throw ioError(path, "unsupported encoding '" + encoding + "' (only raw)");
  if (dims.x <= 0 || dims.y <= 0 || dims.z <= 0) throw ioError(path, "empty extent");
  v.allocate(dims, type);
  if (!dataFile.empty()) {
    std::string p = dataFile[0] == '/' ? dataFile : dirName(path) + "/" + dataFile;
    std::ifstream df(p, std::ios::binary);
    if (!df) throw ioError(path, "cannot open data file " + p);
    readExactly(df, v.mutableData(), v.byteSize(), p);
  } else {
    readExactly(in, v.mutableData(), v.byteSize(), path);
  }
  if (bigEndian) swapBytes(v);
  return v;
}

Volume loadVolume(const std::string& path) {
  auto ends = [&](const char* s) {
    size_t n = std::strlen(s);
    return path.size() >= n && path.compare(path.size() - n, n, s) == 0;
  };
  if (ends(".nrrd") || ends(".nhdr")) return loadNrrd(path);
  if (ends(".raw")) return loadRaw(path);
  throw ioError(path, "unknown volume format (expected .raw named NAME_XxYxZ_TYPE.raw, or .nrrd)");
}

void saveNrrd(const Volume& v, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw ioError(path, "cannot write");
  static const char* nrrdType[] = {"uint8", "int8", "uint16", "int16", "float", "double"};
  out << "NRRD0004\ntype: " << nrrdType[int(v.type)] << "\ndimension: 3\nsizes: " << v.dims.x << " "
      << v.dims.y << " " << v.dims.z << "\nspacings: " << v.spacing[0] << " " << v.spacing[1] << " "
      << v.spacing[2] << "\nencoding: raw\nendian: little\n\n";
  out.write(static_cast<const char*>(v.data), std::streamsize(v.byteSize()));
  if (!out) throw ioError(path, "write failed");
}

void saveRaw(const Volume& v, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw ioError(path, "cannot write");
  out.write(static_cast<const char*>(v.data), std::streamsize(v.byteSize()));
  if (!out) throw ioError(path, "write failed");
}

}  // namespace spaceskip

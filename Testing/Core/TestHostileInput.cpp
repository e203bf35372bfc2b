// Issue 14, readers and parsers: crafted files (written here at run time) and option values must
// give a clear error naming the file and field, quickly, without allocating what they claim.
#include "Environment.h"
#include "Options.h"
#include "spaceskip/OutputFile.h"
#include "spaceskip/TransferFunctionIO.h"
#include "spaceskip/VolumeIO.h"

#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>

using namespace spaceskip;
namespace fs = std::filesystem;

namespace {
struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() / ("spaceskip_hostile_" + std::to_string(::getpid()));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string file(const std::string& name, const std::string& bytes) const {
    const fs::path p = path / name;
    std::ofstream o(p, std::ios::binary);
    o << bytes;
    return p.string();
  }
};

/// Peak resident set of this process, MiB (monotonic: growth shows any large allocation).
double peakRssMiB() {
  rusage r{};
  getrusage(RUSAGE_SELF, &r);
  return double(r.ru_maxrss) / 1024.0;
}

/// Runs f, which must throw std::runtime_error within `seconds` and without raising peak RSS by
/// 64 MiB or more; returns the message.
std::string errorOf(const std::function<void()>& f, double seconds = 2.0) {
  const double rss0 = peakRssMiB();
  const auto t0 = std::chrono::steady_clock::now();
  std::string msg = "(no error)";
  try {
    f();
  } catch (const std::runtime_error& e) {
    msg = e.what();
  }
  const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(dt, seconds) << msg;
  EXPECT_LT(peakRssMiB() - rss0, 64.0) << "allocated before checking: " << msg;
  return msg;
}

#define EXPECT_HAS(msg, part) EXPECT_NE((msg).find(part), std::string::npos) << (msg)

const std::string kHeader3 = "NRRD0004\ntype: uint8\ndimension: 3\nencoding: raw\n";
}  // namespace

// --- sizes: overflow, cap, bytes present ---------------------------------------------------------

TEST(HostileInput, RawNameWhoseProductOverflowsIsRefused) {
  TempDir d;
  // Every axis within 2^30, product 2^90 voxels: wrapped to 0 before the fix.
  std::string p = d.file("v_1073741824x1073741824x1073741824_float64.raw", "");
  std::string m = errorOf([&] { loadVolume(p); });
  EXPECT_HAS(m, p);
  EXPECT_HAS(m, "overflows");
  // 2^32 per axis wraps a 64-bit product to 0 exactly.
  p = d.file("w_4294967296x4294967296x4294967296_uint8.raw", "");
  m = errorOf([&] { loadVolume(p); });
  EXPECT_HAS(m, "2^30");
  // Numbers beyond 64 bits do not parse as a raw name at all.
  vec3l dims;
  VoxelType t;
  EXPECT_FALSE(parseRawName("x_18446744073709551616x1x1_uint8.raw", dims, t));
  EXPECT_FALSE(parseRawName("x_-1x1x1_uint8.raw", dims, t));
  EXPECT_TRUE(parseRawName("x_9223372036854775807x1x1_uint8.raw", dims, t));
}

TEST(HostileInput, RawClaimLargerThanFileFailsBeforeAllocating) {
  TempDir d;
  // 1 GB claimed by an empty file: compared with the file size before any allocation.
  std::string p = d.file("e_1000x1000x1000_uint8.raw", "");
  std::string m = errorOf([&] { loadVolume(p); }, 1.0);
  EXPECT_HAS(m, p);
  EXPECT_HAS(m, "too short");
  // 10^15 bytes claimed, under an unlimited cap: still no allocation.
  p = d.file("f_100000x100000x100000_uint8.raw", "abc");
  ReadLimits unlimited;
  unlimited.maxBytes = std::numeric_limits<uint64_t>::max();
  m = errorOf([&] { loadVolume(p, unlimited); }, 1.0);
  EXPECT_HAS(m, "too short");
  // Under the default cap the claim is refused by the cap first, naming the limit.
  ReadLimits small;
  small.maxBytes = 1 << 20;
  m = errorOf([&] { loadVolume(p, small); });
  EXPECT_HAS(m, "more than the limit of 1048576");
}

TEST(HostileInput, TrailingBytesAreRefused) {
  TempDir d;
  std::string p = d.file("t_2x2x2_uint8.raw", std::string(9, '\1'));
  std::string m = errorOf([&] { loadVolume(p); });
  EXPECT_HAS(m, "1 trailing bytes");
  p = d.file("t.nrrd", kHeader3 + "sizes: 2 2 2\n\n" + std::string(8, '\1') + "extra");
  m = errorOf([&] { loadVolume(p); });
  EXPECT_HAS(m, p);
  EXPECT_HAS(m, "5 trailing bytes");
  // The exact size loads.
  p = d.file("ok.nrrd", kHeader3 + "sizes: 2 2 2\n\n" + std::string(8, '\1'));
  EXPECT_EQ(loadVolume(p).value(1, 1, 1), 1.0);
}

TEST(HostileInput, NrrdSizesThatOverflowOrExceedTheCap) {
  TempDir d;
  std::string p = d.file("o.nrrd", "NRRD0004\ntype: double\ndimension: 3\nencoding: raw\nendian: little\n"
                                   "sizes: 1073741824 1073741824 1073741824\n\n");
  std::string m = errorOf([&] { loadVolume(p); });
  EXPECT_HAS(m, "field 'sizes'");
  EXPECT_HAS(m, "overflows");
  p = d.file("o2.nrrd", kHeader3 + "sizes: 18446744073709551615 1 1\n\n");
  m = errorOf([&] { loadVolume(p); });
  EXPECT_HAS(m, "field 'sizes'");
  EXPECT_HAS(m, "not a positive 64-bit integer");
  p = d.file("o3.nrrd", kHeader3 + "sizes: -8 2 2\n\n");
  EXPECT_HAS(errorOf([&] { loadVolume(p); }), "field 'sizes'");
  // A terabyte claimed by a few bytes of data: "too short" without allocating it.
  p = d.file("big.nrrd", kHeader3 + "sizes: 1048576 1048576 1\n\nabc");
  ReadLimits unlimited;
  unlimited.maxBytes = std::numeric_limits<uint64_t>::max();
  m = errorOf([&] { loadVolume(p, unlimited); }, 1.0);
  EXPECT_HAS(m, "too short");
  EXPECT_HAS(m, "1099511627776");
}

// --- bounded header lines, non-regular files ----------------------------------------------------

TEST(HostileInput, DeviceFilesAndPipesAreRefusedWithoutReading) {
  TempDir d;
  if (fs::exists("/dev/zero")) {
    const fs::path link = d.path / "zero.nrrd";
    fs::create_symlink("/dev/zero", link);
    std::string m = errorOf([&] { loadVolume(link.string()); }, 1.0);
    EXPECT_HAS(m, "character device");
    const fs::path rawLink = d.path / "zero_64x64x64_uint8.raw";
    fs::create_symlink("/dev/zero", rawLink);
    EXPECT_HAS(errorOf([&] { loadVolume(rawLink.string()); }, 1.0), "character device");
    EXPECT_HAS(errorOf([&] { loadTransferFunction("/dev/zero", 0, 1); }, 1.0), "not a regular file");
  }
  // A FIFO with no writer: opening it would block forever.
  const fs::path fifo = d.path / "pipe.nrrd";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_HAS(errorOf([&] { loadVolume(fifo.string()); }, 1.0), "pipe");
  EXPECT_HAS(errorOf([&] { loadVolume(d.path.string() + "/"); }), "unknown volume format");
  const fs::path dir = d.path / "dir.nrrd";
  fs::create_directories(dir);
  EXPECT_HAS(errorOf([&] { loadVolume(dir.string()); }), "directory");
}

TEST(HostileInput, HeaderLinesAreBounded) {
  ReadLimits limits;
  // 64 MiB of NRRD magic without a newline (what /dev/zero-like input looks like to getline).
  {
    std::istringstream in("NRRD0004" + std::string(size_t(64) << 20, 'x'));
    std::string m = errorOf([&] { readNrrdHeader(in, "mem", limits); }, 1.0);
    EXPECT_HAS(m, "longer than 64 bytes");
  }
  {
    std::istringstream in("NRRD0004\ncontent: " + std::string(size_t(64) << 20, 'x'));
    EXPECT_HAS(errorOf([&] { readNrrdHeader(in, "mem", limits); }, 1.0), "longer than 4096 bytes");
  }
  {
    std::string many = "NRRD0004\n";
    while (many.size() < (size_t(2) << 20)) many += "# a comment line of the kind that never ends\n";
    std::istringstream in(many);
    EXPECT_HAS(errorOf([&] { readNrrdHeader(in, "mem", limits); }, 1.0), "header longer than 1048576 bytes");
  }
}

// --- strict NRRD fields -------------------------------------------------------------------------

TEST(HostileInput, NrrdFieldsInAnyOrder) {
  TempDir d;
  std::string data;
  for (int i = 0; i < 24; ++i) data.push_back(char(i));
  // sizes and spacings before dimension: was a 1x1x1 volume and a blank image, exit 0.
  std::string p = d.file("order.nrrd", "NRRD0004\nsizes: 4 3 2\nspacings: 0.5 1 2\nencoding: raw\n"
                                       "type: uint8\ndimension: 3\n\n" + data);
  Volume v = loadVolume(p);
  EXPECT_EQ(v.dims.x, 4);
  EXPECT_EQ(v.dims.y, 3);
  EXPECT_EQ(v.dims.z, 2);
  EXPECT_DOUBLE_EQ(v.spacing[0], 0.5);
  EXPECT_DOUBLE_EQ(v.spacing[2], 2.0);
  EXPECT_EQ(v.value(3, 2, 1), 23.0);
  // Space directions give spacing and direction; origin is kept.
  p = d.file("space.nrrd", "NRRD0005\ntype: uchar\ndimension: 3\nspace: left-posterior-superior\n"
                           "sizes: 4 3 2\nspace directions: (0,2,0) (-3,0,0) (0,0,0.5)\n"
                           "space origin: (10,-20,1e6)\nencoding: raw\nkinds: domain domain domain\n"
                           "key:=free text: with colons\n\n" + data);
  v = loadVolume(p);
  EXPECT_DOUBLE_EQ(v.spacing[0], 2.0);
  EXPECT_DOUBLE_EQ(v.spacing[1], 3.0);
  EXPECT_DOUBLE_EQ(v.direction[1 * 3 + 0], 1.0);   // axis 0 along +y
  EXPECT_DOUBLE_EQ(v.direction[0 * 3 + 1], -1.0);  // axis 1 along -x
  EXPECT_DOUBLE_EQ(v.origin[2], 1e6);
}

TEST(HostileInput, NrrdFieldErrorsNameTheField) {
  TempDir d;
  struct Case {
    const char* header;  // after the magic, before the blank line
    const char* expect;
  };
  const Case cases[] = {
      {"type: uint8\ndimension: 3\nsizes: 2 2\nencoding: raw\n", "field 'sizes': 2 values for dimension 3"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2 2\nencoding: raw\n", "field 'sizes': 4 values"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2x\nencoding: raw\n", "field 'sizes': '2x'"},
      {"type: uint8\ndimension: 2\nsizes: 2 2\nspacings: 1 1 1\nencoding: raw\n", "field 'spacings': 3 values"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nspacings: 1 0 1\nencoding: raw\n", "field 'spacings': '0'"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nspacings: 1 inf 1\nencoding: raw\n", "field 'spacings': 'inf'"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\n", "field 'encoding': required field missing"},
      {"type: uint8\nsizes: 2 2 2\nencoding: raw\n", "field 'dimension': required field missing"},
      {"dimension: 3\nsizes: 2 2 2\nencoding: raw\n", "field 'type': required field missing"},
      {"type: uint8\ndimension: 3\nencoding: raw\n", "field 'sizes': required field missing"},
      {"type: uint8\ndimension: 4\nsizes: 1 2 2 2\nencoding: raw\n", "field 'dimension'"},
      {"type: int32\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n", "field 'type': unsupported NRRD type 'int32'"},
      {"type: uint16\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n", "field 'endian': required field missing"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nsizes: 2 2 2\nencoding: raw\n", "field 'sizes': given more than once"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndatafile: a\ndata file: b\n", "field 'data file': given more than once"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ncolour: red\n", "unknown NRRD field 'colour'"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nbyte skip: -1\n", "field 'byte skip'"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nspacings: 1 1 1\nspace directions: (1,0,0) (0,1,0) (0,0,1)\n",
       "field 'spacings': may not be given together"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nspace directions: (1,0,0) (0,0,0) (0,0,1)\n",
       "field 'space directions': axis 1"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nspace origin: (1,2)\n", "field 'space origin'"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nspace directions: (1,0,0) (2,0,0) (0,0,1)\n",
       "field 'space directions': the axes are parallel"},
      {"type: uint8\ndimension: 2\nsizes: 2 4\nencoding: raw\nspace directions: (0,0,1) (0,1,0)\n",
       "field 'space directions': the axes are parallel"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: slice%03d.raw 0 9 1\n", "field 'data file'"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nsizes:2 2 2\n", "malformed NRRD field"},
      // Issue 41: a colour or vector axis was read as space (the components side by side).
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nkinds: RGB-color domain domain\n",
       "field 'kinds': axis 0 is 'RGB-color' (2 components per voxel): only scalar volumes"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nkinds: domain vector domain\n", "axis 1 is 'vector'"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nkinds: domain domain list\n", "axis 2 is 'list'"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nkinds: domain domain\n", "field 'kinds': 2 values for dimension 3"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nkinds: domain domain domain domain\n", "field 'kinds': 4 values"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nkinds: domain colour domain\n", "'colour' is not a NRRD kind"},
      {"type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nkinds: domain stub domain\n", "axis 1 is 'stub' but has 2 samples"},
  };
  int i = 0;
  for (const Case& c : cases) {
    std::string p = d.file("c" + std::to_string(i++) + ".nrrd", std::string("NRRD0004\n") + c.header + "\n" + std::string(8, '\0'));
    std::string m = errorOf([&] { loadVolume(p); });
    EXPECT_HAS(m, p);
    EXPECT_HAS(m, c.expect);
  }
}

TEST(HostileInput, DetachedNrrdDataIsCheckedLikeAttached) {
  TempDir d;
  d.file("data.bin", std::string(8, '\2') + "x");
  std::string p = d.file("h.nhdr", kHeader3 + "sizes: 2 2 2\ndata file: data.bin\n");
  std::string m = errorOf([&] { loadVolume(p); });
  EXPECT_HAS(m, "data.bin");
  EXPECT_HAS(m, "1 trailing bytes");
  d.file("data.bin", std::string(8, '\2'));
  EXPECT_EQ(loadVolume(p).value(1, 1, 1), 2.0);
  p = d.file("h2.nhdr", kHeader3 + "sizes: 2 2 2\ndata file: data.bin\n\nattached too");
  EXPECT_HAS(errorOf([&] { loadVolume(p); }), "bytes after the header");
  p = d.file("h3.nhdr", kHeader3 + "sizes: 2 2 2\ndata file: missing.bin\n");
  EXPECT_HAS(errorOf([&] { loadVolume(p); }), "missing.bin");
}

// --- validate() and allocate(): every path a volume enters ----------------------------------------

TEST(HostileInput, ValidateRefusesOverflowingDims) {
  unsigned char byte = 0;
  Volume v;
  v.data = &byte;
  v.type = VoxelType::Float64;
  v.dims = vec3l{int64_t(1) << 30, int64_t(1) << 30, int64_t(1) << 30};
  EXPECT_HAS(errorOf([&] { validate(v); }), "overflows");
  v.dims = vec3l{(int64_t(1) << 30) + 1, 1, 1};
  EXPECT_HAS(errorOf([&] { validate(v); }), "2^30");
  v.dims = vec3l{4, -1, 4};
  EXPECT_HAS(errorOf([&] { validate(v); }), "extent");
  v.dims = vec3l{4, 4, 4};
  EXPECT_NO_THROW(validate(v));
  Volume a;
  EXPECT_HAS(errorOf([&] { a.allocate(vec3l{int64_t(1) << 30, int64_t(1) << 30, 1 << 20}, VoxelType::UInt8); }),
             "overflows");
  EXPECT_EQ(a.data, nullptr);  // left untouched
  EXPECT_EQ(checkedByteSize(vec3l{2048, 2048, 2048}, VoxelType::Float32, uint64_t(32) << 30, "x"), uint64_t(32) << 30);
  EXPECT_HAS(errorOf([&] { checkedByteSize(vec3l{2048, 2048, 2048}, VoxelType::Float32, (uint64_t(32) << 30) - 1, "x"); }),
             "more than the limit");
}

TEST(HostileInput, CliCapFollowsTheEnvironment) {
  // SPACESKIP_MAX_VOLUME_BYTES is the CLI's (Core/cli/Environment.h): the library's default cap
  // reads no environment.
  const char* old = std::getenv("SPACESKIP_MAX_VOLUME_BYTES");
  const std::string saved = old ? old : "";
  setenv("SPACESKIP_MAX_VOLUME_BYTES", "3M", 1);
  EXPECT_EQ(cli::maxVolumeBytesFromEnvironment(7), uint64_t(3) << 20);
  EXPECT_EQ(cli::maxVolumeBytes(cli::Options{}), uint64_t(3) << 20);
  EXPECT_EQ(ReadLimits{}.maxBytes, defaultMaxVolumeBytes());
  EXPECT_GT(defaultMaxVolumeBytes(), uint64_t(3) << 20);
  setenv("SPACESKIP_MAX_VOLUME_BYTES", "12abc", 1);
  EXPECT_HAS(errorOf([] { cli::maxVolumeBytesFromEnvironment(7); }), "SPACESKIP_MAX_VOLUME_BYTES");
  unsetenv("SPACESKIP_MAX_VOLUME_BYTES");
  EXPECT_EQ(cli::maxVolumeBytesFromEnvironment(7), uint64_t(7));
  if (old) setenv("SPACESKIP_MAX_VOLUME_BYTES", saved.c_str(), 1);
  EXPECT_GE(defaultMaxVolumeBytes(), uint64_t(1) << 20);
  EXPECT_LE(defaultMaxVolumeBytes(), uint64_t(64) << 30);
}

// --- transfer-function files ---------------------------------------------------------------------

TEST(HostileInput, TransferFunctionFilesAreStrictAndBounded) {
  auto tfError = [](const std::string& text) {
    return errorOf([&] {
      std::istringstream in(text);
      readTransferFunction(in, "tf.txt", 0, 1);
    });
  };
  EXPECT_HAS(tfError("size 2000000000\n0 1 1 1 1\n"), "tf.txt:1: expected 'size N'");
  EXPECT_HAS(tfError("0 1 1 1 1\nnan 1 1 1 1\n"), "tf.txt:2:");
  EXPECT_HAS(tfError("0 1 1 1 1\n1 1 1 1 1 junk\n"), "tf.txt:2:");
  EXPECT_HAS(tfError("0 1 1 1 2\n"), "r, g, b, a in [0, 1]");
  EXPECT_HAS(tfError("range 1 inf\n0 1 1 1 1\n"), "range");
  EXPECT_HAS(tfError("unit 0\n0 1 1 1 1\n"), "unit");
  EXPECT_HAS(tfError("# only a comment\n"), "no control points");
  EXPECT_HAS(tfError(std::string(size_t(8) << 20, '1')), "longer than 4096");
  std::istringstream ok("# grey ramp\nrange 0 10\nsize 16\nunit 2\n0 0 0 0 0\n10 1 1 1 1\n");
  TransferFunction tf = readTransferFunction(ok, "ok", 0, 1);
  EXPECT_EQ(tf.table.size(), 16u);
  EXPECT_DOUBLE_EQ(tf.rangeMax, 10.0);
  EXPECT_DOUBLE_EQ(tf.unitDistance, 2.0);
}

// --- command-line values -------------------------------------------------------------------------

TEST(HostileInput, CliValuesAreParsedStrictly) {
  using namespace spaceskip::cli;
  auto argError = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_HAS(argError([] { parseIntArg("12abc", "--mls", 0, 100); }), "--mls: '12abc' is not an integer");
  EXPECT_HAS(argError([] { parseIntArg("99999999999999999999", "--mls", 0, 100); }), "not an integer");
  EXPECT_HAS(argError([] { parseIntArg("101", "--mls", 0, 100); }), "out of range [0, 100]");
  EXPECT_HAS(argError([] { parseIntArg("", "--mls", 0, 100); }), "not an integer");
  EXPECT_HAS(argError([] { parseDoubleArg("nan", "--ert", 0, 1); }), "not a finite number");
  EXPECT_HAS(argError([] { parseDoubleArg("1e999", "--ert", 0, 1); }), "not a finite number");
  EXPECT_DOUBLE_EQ(parseDoubleArg("+2.5e-1", "--ert", 0, 1), 0.25);
  EXPECT_HAS(argError([] { parseDims("4294967296", "--dims"); }), "out of range");
  EXPECT_HAS(argError([] { parseDims("2x2", "--dims"); }), "not N or XxYxZ");
  EXPECT_HAS(argError([] { parseDims("2x-2x2", "--dims"); }), "out of range");
  vec3l d = parseDims("3x4x5", "--dims");
  EXPECT_EQ(d.y, 4);
  int w = 0, h = 0;
  EXPECT_HAS(argError([&] { parseSize("0x10", w, h); }), "--size (width)");
  EXPECT_HAS(argError([&] { parseSize("10x10x", w, h); }), "--size (height)");
  EXPECT_HAS(argError([&] { parseSize("100000x10", w, h); }), "out of range");
  double az, el, zoom;
  EXPECT_HAS(argError([&] { parseCamera("10,20,0", az, el, zoom); }), "zoom");
  EXPECT_HAS(argError([&] { parseCamera("10", az, el, zoom); }), "AZ,EL");
  const char* argv[] = {"spaceskip", "render", "--bins", "-1", "--mls", "32"};
  Options o = parseArgs(6, argv, 2);
  EXPECT_HAS(argError([&] { buildParams(o, "grid"); }), "--bins: '-1' is out of range");
  EXPECT_HAS(argError([&] { buildParams(Options{}, "kdtree-cpu:mls99999999999"); }), "builder suffix 'mls'");
  EXPECT_HAS(argError([&] { buildParams(Options{}, "kdtree-gpu:bins1"); }), "bad bins 1");
  const char* typo[] = {"spaceskip", "render", "--sampel-distance", "1"};
  EXPECT_HAS(argError([&] { parseArgs(4, typo, 2); }), "'--sampel-distance' is not an option");
  const char* noValue[] = {"spaceskip", "render", "--mls"};
  EXPECT_HAS(argError([&] { parseArgs(3, noValue, 2); }), "--mls needs a value");
  // A generated volume is size-checked before anything is generated.
  std::string shape;
  EXPECT_HAS(errorOf([&] { parseGeneratorSpec("gen:noise:1024", 1 << 20, shape, d); }), "more than the limit");
  EXPECT_TRUE(parseGeneratorSpec("gen:menger:64", 1 << 20, shape, d));
  EXPECT_FALSE(parseGeneratorSpec("menger.nrrd", 1 << 20, shape, d));
  // Issue 41: the image budget names the size, its bytes and the option that raises it.
  Options image;
  image.kv["--size"] = "16384x16384";
  EXPECT_HAS(argError([&] { imageSize(image, w, h); }),
             "--size 16384x16384: the image takes 4294967296 bytes (4.00 GiB at 16 bytes a pixel), more than the "
             "image budget of 1073741824 bytes (1.00 GiB); raise it with --max-image-bytes");
  image.kv["--max-image-bytes"] = "4G";
  imageSize(image, w, h);
  EXPECT_EQ(w, 16384);
  w = 512, h = 512;
  imageSize(Options{}, w, h);  // the command's default stays
  EXPECT_EQ(w, 512);
  image.kv["--max-image-bytes"] = "0";
  EXPECT_HAS(argError([&] { imageSize(image, w, h); }), "--max-image-bytes: '0' is not a positive byte count");
  Options cap;
  cap.kv["--max-volume-bytes"] = "64Q";
  EXPECT_HAS(argError([&] { maxVolumeBytes(cap); }), "--max-volume-bytes");
  cap.kv["--max-volume-bytes"] = "64M";
  EXPECT_EQ(maxVolumeBytes(cap), uint64_t(64) << 20);
}

// --- output files (issue 41): a failed write leaves what was there --------------------------------

TEST(HostileInput, OutputFileLeavesTheTargetOnAFailedWrite) {
  TempDir d;
  const std::string target = d.file("keep.csv", "old contents\n");
  const std::string link = (d.path / "link.csv").string();
  fs::create_symlink("keep.csv", link);
  auto onlyTheTwo = [&] {
    int n = 0;
    for (const auto& e : fs::directory_iterator(d.path)) n += e.path().filename().string()[0] == '.' ? 100 : 1;
    EXPECT_EQ(n, 2) << "a temporary file was left behind";
  };
  // A write error on a regular file (as on a full disk): the file-size limit makes write() fail
  // with EFBIG, its signal ignored.
  rlimit old{};
  getrlimit(RLIMIT_FSIZE, &old);
  auto* prev = std::signal(SIGXFSZ, SIG_IGN);
  rlimit small = old;
  small.rlim_cur = 4096;
  setrlimit(RLIMIT_FSIZE, &small);
  std::string msg = "(no error)";
  try {
    OutputFile f(link);
    f.stream() << std::string(1 << 20, 'x');
    f.commit();
  } catch (const std::runtime_error& e) {
    msg = e.what();
  }
  setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, prev);
  EXPECT_HAS(msg, link + ": cannot write: File too large");
  EXPECT_TRUE(fs::is_symlink(link));
  std::ifstream in(target);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "old contents\n");
  onlyTheTwo();
  // Destroyed without commit(): nothing changes either.
  { OutputFile f(target); f.stream() << "new"; }
  onlyTheTwo();
  // Committed through the link: the link stays, its target has the new contents and keeps its mode.
  fs::permissions(target, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  writeOutputFile(link, "new contents\n");
  EXPECT_TRUE(fs::is_symlink(link));
  std::ifstream again(target);
  text.assign(std::istreambuf_iterator<char>(again), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "new contents\n");
  EXPECT_EQ(fs::status(target).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  onlyTheTwo();
  // What can be known before writing fails at once, naming the path and the cause.
  EXPECT_HAS(errorOf([&] { OutputFile f((d.path / "no" / "x.csv").string()); }), "the folder '");
  EXPECT_HAS(errorOf([&] { OutputFile f(d.path.string()); }), "is a directory");
  EXPECT_HAS(errorOf([&] { OutputFile f(target + "/x.csv"); }), "is not a folder");
}

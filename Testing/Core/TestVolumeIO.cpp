// Raw/NRRD parsing: good files load, malformed ones give clear errors.
#include "spaceskip/VolumeIO.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

using namespace spaceskip;
namespace fs = std::filesystem;

namespace {
fs::path tmpDir() {
  fs::path p = fs::temp_directory_path() / ("spaceskip_io_" + std::to_string(::getpid()));
  fs::create_directories(p);
  return p;
}
void writeFile(const fs::path& p, const std::string& bytes) {
  std::ofstream o(p, std::ios::binary);
  o << bytes;
}
std::string errorOf(const std::string& path) {
  try {
    loadVolume(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(VolumeIO, ParsesRawNames) {
  vec3l d;
  VoxelType t;
  ASSERT_TRUE(parseRawName("/a/b/aneurism_256x256x128_uint16.raw", d, t));
  EXPECT_EQ(d.x, 256);
  EXPECT_EQ(d.z, 128);
  EXPECT_EQ(t, VoxelType::UInt16);
  EXPECT_TRUE(parseRawName("x_1x2x3_float32.raw", d, t));
  EXPECT_EQ(t, VoxelType::Float32);
  EXPECT_FALSE(parseRawName("volume.raw", d, t));
  EXPECT_FALSE(parseRawName("v_2x2_uint8.raw", d, t));
  EXPECT_FALSE(parseRawName("v_2x2x2_complex.raw", d, t));
}

TEST(VolumeIO, RawRoundTripAndSizeMismatch) {
  fs::path dir = tmpDir();
  Volume v;
  v.allocate(vec3l{3, 2, 2}, VoxelType::Int16);
  for (int i = 0; i < 12; ++i) reinterpret_cast<int16_t*>(v.mutableData())[i] = int16_t(i * 100 - 500);
  std::string p = (dir / "t_3x2x2_int16.raw").string();
  saveRaw(v, p);
  Volume r = loadVolume(p);
  EXPECT_EQ(r.value(2, 1, 1), v.value(2, 1, 1));
  std::string bad = (dir / "t_4x2x2_int16.raw").string();
  fs::copy_file(p, bad, fs::copy_options::overwrite_existing);
  EXPECT_NE(errorOf(bad).find("does not match"), std::string::npos) << errorOf(bad);
}

TEST(VolumeIO, NrrdRoundTripAndErrors) {
  fs::path dir = tmpDir();
  Volume v;
  v.allocate(vec3l{4, 3, 2}, VoxelType::Float32);
  for (int i = 0; i < 24; ++i) reinterpret_cast<float*>(v.mutableData())[i] = float(i) * 0.5f;
  v.spacing[0] = 0.5;
  v.spacing[2] = 2.0;
  std::string p = (dir / "v.nrrd").string();
  saveNrrd(v, p);
  Volume r = loadVolume(p);
  EXPECT_EQ(r.dims.x, 4);
  EXPECT_EQ(r.type, VoxelType::Float32);
  EXPECT_DOUBLE_EQ(r.spacing[2], 2.0);
  EXPECT_DOUBLE_EQ(r.value(3, 2, 1), v.value(3, 2, 1));

  // Malformed files: each error names what is wrong.
  struct Bad {
    const char* file;
    const char* bytes;
    const char* error;
  };
  const Bad bad[] = {
      {"nomagic.nrrd", "HELLO\n", "not a NRRD"},
      {"gzip.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: gzip\n\n", "encoding"},
      {"short.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\nabc", "too short"},
      {"badtype.nrrd", "NRRD0004\ntype: quaternion\ndimension: 3\nsizes: 2 2 2\n\n", "unsupported NRRD type"},
      {"nosizes.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\n\n", "field 'sizes': required field missing"},
      {"zero.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 0 2 2\nencoding: raw\n\n",
       "field 'sizes': '0' is not a positive"},
  };
  for (const Bad& c : bad) {
    writeFile(dir / c.file, c.bytes);
    EXPECT_NE(errorOf((dir / c.file).string()).find(c.error), std::string::npos) << c.file;
  }
  std::string header = "NRRD0004\ntype: uint16\nendian: big\ndimension: 1\nsizes: 2\nencoding: raw\n\n";
  writeFile(dir / "big.nrrd", header + std::string("\x01\x02\x00\x05", 4));
  Volume b = loadVolume((dir / "big.nrrd").string());
  EXPECT_EQ(b.value(0, 0, 0), 0x0102);
  EXPECT_EQ(b.value(1, 0, 0), 5);
  EXPECT_NE(errorOf((dir / "missing.nrrd").string()).find("cannot open"), std::string::npos);
  EXPECT_NE(errorOf((dir / "file.vtk").string()).find("unknown volume format"), std::string::npos);
  fs::remove_all(dir);
}

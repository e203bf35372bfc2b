// The builder registry (Builders.h) is the one list of builders: the CLI's names, the VTK
// mapper's enum and the plugin XML's menu must agree with it, row for row. The mapper header and
// the XML are read as text, so this runs without VTK.
#include "spaceskip/Builders.h"
#include "Options.h"

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

using namespace spaceskip;

namespace {

std::string readSource(const std::string& rel) {
  std::ifstream in(std::string(SPACESKIP_SOURCE_DIR) + "/" + rel);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<BuilderInfo> rows() {
  int n = 0;
  const BuilderInfo* r = builderRegistry(&n);
  return std::vector<BuilderInfo>(r, r + n);
}

}  // namespace

TEST(BuilderRegistry, OneRowPerKindInOrder) {
  const auto r = rows();
  ASSERT_EQ(int(r.size()), int(BuilderKind::Auto) + 1);
  for (size_t i = 0; i < r.size(); ++i) {
    EXPECT_EQ(int(r[i].kind), int(i));
    EXPECT_STREQ(builderName(r[i].kind), r[i].name);
    EXPECT_EQ(traversalFor(r[i].kind), r[i].traversal);
    // A tree builder must build somewhere: on the host, on the device (in a build with CUDA), and
    // its fallback on the CPU backend.
    if (buildsTree(r[i]) && r[i].kind != BuilderKind::Auto) {
#if SPACESKIP_HAVE_CUDA
      EXPECT_TRUE(r[i].cpu || r[i].cuda) << r[i].name;
#else
      EXPECT_TRUE(r[i].cpu || r[i].fallback != r[i].kind) << r[i].name;
#endif
      EXPECT_TRUE(runsOnCpu(builderInfo(r[i].fallback))) << r[i].name << "'s fallback must run on the CPU backend";
    }
  }
}

TEST(BuilderRegistry, CliAndVtkNamesParse) {
  for (const BuilderInfo& b : rows()) {
    BuilderKind k{};
    ASSERT_TRUE(parseBuilder(b.cliName, k)) << b.cliName;
    EXPECT_EQ(k, b.kind);
    ASSERT_TRUE(parseBuilder(b.name, k)) << b.name;
    EXPECT_EQ(k, b.kind);
    // The CLI's builder specs (with suffixes) go through the same table.
    BuildParams p = cli::buildParams(cli::Options{}, std::string(b.cliName) + ":deep");
    EXPECT_EQ(p.builder, b.kind);
  }
}

TEST(BuilderRegistry, MapperEnumMatches) {
  const std::string h = readSource("VTKModule/vtkSpaceSkippingVolumeMapper.h");
  const size_t at = h.find("enum BuilderTypes");
  ASSERT_NE(at, std::string::npos);
  const std::string body = h.substr(at, h.find("};", at) - at);
  std::vector<std::string> names;
  const std::regex entry(R"(^\s*([A-Za-z]\w*)\s*(=\s*0\s*)?,?\s*(///.*)?$)");
  std::istringstream lines(body.substr(body.find('{') + 1));
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (std::regex_match(line, m, entry)) names.push_back(m[1]);
  }
  const auto r = rows();
  ASSERT_EQ(names.size(), r.size());
  for (size_t i = 0; i < r.size(); ++i)
    EXPECT_TRUE(names[i] == r[i].name || names[i] == std::string(r[i].name) + "Builder")
        << "mapper enum entry " << i << " is " << names[i] << ", the registry says " << r[i].name;
}

TEST(BuilderRegistry, PluginMenuMatches) {
  const std::string xml = readSource("Plugin/SpaceSkipRepresentation.xml");
  const size_t at = xml.find("name=\"Builder\"");
  ASSERT_NE(at, std::string::npos);
  const size_t end = xml.find("</EnumerationDomain>", at);
  ASSERT_NE(end, std::string::npos);
  const std::string menu = xml.substr(at, end - at);
  std::vector<std::pair<int, std::string>> entries;
  const std::regex entry(R"re(<Entry\s+value="(\d+)"\s+text="([^"]+)")re");
  for (auto it = std::sregex_iterator(menu.begin(), menu.end(), entry); it != std::sregex_iterator(); ++it)
    entries.emplace_back(std::stoi((*it)[1]), (*it)[2]);
  const auto r = rows();
  ASSERT_EQ(entries.size(), r.size());
  for (size_t i = 0; i < r.size(); ++i) {
    EXPECT_EQ(entries[i].first, int(r[i].kind));
    EXPECT_EQ(entries[i].second, r[i].name);
  }
}

// The filter modes: Core's FilterMode, the mapper's FilterModeTypes and the plugin's Filter Mode
// menu name the same values in the same order (the mapper casts its value to FilterMode).
TEST(BuilderRegistry, FilterModeMatchesMapperAndPlugin) {
  const std::vector<std::pair<FilterMode, std::string>> modes{{FilterMode::Exact, "Exact"},
                                                              {FilterMode::Hardware, "Hardware"}};
  const std::string h = readSource("VTKModule/vtkSpaceSkippingVolumeMapper.h");
  const size_t at = h.find("enum FilterModeTypes");
  ASSERT_NE(at, std::string::npos);
  const std::string body = h.substr(at, h.find("};", at) - at);
  const std::regex entry(R"((\w+)Filter\s*=\s*(\d+))");
  std::vector<std::pair<int, std::string>> mapper;
  for (auto it = std::sregex_iterator(body.begin(), body.end(), entry); it != std::sregex_iterator(); ++it)
    mapper.emplace_back(std::stoi((*it)[2]), (*it)[1]);
  const std::string xml = readSource("Plugin/SpaceSkipRepresentation.xml");
  const size_t x = xml.find("name=\"FilterMode\"");
  ASSERT_NE(x, std::string::npos);
  const std::string menu = xml.substr(x, xml.find("</EnumerationDomain>", x) - x);
  const std::regex xmlEntry(R"re(<Entry\s+value="(\d+)"\s+text="([^"]+)")re");
  std::vector<std::pair<int, std::string>> plugin;
  for (auto it = std::sregex_iterator(menu.begin(), menu.end(), xmlEntry); it != std::sregex_iterator(); ++it)
    plugin.emplace_back(std::stoi((*it)[1]), (*it)[2]);
  ASSERT_EQ(mapper.size(), modes.size());
  ASSERT_EQ(plugin.size(), modes.size());
  for (size_t i = 0; i < modes.size(); ++i) {
    EXPECT_EQ(mapper[i].first, int(modes[i].first)) << modes[i].second;
    EXPECT_EQ(mapper[i].second, modes[i].second);
    EXPECT_EQ(plugin[i].first, int(modes[i].first)) << modes[i].second;
    EXPECT_EQ(plugin[i].second, modes[i].second);
  }
}

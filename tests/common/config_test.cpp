#include "mbot/common/config.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace mbot::config {
namespace {

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(ConfigTest, TypedGettersAndDefaults) {
  auto c = Config::FromString("[a]\nx = 3\ny = 2.5\nflag = yes\nlist = a, b ,c\n", "t.ini");
  Section s = c.GetSection("a");
  EXPECT_EQ(s.GetInt("x", 0, ""), 3);
  EXPECT_DOUBLE_EQ(s.GetDouble("y", 0, ""), 2.5);
  EXPECT_TRUE(s.GetBool("flag", false, ""));
  EXPECT_EQ(s.GetList("list", {}, ""), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(s.GetInt("missing", 7, ""), 7);
  EXPECT_NO_THROW(s.Finish());
}

TEST(ConfigTest, UnknownKeyNamesFileLineSectionAndKnownKeys) {
  auto c = Config::FromString("[a]\nx = 3\n\ntypo = 1\n", "t.ini");
  Section s = c.GetSection("a");
  s.GetInt("x", 0, "");
  const std::string e = ErrorOf([&] { s.Finish(); });
  EXPECT_NE(e.find("t.ini:4: [a] typo: unknown key (known keys: x)"), std::string::npos) << e;
}

TEST(ConfigTest, MissingRequiredKeyNamesFileSectionAndKey) {
  auto c = Config::FromString("[a]\n", "t.ini");
  Section s = c.GetSection("a");
  const std::string e = ErrorOf([&] { s.RequireString("path", "the input"); });
  EXPECT_NE(e.find("t.ini: [a] path: required key is missing"), std::string::npos) << e;
}

TEST(ConfigTest, MalformedAndOutOfRangeValues) {
  auto c = Config::FromString("[a]\nn = 3x\nd = 5\nb = maybe\nch = z\n", "t.ini");
  Section s = c.GetSection("a");
  EXPECT_NE(ErrorOf([&] { s.GetInt("n", 0, ""); }).find("t.ini:2: [a] n: expected an integer"), std::string::npos);
  EXPECT_NE(ErrorOf([&] { s.GetDouble("d", 0, "", 0.0, 1.0); }).find("t.ini:3: [a] d: value 5 out of range"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { s.GetBool("b", false, ""); }).find("expected true or false"), std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              s.GetChoice("ch", "x", {"x", "y"}, "");
            }).find("'z' is not one of: x, y"),
            std::string::npos);
}

TEST(ConfigTest, SyntaxErrorsNameTheLine) {
  EXPECT_NE(ErrorOf([] { Config::FromString("[a]\njunk\n", "t.ini"); }).find("t.ini:2: expected 'key = value'"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { Config::FromString("x = 1\n", "t.ini"); }).find("t.ini:1: key 'x' outside any section"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { Config::FromString("[a]\nx = 1\nx = 2\n", "t.ini"); }).find("set twice"), std::string::npos);
}

TEST(ConfigTest, IncludeThenOverrideThenSet) {
  const auto dir = std::filesystem::temp_directory_path() / "mbot_config_test";
  std::filesystem::create_directories(dir / "sub");
  std::ofstream(dir / "sub" / "base.ini") << "[a]\nx = 1\ny = 1\nz = 1\n";
  std::ofstream(dir / "main.ini") << "include = sub/base.ini  # shared defaults\n[a]\ny = 2\nz = 2\n";
  auto c = Config::Load((dir / "main.ini").string());
  c.Set("a.z=3");
  Section s = c.GetSection("a");
  EXPECT_EQ(s.GetInt("x", 0, ""), 1);
  EXPECT_EQ(s.GetInt("y", 0, ""), 2);
  EXPECT_EQ(s.GetInt("z", 0, ""), 3);
  EXPECT_NE(c.ToIni().find("z = 3    # --set"), std::string::npos);
  EXPECT_NE(c.ToIni().find("x = 1    # " + (dir / "sub" / "base.ini").string() + ":2"), std::string::npos);
}

TEST(ConfigTest, IncludeCycleAndMissingFileAreErrors) {
  const auto dir = std::filesystem::temp_directory_path() / "mbot_config_cycle";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "a.ini") << "include = b.ini\n";
  std::ofstream(dir / "b.ini") << "include = a.ini\n";
  EXPECT_NE(ErrorOf([&] { Config::Load((dir / "a.ini").string()); }).find("include cycle"), std::string::npos);
  EXPECT_NE(ErrorOf([&] { Config::Load((dir / "none.ini").string()); }).find("cannot open"), std::string::npos);
}

TEST(ConfigTest, MalformedSetIsAnError) {
  auto c = Config::FromString("", "t.ini");
  EXPECT_THROW(c.Set("novalue"), ConfigError);
  EXPECT_THROW(c.Set("nodot=1"), ConfigError);
}

TEST(ConfigTest, PathVariablesExpand) {
  auto c = Config::FromString("[a]\np = ${datasets}/x\nq = ${nope}/x\n", "cfg/t.ini");
  Section s = c.GetSection("a");
  EXPECT_EQ(s.GetPath("p", "", ""), DatasetsDir() + "/x");
  EXPECT_NE(ErrorOf([&] { s.GetPath("q", "", ""); }).find("unknown variable ${nope}"), std::string::npos);
}

TEST(ConfigTest, DescribeModeRecordsKeysWithoutReading) {
  Section s = Section::Describe("stage");
  EXPECT_EQ(s.GetInt("n", 5, "count"), 5);
  s.RequirePath("path", "input");
  ASSERT_EQ(s.docs().size(), 2u);
  EXPECT_EQ(s.docs()[0].default_value, "5");
  EXPECT_TRUE(s.docs()[1].required);
}

}  // namespace
}  // namespace mbot::config

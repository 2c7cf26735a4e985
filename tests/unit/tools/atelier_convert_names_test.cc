// Names are data: an input named with bytes that are not UTF-8, a newline or an escape
// character converts like any other, and every text output stays valid UTF-8.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "convert/common/display_text.h"
#include "tests/support/convert_tool.h"

namespace {

namespace fs = std::filesystem;

const fs::path kData = ATELIER_TEST_DATA;

struct NameCase {
  std::string label;
  std::string kind;
  std::string params;  // --set arguments for a quick job
};

// Text without its line breaks and tabs must already be what safe_text makes of it.
bool valid_text(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\t' || c == '\r') c = ' ';
  return atelier::safe_text(s) == s;
}

class NamesTest : public atelier::test::ConvertToolFixture,
                  public ::testing::WithParamInterface<std::tuple<NameCase, std::string>> {};

TEST_P(NamesTest, AnInputWithAnyNameConvertsAndItsOutputsAreValid) {
  const auto& [c, stem] = GetParam();
  fs::path input;
  if (c.kind == "lace") {
    input = dir_ / (stem + ".toml");
    write(input, "kind = \"lace\"\npopulation = 10\ngenerations = 2\nwidth = 6\nrows = 4\n");
  } else if (c.kind == "cut") {
    input = dir_ / (stem + ".svg");
    fs::copy_file(kData / "svg" / "sample-box.svg", input);
  } else {
    input = dir_ / (stem + ".png");
    cv::Mat m = cv::imread((kData / "pic3.png").string());
    cv::resize(m, m, cv::Size(48, 48));
    cv::imwrite(input.string(), m);
  }
  std::string args = c.kind + " " + q(input) + " " + q(dir_ / "out") + " " + c.params;
  if (c.kind == "parquetry") args += " --set wood=" + q(kData / "wood");
  ASSERT_EQ(tool(args), 0) << err();
  for (const auto& entry : fs::directory_iterator(dir_ / "out")) {
    const std::string ext = entry.path().extension().string();
    const std::string text = slurp(entry.path());
    if (ext == ".json") EXPECT_NO_THROW((void)nlohmann::json::parse(text)) << entry.path();
    if (ext == ".json" || ext == ".svg" || ext == ".txt" || ext == ".k" || ext == ".gcode")
      EXPECT_TRUE(valid_text(text)) << entry.path();
    if (ext == ".pdf") EXPECT_GT(text.size(), 100u) << entry.path();
  }
  const nlohmann::json report = nlohmann::json::parse(slurp(dir_ / "out" / "report.json"));
  EXPECT_THAT(report.dump(), ::testing::HasSubstr("caf")) << report.dump();
}

INSTANTIATE_TEST_SUITE_P(
    EachKind, NamesTest,
    ::testing::Combine(
        ::testing::Values(NameCase{"knit", "knit", "--set width=24"},
                          NameCase{"lace", "lace", ""},
                          NameCase{"sketch", "sketch", "--set max_lines=20"},
                          NameCase{"embroidery", "embroidery", ""},
                          NameCase{"parquetry", "parquetry",
                                   "--set dpi=25.4 --set size_mm=42 --set patch_mm=14 --set rotations=2"},
                          NameCase{"cut", "cut", ""}),
        ::testing::Values(std::string("caf\xe9"), std::string("caf\xc3\xa9 new\nline \x1b[31mred"))),
    [](const auto& info) {
      return std::get<0>(info.param).label + (std::get<1>(info.param).size() == 4 ? "_latin1" : "_controls");
    });

}  // namespace

// A file that fails to parse is never echoed: the reason says file, line and the kind of
// problem, not the bytes read (a job could point the daemon at a file its author cannot read).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tests/support/convert_tool.h"

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

const fs::path kData = ATELIER_TEST_DATA;
const std::string kSecret = "SECRET-MARKER-7f3a";

struct SecretCase {
  std::string name;
  std::string kind;
  std::string file;      // the file holding the secret, beside the input
  std::string content;   // with kSecret in it
  std::string layer;     // the sidecar (or lace job file) naming it
  std::string expect;    // in the reason (the file's name or a position)
};

std::vector<SecretCase> cases() {
  const std::string shadow = "root:" + kSecret + ":20228:0:99999:7:::\n";
  const std::string lace = "kind = \"lace\"\ngenerations = 0\npopulation = 4\n";
  return {
      {"lace_instructions_txt", "lace", "shadow.txt", shadow, lace + "start_chart = \"shadow.txt\"\n", "shadow.txt"},
      {"lace_chart_json_syntax", "lace", "c.json", "{\"rows\": " + kSecret + "}", lace + "start_chart = \"c.json\"\n",
       "line 1, column"},
      {"lace_chart_json_symbol", "lace", "s.json", "{\"rows\": [[\"" + kSecret + "\"]]}",
       lace + "start_chart = \"s.json\"\n", "s.json"},
      {"sidecar_toml", "knit", "", "[" + kSecret + "]\n[" + kSecret + "]\n", "", "pic.png.toml:2"},
      {"sidecar_toml_value", "knit", "", "width = " + kSecret + "\n", "", "pic.png.toml:1"},
      {"pencil_profile_toml", "sketch", "p.toml", "[" + kSecret + "]\n[" + kSecret + "]\n", "pencil = \"p.toml\"\n",
       "p.toml:2"},
      {"wood_library_toml", "parquetry", "wood/library.toml", "[" + kSecret + "]\n[" + kSecret + "]\n",
       "wood = \"wood\"\ndpi = 25.4\n", "library.toml:2"},
      {"relax_mask_not_an_image", "knit", "m.png", shadow, "relax_mask = \"m.png\"\n", "m.png"},
  };
}

class SecretTest : public atelier::test::ConvertToolFixture, public ::testing::WithParamInterface<SecretCase> {};

TEST_P(SecretTest, TheReasonNamesTheFileButNotItsContent) {
  const SecretCase& c = GetParam();
  const fs::path in = dir_ / "spool" / "incoming" / c.kind;
  fs::path input;
  if (c.kind == "lace") {
    input = in / "swatch.toml";
    write(input, c.layer);
  } else {
    input = in / "pic.png";
    fs::create_directories(in);
    cv::Mat m = cv::imread((kData / "pic3.png").string());
    cv::resize(m, m, cv::Size(48, 48));
    cv::imwrite(input.string(), m);
    write(in / "pic.png.toml", c.file.empty() ? c.content : c.layer);
  }
  if (!c.file.empty()) write(in / c.file, c.content);
  EXPECT_EQ(tool(c.kind + " " + q(input) + " " + q(dir_ / "out") + " --confine " + q(dir_ / "spool")), 1);
  const std::string e = err();
  EXPECT_THAT(e, Not(HasSubstr(kSecret))) << e;
  EXPECT_THAT(e, Not(HasSubstr("root:"))) << e;
  EXPECT_THAT(e, HasSubstr(c.expect)) << e;
}

INSTANTIATE_TEST_SUITE_P(EachParser, SecretTest, ::testing::ValuesIn(cases()),
                         [](const auto& info) { return info.param.name; });

}  // namespace

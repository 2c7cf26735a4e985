// Every failure reason names the file at fault (the input, its sidecar or job file, or the file
// a parameter names) and stays short: long values are cut, never echoed whole.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tests/support/convert_tool.h"

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kData = ATELIER_TEST_DATA;
const std::string kHuge(5 << 20, 'A');      // in a file
const std::string kLongArg(100000, 'B');   // on the command line (argv holds 128 KiB per argument)

struct BadInput {
  std::string name;
  std::string kind;
  std::string sidecar;  // NAME.png.toml beside pic.png, or the lace job file; "" for none
  std::string sets;     // more arguments (already quoted)
  std::string names;    // what the reason must contain
  // Extra setup in the job's folder.
  void (*setup)(const fs::path& dir) = nullptr;
};

void write(const fs::path& p, const std::string& s) { atelier::test::ConvertToolFixture::write(p, s); }

std::string png_bytes() {
  std::vector<unsigned char> buf;
  cv::Mat m = cv::imread((kData / "pic1.png").string());
  cv::resize(m, m, cv::Size(40, 40));
  cv::imencode(".png", m, buf);
  return std::string(buf.begin(), buf.end());
}

std::vector<BadInput> cases() {
  const std::string lace = "kind = \"lace\"\ngenerations = 0\npopulation = 4\n";
  return {
      {"huge_choice_value", "knit", "dither = \"" + kHuge + "\"\n", "", "pic.png.toml"},
      {"huge_unknown_key", "knit", "\"" + kHuge + "\" = 1\n", "", "pic.png.toml"},
      {"huge_colour", "knit", "colors = [\"" + kHuge + "\", \"#000000\"]\n", "", "pic.png.toml"},
      {"relax_mask_root", "knit", "relax_mask = \"/\"\n", "", "pic.png.toml"},
      {"relax_mask_folder_slash", "knit", "relax_mask = \"sub/\"\n", "", "pic.png.toml",
       [](const fs::path& d) { fs::create_directories(d / "sub"); }},
      {"relax_mask_empty_file", "knit", "relax_mask = \"empty.png\"\n", "", "empty.png",
       [](const fs::path& d) { write(d / "empty.png", ""); }},
      {"relax_mask_missing", "knit", "relax_mask = \"missing.png\"\n", "", "missing.png"},
      {"relax_mask_truncated", "knit", "relax_mask = \"cut.png\"\n", "", "cut.png",
       [](const fs::path& d) { write(d / "cut.png", png_bytes().substr(0, 200)); }},
      {"input_truncated", "knit", "", "", "pic.png",
       [](const fs::path& d) { write(d / "pic.png", png_bytes().substr(0, 300)); }},
      {"input_not_an_image", "knit", "", "", "pic.png", [](const fs::path& d) { write(d / "pic.png", "hello\n"); }},
      {"wrong_type", "knit", "width = \"wide\"\n", "", "pic.png.toml"},
      {"unknown_key", "knit", "widht = 10\n", "", "pic.png.toml"},
      {"set_without_equals", "knit", "", "--set " + kLongArg, "pic.png"},
      {"set_huge_choice", "knit", "", "--set dither=" + kLongArg, "pic.png"},
      {"lace_huge_start_chart", "lace", lace + "start_chart = \"" + kHuge + ".json\"\n", "", "swatch.toml"},
      {"lace_start_chart_folder", "lace", lace + "start_chart = \"charts\"\n", "", "swatch.toml",
       [](const fs::path& d) { fs::create_directories(d / "charts"); }},
      {"lace_set_long_start_chart", "lace", lace, "--set start_chart=" + kLongArg + ".txt", "swatch.toml"},
      {"lace_input_is_an_image", "lace", "", "", "pic.png"},
      {"sketch_huge_pencil", "sketch", "pencil = \"" + kHuge + ".toml\"\n", "", "pic.png.toml"},
      {"sketch_pencil_folder", "sketch", "pencil = \"p.toml\"\n", "", "p.toml",
       [](const fs::path& d) { fs::create_directories(d / "p.toml"); }},
      {"embroidery_huge_textures", "embroidery", "textures = \"" + kHuge + "\"\n", "", "pic.png.toml"},
      {"parquetry_huge_wood", "parquetry", "wood = \"" + kHuge + "\"\n", "", "pic.png.toml"},
      {"parquetry_empty_wood", "parquetry", "wood = \"empty\"\n", "", "empty",
       [](const fs::path& d) { fs::create_directories(d / "empty"); }},
      {"parquetry_sheet_missing", "parquetry", "wood = [{id = \"m\", image = \"gone.png\"}]\n", "", "gone.png"},
  };
}

class ReasonTest : public atelier::test::ConvertToolFixture, public ::testing::WithParamInterface<BadInput> {};

TEST_P(ReasonTest, NamesTheFileAndStaysShort) {
  const BadInput& c = GetParam();
  const fs::path spool = dir_ / "spool";
  const fs::path d = spool / "incoming" / c.kind;
  fs::create_directories(d);
  fs::path input = d / "pic.png";
  write(input, png_bytes());
  if (c.kind == "lace" && !c.sidecar.empty()) {
    input = d / "swatch.toml";
    write(input, c.sidecar);
  } else if (!c.sidecar.empty()) {
    write(d / "pic.png.toml", c.sidecar);
  }
  if (c.setup) c.setup(d);
  EXPECT_EQ(tool(c.kind + " " + q(input) + " " + q(dir_ / "out") + " --confine " + q(spool) + " " + c.sets), 1);
  const std::string e = err();
  EXPECT_THAT(e, HasSubstr(c.names)) << e.substr(0, 400);
  EXPECT_LE(e.size(), 300u) << e.substr(0, 400);
}

INSTANTIATE_TEST_SUITE_P(AcrossTheKinds, ReasonTest, ::testing::ValuesIn(cases()),
                         [](const auto& info) { return info.param.name; });

}  // namespace

// convert() for kind cut: an SVG becomes job.gcode, preview.png and report.json.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "convert/convert.h"
#include "convert/kinds.h"
#include "convert/common/param_table.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kSvgData = fs::path(ATELIER_TEST_DATA) / "svg";

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

size_t index_of(const std::vector<std::string>& lines, const std::string& prefix) {
  for (size_t i = 0; i < lines.size(); ++i)
    if (lines[i].rfind(prefix, 0) == 0) return i;
  return lines.size();
}

class ConvertCutTest : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = fs::temp_directory_path() /
           ("atelier-convert-cut-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(out_);
  }
  void TearDown() override { fs::remove_all(out_); }

  ConvertResult run(const fs::path& input, const std::string& laser_toml = "") {
    ConvertRequest req;
    req.kind = "cut";
    req.input = input;
    if (!laser_toml.empty()) {
      toml::table t = toml::parse(laser_toml, std::string_view{"test.toml"});
      req.params.insert_or_assign("laser", *t.get_as<toml::table>("laser"));
    }
    req.output_dir = out_;
    req.progress = [this](double f) { progress_.push_back(f); };
    return convert(req);
  }

  std::string error_of(const fs::path& input, const std::string& laser_toml = "") {
    try {
      run(input, laser_toml);
    } catch (const ConvertError& e) {
      return e.what();
    }
    return "";
  }

  fs::path out_;
  std::vector<double> progress_;
};

TEST_F(ConvertCutTest, CutIsAKnownKind) {
  EXPECT_TRUE(is_known_kind("cut"));
  EXPECT_TRUE(is_known_kind("knit"));
  EXPECT_NO_THROW(validate_kind_params("cut", toml::table{}, "x.toml"));
  toml::table bad = toml::parse("speed = 3\n", std::string_view{"x.toml"});
  EXPECT_THROW(validate_kind_params("cut", bad, "x.toml"), ParamError);
  toml::table bad_laser = toml::parse("[laser]\ns_max = 0\n", std::string_view{"x.toml"});
  EXPECT_THROW(validate_kind_params("cut", bad_laser, "x.toml"), ParamError);
}

TEST_F(ConvertCutTest, BoxWithHolesAndEngraving) {
  ConvertResult r = run(kSvgData / "box-test.svg");
  EXPECT_EQ(r.outputs, (std::vector<std::string>{"job.gcode", "preview.png", "report.json"}));
  for (const auto& name : r.outputs) EXPECT_TRUE(fs::exists(out_ / name)) << name;
  for (const auto& e : fs::directory_iterator(out_))
    EXPECT_NE(e.path().extension(), ".tmp") << "temporary file left: " << e.path();

  // G-code: engrave (blue) first, then the cut; holes before the outline around them.
  auto lines = lines_of(slurp(out_ / "job.gcode"));
  ASSERT_GT(lines.size(), 10u);
  EXPECT_EQ(lines[0], "; atelier laser job");
  EXPECT_EQ(lines.back(), "M5");
  size_t engrave = index_of(lines, "; layer blue engrave");
  size_t cut = index_of(lines, "; layer black cut");
  ASSERT_LT(engrave, lines.size());
  ASSERT_LT(cut, lines.size());
  EXPECT_LT(engrave, cut);
  // The outline (5..55 x 5..35 mm) is the last cut: its corners only appear after the last G0.
  size_t last_travel = 0;
  for (size_t i = 0; i < lines.size(); ++i)
    if (lines[i].rfind("G0", 0) == 0) last_travel = i;
  EXPECT_GT(last_travel, cut);
  // front-left origin on a 400 mm bed: design y 5 -> Y 395, y 35 -> Y 365.
  EXPECT_THAT(lines[last_travel], ::testing::AnyOf(HasSubstr("Y395"), HasSubstr("Y365")));

  // report.json
  nlohmann::json j = nlohmann::json::parse(slurp(out_ / "report.json"));
  EXPECT_EQ(j, r.report);
  ASSERT_EQ(j["layers"].size(), 2u);
  EXPECT_EQ(j["layers"][0]["name"], "blue");
  EXPECT_EQ(j["layers"][0]["mode"], "engrave");
  EXPECT_EQ(j["layers"][0]["color"], "#0000ff");
  EXPECT_EQ(j["layers"][0]["paths"], 3) << "A (two strokes) and P";
  EXPECT_EQ(j["layers"][1]["name"], "black");
  EXPECT_EQ(j["layers"][1]["paths"], 3);
  EXPECT_EQ(j["layers"][1]["passes"], 1);
  EXPECT_DOUBLE_EQ(j["layers"][1]["speed_mm_min"].get<double>(), 600);
  // Outline 160 mm + square hole 32 mm + round hole 2 pi 5 (flattened: a little less).
  double cut_len = j["cut_length_mm"].get<double>();
  EXPECT_NEAR(cut_len, 160 + 32 + 31.416, 0.1);
  EXPECT_NEAR(j["layers"][1]["length_mm"].get<double>(), cut_len, 1e-3);
  EXPECT_GT(j["engrave_length_mm"].get<double>(), 20);
  EXPECT_GT(j["travel_length_mm"].get<double>(), 0);
  EXPECT_NEAR(j["estimated_time_s"].get<double>(),
              j["layers"][0]["time_s"].get<double>() + j["layers"][1]["time_s"].get<double>(),
              0.01);
  EXPECT_GT(j["estimated_time_s"].get<double>(), cut_len / 600 * 60);
  EXPECT_DOUBLE_EQ(j["bounds_mm"]["min_x"].get<double>(), 5);
  EXPECT_DOUBLE_EQ(j["bounds_mm"]["max_x"].get<double>(), 55);
  EXPECT_DOUBLE_EQ(j["bounds_mm"]["min_y"].get<double>(), 365);
  EXPECT_DOUBLE_EQ(j["bounds_mm"]["max_y"].get<double>(), 395);
  EXPECT_EQ(j["work_area_mm"], nlohmann::json({400.0, 400.0}));
  EXPECT_DOUBLE_EQ(j["s_max"].get<double>(), 1000);
  EXPECT_EQ(j["ignored_unstroked"], 1);
  EXPECT_DOUBLE_EQ(j["source"]["width_mm"].get<double>(), 60);
  EXPECT_DOUBLE_EQ(j["source"]["height_mm"].get<double>(), 40);

  // preview.png: the job (50 x 30 mm) plus 5 mm margins at 10 px/mm, black and blue lines.
  cv::Mat preview = cv::imread((out_ / "preview.png").string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(preview.empty());
  EXPECT_NEAR(preview.cols, 600, 2);
  EXPECT_NEAR(preview.rows, 400, 2);
  int black = 0, blue = 0, white = 0;
  for (int y = 0; y < preview.rows; ++y)
    for (int x = 0; x < preview.cols; ++x) {
      cv::Vec3b p = preview.at<cv::Vec3b>(y, x);
      if (p[0] < 60 && p[1] < 60 && p[2] < 60) ++black;
      if (p[0] > 200 && p[1] < 60 && p[2] < 60) ++blue;
      if (p[0] == 255 && p[1] == 255 && p[2] == 255) ++white;
    }
  EXPECT_GT(black, 2 * 2230) << "about 2 px wide along 223 mm of cuts";
  EXPECT_GT(blue, 2 * 200);
  EXPECT_GT(white, preview.cols * preview.rows / 2) << "inside the work area";
  // The outline's top-left corner sits 5 mm (50 px) in from the image's top-left corner.
  cv::Vec3b corner = preview.at<cv::Vec3b>(50, 50);
  EXPECT_LT(corner[0] + corner[1] + corner[2], 3 * 128);

  ASSERT_FALSE(progress_.empty());
  EXPECT_DOUBLE_EQ(progress_.back(), 1.0);
}

TEST_F(ConvertCutTest, LayerSettingsComeFromTheLaserTable) {
  run(kSvgData / "box-test.svg", R"([laser]
s_max = 255
[[laser.layer]]
color = "black"
name = "plywood"
power_pct = 100
passes = 2
kerf_mm = 0.2
[[laser.layer]]
color = "blue"
mode = "engrave"
power_pct = 10
)");
  std::string gcode = slurp(out_ / "job.gcode");
  EXPECT_THAT(gcode, HasSubstr("; s_max=255\n"));
  EXPECT_THAT(gcode, HasSubstr("; layer plywood cut 600mm/min 100% x2\nM4 S255\n"));
  EXPECT_THAT(gcode, HasSubstr("; layer blue engrave 600mm/min 10% x1\nM4 S26\n"));
  nlohmann::json j = nlohmann::json::parse(slurp(out_ / "report.json"));
  // Kerf: the outline grows by 0.1 mm on each side.
  EXPECT_NEAR(j["bounds_mm"]["min_x"].get<double>(), 4.9, 0.002);
  EXPECT_NEAR(j["bounds_mm"]["max_x"].get<double>(), 55.1, 0.002);
  EXPECT_DOUBLE_EQ(j["layers"][1]["kerf_mm"].get<double>(), 0.2);
  EXPECT_EQ(j["layers"][1]["passes"], 2);
  EXPECT_NEAR(j["cut_length_mm"].get<double>(), 2 * j["layers"][1]["length_mm"].get<double>(),
              1e-2);
}

TEST_F(ConvertCutTest, UnmappedColourFailsNamingIt) {
  std::string e = error_of(kSvgData / "unmapped-color.svg");
  EXPECT_THAT(e, HasSubstr("unmapped-color.svg: "));
  EXPECT_THAT(e, HasSubstr("#00ff00 (2 shapes)"));
  EXPECT_THAT(e, HasSubstr("#000000 (black), #ff0000 (red), #0000ff (blue)"));
  EXPECT_FALSE(fs::exists(out_ / "job.gcode")) << "nothing is written for a failed job";
  // Configured, it converts.
  run(kSvgData / "unmapped-color.svg", "[laser]\n[[laser.layer]]\ncolor = \"black\"\n"
                                       "[[laser.layer]]\ncolor = \"lime\"\nmode = \"engrave\"\n");
  EXPECT_TRUE(fs::exists(out_ / "job.gcode"));
}

TEST_F(ConvertCutTest, DrawingLargerThanTheWorkAreaFails) {
  std::string e = error_of(kSvgData / "too-large.svg");
  EXPECT_THAT(e, HasSubstr("too-large.svg: the job spans X 10..490 mm"));
  EXPECT_THAT(e, HasSubstr("outside the 400 x 400 mm work area"));
  EXPECT_FALSE(fs::exists(out_ / "job.gcode"));
  // A bigger bed takes it.
  run(kSvgData / "too-large.svg", "[laser]\nwork_area_mm = [600, 400]\n");
  EXPECT_TRUE(fs::exists(out_ / "job.gcode"));
}

TEST_F(ConvertCutTest, MalformedAndEmptyDrawingsFail) {
  EXPECT_THAT(error_of(kSvgData / "malformed.svg"), HasSubstr("malformed.svg: line"));
  fs::create_directories(out_);
  fs::path only_fill = out_ / "fill.svg";
  std::ofstream(only_fill) << R"(<svg xmlns="http://www.w3.org/2000/svg" width="10mm"
    height="10mm"><rect width="5" height="5"/></svg>)";
  EXPECT_THAT(error_of(only_fill),
              HasSubstr("fill.svg: nothing to burn: no shape has a stroke (1 shape only filled"));
}

TEST_F(ConvertCutTest, SampleBoxConverts) {
  ConvertResult r = run(kSvgData / "sample-box.svg");
  EXPECT_EQ(r.report["layers"].size(), 2u);
  EXPECT_EQ(r.report["layers"][1]["paths"], 4) << "plate, two holes, slot";
  EXPECT_EQ(r.report["ignored_unstroked"], 0);
  EXPECT_DOUBLE_EQ(r.report["source"]["width_mm"].get<double>(), 80);
}

TEST_F(ConvertCutTest, CommandLineTool) {
  const std::string tool = std::string(ATELIER_BINARY_DIR) + "/bin/atelier-convert";
  ASSERT_TRUE(fs::exists(tool));
  std::string cmd = tool + " cut " + (kSvgData / "box-test.svg").string() + " " +
                    out_.string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_TRUE(fs::exists(out_ / "job.gcode"));
  EXPECT_TRUE(fs::exists(out_ / "box-test.svg")) << "the input is copied beside the outputs";
  cmd = tool + " cut " + (kSvgData / "unmapped-color.svg").string() + " " + out_.string() +
        " >/dev/null 2>&1";
  EXPECT_NE(std::system(cmd.c_str()), 0);
}

TEST_F(ConvertCutTest, TextClonesAndImagesAreNamedInTheReportNotSilentlyLost) {
  fs::create_directories(out_.parent_path());
  const fs::path svg = out_.string() + "-input.svg";
  std::ofstream(svg) << R"(<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink"
     width="50mm" height="50mm" viewBox="0 0 50 50">
  <defs><text id="t">in defs, not drawn</text></defs>
  <rect id="r" x="5" y="5" width="20" height="20" fill="none" stroke="#000000"/>
  <text x="5" y="40" stroke="#0000ff">Hello</text>
  <g><text x="5" y="45" stroke="#0000ff">World</text><use xlink:href="#r" x="20"/></g>
</svg>)";
  ConvertResult r = run(svg);
  fs::remove(svg);
  EXPECT_EQ(r.report["ignored_elements"], (nlohmann::json{{"text", 2}, {"use", 1}}));
  EXPECT_EQ(r.report["layers"].size(), 1u);
}

}  // namespace
}  // namespace atelier

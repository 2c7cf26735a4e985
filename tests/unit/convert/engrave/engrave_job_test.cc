// convert() for kind engrave: a photo becomes a raster program (job.gcode), preview.png and
// report.json; its parameters are read strictly.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <regex>
#include <sstream>
#include <string>

#include "convert/common/param_table.h"
#include "convert/convert.h"
#include "convert/kinds.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/convert_kind.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kData = fs::path(ATELIER_TEST_DATA);

class ConvertEngraveTest : public ::testing::Test {
 protected:
  ConvertResult run(const fs::path& input, const std::string& params_toml = "", const std::string& out = "out") {
    return test::convert_kind("engrave", input, params_toml, dir_ / out);
  }
  std::string error_of(const std::string& params_toml) {
    try {
      validate_kind_params("engrave", toml::parse(params_toml, std::string_view{"test.toml"}), "test.toml");
    } catch (const ParamError& e) {
      return e.what();
    }
    return "";
  }
  std::string read(const fs::path& f) {
    std::ifstream in(f);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  test::TempDir tmp_;
  const fs::path dir_ = tmp_.path();
};

TEST_F(ConvertEngraveTest, APhotoBecomesARasterProgramWithOneG1PerRun) {
  const ConvertResult r = run(kData / "fruits.jpg", "width_mm = 40\ndpi = 127\nline_interval_mm = 0.2\n"
                                                    "position_mm = [20, 30]\ndither = \"floyd-steinberg\"\n");
  const fs::path out = dir_ / "out";
  for (const char* f : {"job.gcode", "preview.png", "report.json"}) EXPECT_TRUE(fs::exists(out / f)) << f;
  const nlohmann::json& rep = r.report;
  EXPECT_EQ(rep["kind"], "engrave");
  EXPECT_EQ(rep["dither"], "floyd-steinberg");
  EXPECT_EQ(rep["grid"]["cols"], 200);  // 40 mm at 5 dots per mm
  const cv::Mat photo = cv::imread((kData / "fruits.jpg").string());
  const int rows = static_cast<int>(std::lround(40.0 * photo.rows / photo.cols / 0.2));
  EXPECT_EQ(rep["grid"]["rows"], rows) << "the height keeps the aspect";
  // GRBL's planner: every line starts and ends at rest, so the burn takes longer than its
  // length at the feed, and less than twice that at these short run-ups.
  const double at_feed = rep["scan_length_mm"].get<double>() / 3000 * 60;
  EXPECT_GT(rep["estimated_time_s"].get<double>(), at_feed);
  EXPECT_LT(rep["estimated_time_s"].get<double>(), 2 * at_feed);
  EXPECT_NEAR(rep["overscan_mm"].get<double>(), 2.75, 1e-3) << "3000 mm/min at 500 mm/s^2";

  const std::string gcode = read(out / "job.gcode");
  EXPECT_THAT(gcode, ::testing::StartsWith("; atelier laser job\n; s_max=1000\n; bounds="));
  EXPECT_THAT(gcode, HasSubstr("\nM4 S0\n"));
  EXPECT_THAT(gcode, ::testing::EndsWith("\nM5\n"));
  // Every G1 that burns sets its S: equal neighbours were merged, so a burn never repeats the
  // previous run's power; a G1 without S only continues an S0 move (run-up, gap, run-out).
  std::istringstream in(gcode);
  int s = 0, burns = 0;
  double y = 0;
  const auto& b = rep["bounds_mm"];
  const std::regex g1(R"(G1 X([-0-9.]+)( S([0-9]+))?( F[0-9.]+)?)"), g0(R"(G0( X[-0-9.]+)?( Y([-0-9.]+))?)");
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_match(line, m, g0)) {
      if (m[3].matched) y = std::stod(m[3]);
    } else if (std::regex_match(line, m, g1)) {
      if (!m[2].matched) {
        EXPECT_EQ(s, 0) << line << ": a burn without its own S";
      } else {
        s = std::stoi(m[3]);
        EXPECT_LE(s, 1000);
      }
      if (s > 0) {
        ++burns;
        const double x = std::stod(m[1]);
        EXPECT_TRUE(x >= b["min_x"].get<double>() - 1e-3 && x <= b["max_x"].get<double>() + 1e-3) << line;
        EXPECT_TRUE(y >= b["min_y"].get<double>() - 1e-3 && y <= b["max_y"].get<double>() + 1e-3) << line;
      }
    }
  }
  EXPECT_EQ(burns, rep["burn_moves"].get<int>());
  EXPECT_GE(b["min_x"].get<double>(), 20);
  EXPECT_LE(b["max_x"].get<double>(), 60);
  EXPECT_GE(b["min_y"].get<double>(), 30) << "position_mm is the front-left corner, Y from the front";

  // The preview is the burn at 5 px per mm; where the photo is dark it is dark.
  const cv::Mat preview = cv::imread((out / "preview.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(preview.cols, 200);
  cv::Mat grey, small;
  cv::cvtColor(photo, grey, cv::COLOR_BGR2GRAY);
  cv::resize(grey, small, preview.size(), 0, 0, cv::INTER_AREA);
  cv::Mat blurred;
  cv::GaussianBlur(preview, blurred, {9, 9}, 2.0);
  cv::Mat a, c;
  small.convertTo(a, CV_64F);
  blurred.convertTo(c, CV_64F);
  cv::Mat ma, mc, sa, sc;
  cv::meanStdDev(a, ma, sa);
  cv::meanStdDev(c, mc, sc);
  const double corr = cv::mean((a - ma.at<double>(0)).mul(c - mc.at<double>(0)))[0] / (sa.at<double>(0) * sc.at<double>(0));
  EXPECT_GT(corr, 0.8) << "the preview's tones follow the photo's";
}

TEST_F(ConvertEngraveTest, BlankMarginsAndLinesAreNotScanned) {
  cv::Mat img(100, 200, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::rectangle(img, cv::Point(50, 25), cv::Point(149, 74), cv::Scalar(0, 0, 0), cv::FILLED);
  cv::imwrite((dir_ / "box.png").string(), img);
  // 20 mm wide, 0.1 mm dots and lines: the box spans X 5..15 mm and 2.5..7.5 mm up.
  const ConvertResult r = run(dir_ / "box.png", "width_mm = 20\nposition_mm = [0, 0]\ndither = \"threshold\"\n"
                                                 "dpi = 254\nline_interval_mm = 0.1\n");
  const auto& b = r.report["bounds_mm"];
  EXPECT_NEAR(b["min_x"].get<double>(), 5, 0.11);
  EXPECT_NEAR(b["max_x"].get<double>(), 15, 0.11);
  EXPECT_NEAR(b["min_y"].get<double>(), 2.5, 0.11);
  EXPECT_NEAR(b["max_y"].get<double>(), 7.5, 0.11);
  EXPECT_EQ(r.report["scanned_rows"], 50) << "only the box's lines";
  EXPECT_EQ(r.report["burn_moves"], 50) << "one run per line";
  // Each line: G0, run-up, burn, run-out; plus 6 header lines and M5.
  EXPECT_EQ(r.report["gcode_lines"], 50 * 4 + 7);
}

TEST_F(ConvertEngraveTest, AWhiteImageHasNothingToBurn) {
  cv::imwrite((dir_ / "white.png").string(), cv::Mat(50, 50, CV_8UC3, cv::Scalar(255, 255, 255)));
  try {
    run(dir_ / "white.png");
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_THAT(e.what(), HasSubstr("white.png: nothing to burn"));
  }
}

TEST_F(ConvertEngraveTest, BadParametersAreRefusedNamingFileLineAndKey) {
  EXPECT_THAT(error_of("dither = \"random\"\n"), HasSubstr("test.toml:1: key 'dither'"));
  EXPECT_THAT(error_of("dpi = 5\n"), HasSubstr("test.toml:1: key 'dpi'"));
  EXPECT_THAT(error_of("gamma = 0\n"), HasSubstr("test.toml:1: key 'gamma'"));
  EXPECT_THAT(error_of("min_power_pct = 60\nmax_power_pct = 50\n"), HasSubstr("key 'min_power_pct': is above max_power_pct"));
  EXPECT_THAT(error_of("position_mm = [1]\n"), HasSubstr("test.toml:1: key 'position_mm'"));
  EXPECT_THAT(error_of("line_interval = 0.1\n"), HasSubstr("unknown key 'line_interval'"));
  EXPECT_THAT(error_of("[laser]\norigin = \"rear-right\"\n"), HasSubstr("test.toml:2: key 'laser.origin': is no longer read"));
  EXPECT_EQ(error_of("dither = \"stucki\"\ndpi = 300\nnegative = true\noverscan_mm = 3\n"), "");
}

}  // namespace
}  // namespace atelier

// Review of issue 8 (sketch jobs, pencil profiles): odd inputs that once failed.
//  - A drawing placed at the bed's corner: its hand-drawn lines wander past the drawing's edge,
//    and the engraving left the work area (the job failed); now it is clipped to the drawing.
//  - position_mm = [nan, 3] passed the range check and hung the laser planner.
//  - A profile file whose histogram counts overflow when added wrapped round to the stated
//    total and was accepted.
//  - `atelier-convert pencil-profile` on a scan that is all line wrote a profile (1200 px wide)
//    that every job then refused.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "algorithms/pencil/reference_scan.h"
#include "daemon/convert/convert.h"
#include "daemon/convert/param_table.h"
#include "daemon/convert/pencil_profile_file.h"
#include "drivers/grbl/program.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class SketchReviewTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("atelier-sketch-review-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  ConvertResult sketch(const fs::path& input, const std::string& params_toml, const std::string& out = "out") {
    ConvertRequest req;
    req.kind = "sketch";
    req.input = input;
    req.params = toml::parse(params_toml, std::string_view{"test.toml"});
    validate_kind_params("sketch", req.params, "test.toml");
    req.output_dir = dir_ / out;
    return convert(req);
  }
  fs::path dir_;
};

TEST_F(SketchReviewTest, AnEngravingAtTheBedsCornerStaysInsideTheDrawingAndTheBed) {
  // All dark: hatch lines run right up to every edge, and wander past it by up to the squiggle.
  cv::imwrite((dir_ / "dark.png").string(), cv::Mat(200, 300, CV_8UC1, cv::Scalar(20)));
  for (const char* corner : {"[0, 0]", "[300, 333.333]"}) {
    SCOPED_TRACE(corner);
    const std::string out = std::string("out") + corner[1];
    const ConvertResult r =
        sketch(dir_ / "dark.png", std::string("hatching = true\nwidth_mm = 100\nposition_mm = ") + corner + "\n", out);
    EXPECT_GT(r.report["hatch_lines"].get<int>(), 20);
    const grbl::Program prog = grbl::parse_program(slurp(dir_ / out / "engrave.gcode"), 6000);
    ASSERT_TRUE(prog.bounds);
    // Design x in [x0, x0 + 100], y in [y0, y0 + 66.667] on a 400 mm front-left bed (Y = 400 - y).
    const double x0 = corner[1] == '0' ? 0 : 300, y0 = corner[1] == '0' ? 0 : 333.333;
    EXPECT_GE(prog.bounds->min_x, x0 - 1e-3);
    EXPECT_LE(prog.bounds->max_x, x0 + 100 + 1e-3);
    EXPECT_GE(prog.bounds->min_y, 400 - y0 - 66.667 - 1e-3);
    EXPECT_LE(prog.bounds->max_y, 400 - y0 + 1e-3);
    // Clipped, not dropped: the engraving still fills the drawing.
    EXPECT_GT(prog.bounds->width(), 99);
  }
}

TEST_F(SketchReviewTest, ANonNumberPositionIsRefusedNamingTheKey) {
  cv::imwrite((dir_ / "square.png").string(), cv::Mat(100, 100, CV_8UC1, cv::Scalar(255)));
  for (const char* pos : {"[nan, 3]", "[3, nan]", "[inf, 3]", "[3, -inf]"}) {
    try {
      sketch(dir_ / "square.png", std::string("position_mm = ") + pos + "\n");
      FAIL() << pos << " was accepted";
    } catch (const ParamError& e) {
      EXPECT_THAT(e.what(), HasSubstr("test.toml:1: key 'position_mm'")) << pos;
    }
  }
}

TEST(SketchReviewProfile, HistogramCountsThatOverflowTheirSumAreRefused) {
  const pencil::PencilProfile p =
      pencil::learn_profile(pencil::reference_scan(*pencil::find_grade_model("HB"), 60, 3), "hb");
  std::string text = profile_to_toml(p, "scan.png");
  // Four counts of 2^62 add up to 2^64, which wraps to 0 in 64 bits: the sum would still match.
  const std::string from = "mid_hist = [\n ";
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos);
  const std::string huge = " 4611686018427387904,";
  text.insert(at + from.size(), huge + huge + huge + huge);
  // ... and the last four counts (grey levels 252..255, no centre is that light) dropped, so that
  // there are still 256. The last line of the array is "  c240, ..., c255,  # 240..255".
  const auto end = text.find("  # 240..255\n]", at);
  ASSERT_NE(end, std::string::npos);
  auto cut = end;
  for (int k = 0; k < 5; ++k) cut = text.rfind(',', cut - 1);
  ASSERT_EQ(text.substr(cut, end - cut), ", 0, 0, 0, 0,") << "the last counts are not zeros";
  text.erase(cut + 1, end - cut - 1);
  try {
    profile_from_toml(text, "mine.toml");
    FAIL() << "counts of 2^62 were accepted";
  } catch (const ConvertError& e) {
    EXPECT_THAT(e.what(), HasSubstr("key 'mid_hist': grey level 0: count 4611686018427387904 is more than"));
  }
}

TEST(SketchReviewTool, PencilProfileRefusesAScanThatIsAllLine) {
  const fs::path dir = fs::temp_directory_path() / ("atelier-sketch-review-tool-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path tool = fs::path(ATELIER_BINARY_DIR) / "bin" / "atelier-convert";
  ASSERT_TRUE(fs::exists(tool)) << tool << " is not built (ninja atelier-convert)";
  ASSERT_TRUE(cv::imwrite((dir / "dark.png").string(), cv::Mat(50, 1200, CV_8UC1, cv::Scalar(0))));
  const std::string cmd = "'" + tool.string() + "' pencil-profile '" + (dir / "dark.png").string() + "' '" +
                          (dir / "dark.toml").string() + "' 2>'" + (dir / "err.txt").string() + "' >/dev/null";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
  const std::string err = slurp(dir / "err.txt");
  EXPECT_THAT(err, HasSubstr("dark.png: the profile learned from it would be unusable"));
  EXPECT_THAT(err, HasSubstr("width_px"));
  EXPECT_FALSE(fs::exists(dir / "dark.toml")) << "an unusable profile was written";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace atelier

// One hand-drawn line (`atelier-convert line`, issue 8) and learning a pencil from a scan
// (`atelier-convert pencil-profile`): the line runs between its end points in the canvas the
// report describes, is dark along its path and paper white away from it, is reproducible by
// seed; bad parameters name their key; the real tool does both and exits as documented.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "algorithms/pencil/path.h"
#include "algorithms/pencil/profile.h"
#include "algorithms/pencil/reference_scan.h"
#include "convert/convert.h"
#include "tests/e2e/daemon_harness.h"
#include "convert/sketch/line_job.h"
#include "convert/common/param_table.h"
#include "convert/sketch/pencil_profile_file.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kTool = fs::path(ATELIER_BINARY_DIR) / "bin" / "atelier-convert";

class PencilLineJob : public ::testing::Test {
 protected:
  static toml::table params(const std::vector<std::string>& sets) {
    toml::table t;
    for (const auto& s : sets) apply_set(t, s);
    return t;
  }
  std::string param_error(const std::vector<std::string>& sets) {
    try {
      convert_line(params(sets), "--set", dir_ / "bad");
    } catch (const ParamError& e) {
      return e.what();
    }
    return "";
  }

  test::TempDir tmp_;
  const fs::path dir_ = tmp_.path();
};

TEST_F(PencilLineJob, DrawsTheLineBetweenItsEndPoints) {
  const cv::Point2d from(-30, 40), to(420, 160);
  const ConvertResult r =
      convert_line(params({"from=-30,40", "to=[420, 160]", "pencil=6B", "seed=7"}), "--set", dir_ / "out");
  EXPECT_EQ(r.outputs, (std::vector<std::string>{"line.png", "line.json", "report.json"}));
  const nlohmann::json j = nlohmann::json::parse(test::read_file(dir_ / "out" / "line.json"));
  EXPECT_EQ(j["pencil"], "6B");
  EXPECT_EQ(j["seed"], 7);
  EXPECT_EQ(j["squiggle"], 5.0);
  const auto& path = j["path"];
  ASSERT_GT(path.size(), 100u);
  EXPECT_LE(cv::norm(cv::Point2d(path.front()[0], path.front()[1]) - from), 1.0);
  EXPECT_LE(cv::norm(cv::Point2d(path.back()[0], path.back()[1]) - to), 1.0);
  EXPECT_GE(j["control"].size(), 3u);

  const cv::Mat png = cv::imread((dir_ / "out" / "line.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(png.type(), CV_8UC1);
  const cv::Point2d origin(j["origin"][0], j["origin"][1]);
  const nlohmann::json report = nlohmann::json::parse(test::read_file(dir_ / "out" / "report.json"));
  EXPECT_EQ(report["canvas"]["width"], png.cols);
  EXPECT_EQ(report["canvas"]["height"], png.rows);
  EXPECT_EQ(report["points"], path.size());
  EXPECT_GT(report["length_px"].get<double>(), cv::norm(to - from));
  EXPECT_TRUE(report.contains("milliseconds"));
  // The canvas holds the line and the margin: its origin is up-left of both end points.
  EXPECT_LE(origin.x, from.x - 20);
  EXPECT_LE(origin.y, from.y - 20);
  EXPECT_GE(origin.x + png.cols, to.x + 20);

  // Dark along the path (a 6B centre is ~40..90), paper white beyond the line's width.
  cv::Mat near(png.size(), CV_8UC1, cv::Scalar(0));
  std::vector<cv::Point> drawn;
  int dark = 0;
  for (size_t i = 0; i < path.size(); ++i) {
    const cv::Point2d p = cv::Point2d(path[i][0], path[i][1]) - origin;
    const cv::Point px(static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)));
    drawn.push_back(px);
    if (i % 10 == 0) {
      uchar darkest = 255;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) darkest = std::min(darkest, png.at<uchar>(px.y + dy, px.x + dx));
      dark += darkest < 150;
    }
  }
  EXPECT_GT(dark, static_cast<int>(0.95 * (path.size() / 10 + 1))) << "dark pixels along the path";
  cv::polylines(near, drawn, false, cv::Scalar(255), 2 * 4 + 3);  // 6B: ~7 px wide, +1 px either side
  cv::Mat away;
  cv::bitwise_and(png < 255, near == 0, away);
  EXPECT_EQ(cv::countNonZero(away), 0) << "marks away from the path";
  EXPECT_GT(cv::countNonZero(png < 200), 5 * static_cast<int>(report["length_px"].get<double>()));
}

TEST_F(PencilLineJob, SameSeedSameFilesOtherSeedOtherPath) {
  const std::vector<std::string> base = {"from=10,10", "to=300,80", "pencil=hb"};
  auto with_seed = [&](const std::string& seed, const std::string& name) {
    auto sets = base;
    sets.push_back("seed=" + seed);
    convert_line(params(sets), "--set", dir_ / name);
    return nlohmann::json::parse(test::read_file(dir_ / name / "line.json"));
  };
  const nlohmann::json a = with_seed("3", "a"), b = with_seed("3", "b"), c = with_seed("4", "c");
  EXPECT_EQ(test::read_file(dir_ / "a" / "line.png"), test::read_file(dir_ / "b" / "line.png"));
  EXPECT_EQ(test::read_file(dir_ / "a" / "line.json"), test::read_file(dir_ / "b" / "line.json"));
  EXPECT_NE(a["path"], c["path"]);
  EXPECT_NE(test::read_file(dir_ / "a" / "line.png"), test::read_file(dir_ / "c" / "line.png"));
  EXPECT_EQ(a["pencil"], "hb");
}

TEST_F(PencilLineJob, BadParametersNameTheirKey) {
  EXPECT_THAT(param_error({"from=1,x", "to=5,5"}), HasSubstr("key 'from': '1,x' is not \"X,Y\""));
  EXPECT_THAT(param_error({"from=[1]", "to=5,5"}), HasSubstr("key 'from'"));
  EXPECT_THAT(param_error({"from=1,2"}), HasSubstr("key 'to': missing"));
  EXPECT_THAT(param_error({"from=1,2", "to=30000,5"}), HasSubstr("key 'to': coordinate 30000 is outside"));
  EXPECT_THAT(param_error({"from=1,2", "to=5,5", "squiggle=-1"}), HasSubstr("key 'squiggle'"));
  EXPECT_THAT(param_error({"from=1,2", "to=5,5", "colour=red"}), HasSubstr("unknown key 'colour'"));
  EXPECT_THAT(param_error({"from=true", "to=5,5"}), HasSubstr("key 'from'"));
  try {
    convert_line(params({"from=1,2", "to=50,5", "pencil=7X"}), "--set", dir_ / "bad");
    ADD_FAILURE() << "an unknown pencil";
  } catch (const ConvertError& e) {
    EXPECT_THAT(e.what(), HasSubstr("key 'pencil': '7X'"));
  }
  // A canvas beyond the pixel limit is refused before anything is allocated.
  EXPECT_THROW(convert_line(params({"from=-20000,-20000", "to=20000,20000"}), "--set", dir_ / "big"), ConvertError);
  EXPECT_FALSE(fs::exists(dir_ / "big" / "line.png"));
}

// The real atelier-convert program.
class PencilConvertTool : public PencilLineJob {
 protected:
  void SetUp() override {
    PencilLineJob::SetUp();
    ASSERT_TRUE(fs::exists(kTool)) << kTool << " is not built (ninja atelier-convert)";
  }
  int tool(const std::string& args) {
    const std::string cmd = "'" + kTool.string() + "' " + args + " >'" + (dir_ / "stdout.txt").string() + "' 2>'" +
                            (dir_ / "stderr.txt").string() + "'";
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  std::string err() { return test::read_file(dir_ / "stderr.txt"); }
  std::string q(const fs::path& p) { return "'" + p.string() + "'"; }
};

TEST_F(PencilConvertTool, LearnsAPencilFromAScan) {
  const cv::Mat scan = pencil::reference_scan(*pencil::find_grade_model("3B"), 200, 9);
  cv::Mat colour;
  cv::cvtColor(scan, colour, cv::COLOR_GRAY2BGR);  // a colour scan of grey lines: same profile
  ASSERT_TRUE(cv::imwrite((dir_ / "scan.png").string(), colour));
  ASSERT_EQ(tool("pencil-profile " + q(dir_ / "scan.png") + " " + q(dir_ / "soft.toml")), 0) << err();
  const pencil::PencilProfile got = load_profile_file(dir_ / "soft.toml");
  const pencil::PencilProfile want = pencil::learn_profile(scan, "soft");
  EXPECT_EQ(got.name, "soft") << "named after OUT";
  EXPECT_TRUE(got.hist == want.hist);
  EXPECT_TRUE(got.ccm == want.ccm);
  EXPECT_EQ(got.width_px, want.width_px);
  EXPECT_THAT(test::read_file(dir_ / "soft.toml"), HasSubstr("source = \"scan.png\""));

  // A scan with transparency: transparent pixels are paper, whatever their colour.
  cv::Mat bgra;
  cv::cvtColor(scan, bgra, cv::COLOR_GRAY2BGRA);
  bgra(cv::Rect(0, 0, 8, 40)).setTo(cv::Scalar(0, 0, 0, 0));  // black but transparent, left of the lines
  ASSERT_TRUE(cv::imwrite((dir_ / "alpha.png").string(), bgra));
  ASSERT_EQ(tool("pencil-profile " + q(dir_ / "alpha.png") + " " + q(dir_ / "soft.toml")), 0) << err();
  EXPECT_TRUE(load_profile_file(dir_ / "soft.toml").hist == want.hist);

  ASSERT_EQ(tool("pencil-profile " + q(dir_ / "scan.png") + " " + q(dir_ / "b.toml") +
                 " --set name=Mine --set paper_threshold=200"),
            0)
      << err();
  const pencil::PencilProfile strict = load_profile_file(dir_ / "b.toml");
  EXPECT_EQ(strict.name, "Mine");
  EXPECT_LT(strict.line_pixels, want.line_pixels) << "a lower threshold counts fewer line pixels";
  EXPECT_EQ(tool("pencil-profile " + q(dir_ / "scan.png") + " " + q(dir_ / "c.toml") + " --set colour=1"), 1);
  EXPECT_THAT(err(), HasSubstr("unknown key 'colour'"));

  // The shipped profiles' recipe gives the shipped profile.
  ASSERT_EQ(tool("pencil-profile --reference 6b " + q(dir_ / "6B.toml") + " --scan-png " + q(dir_ / "6B.png")), 0)
      << err();
  const pencil::PencilProfile six = load_profile_file(dir_ / "6B.toml");
  EXPECT_EQ(six.name, "6B");
  EXPECT_TRUE(six.ccm == shipped_pencil("6B").ccm);
  EXPECT_EQ(cv::imread((dir_ / "6B.png").string(), cv::IMREAD_GRAYSCALE).rows, pencil::kReferenceRows);

  ASSERT_TRUE(cv::imwrite((dir_ / "blank.png").string(), cv::Mat(50, 50, CV_8UC1, cv::Scalar(250))));
  EXPECT_EQ(tool("pencil-profile " + q(dir_ / "blank.png") + " " + q(dir_ / "d.toml")), 1);
  EXPECT_THAT(err(), HasSubstr("blank.png: no pencil line found (darker than 245 on white paper)"));
  EXPECT_FALSE(fs::exists(dir_ / "d.toml"));
  EXPECT_EQ(tool("pencil-profile " + q(dir_ / "scan.png")), 2) << "OUT.toml missing";
  EXPECT_EQ(tool("pencil-profile --reference 7X " + q(dir_ / "e.toml")), 2);
  EXPECT_EQ(tool("pencil-profile --help"), 0);
  EXPECT_THAT(test::read_file(dir_ / "stdout.txt"), HasSubstr("VERTICALLY"));
}

TEST_F(PencilConvertTool, DrawsALine) {
  ASSERT_EQ(tool("line - " + q(dir_ / "out") + " --set from=10,20 --set to=250,90 --set pencil=2H --set seed=5"), 0)
      << err();
  for (const char* f : {"line.png", "line.json", "report.json"}) EXPECT_TRUE(fs::exists(dir_ / "out" / f)) << f;
  const nlohmann::json j = nlohmann::json::parse(test::read_file(dir_ / "out" / "line.json"));
  EXPECT_EQ(j["path"].back(), nlohmann::json::array({250.0, 90.0}));
  // The same line through the library: the tool writes what a job writes.
  convert_line(params({"from=10,20", "to=250,90", "pencil=2H", "seed=5"}), "--set", dir_ / "lib");
  EXPECT_EQ(test::read_file(dir_ / "out" / "line.png"), test::read_file(dir_ / "lib" / "line.png"));

  // A learned profile file as the pencil.
  ASSERT_TRUE(cv::imwrite((dir_ / "scan.png").string(), pencil::reference_scan(*pencil::find_grade_model("B"), 100, 2)));
  ASSERT_EQ(tool("pencil-profile " + q(dir_ / "scan.png") + " " + q(dir_ / "mine.toml")), 0) << err();
  EXPECT_EQ(tool("line - " + q(dir_ / "own") + " --set from=0,0 --set to=100,0 --set pencil=" + q(dir_ / "mine.toml")),
            0)
      << err();

  EXPECT_EQ(tool("line - " + q(dir_ / "bad") + " --set from=1,x --set to=5,5"), 1);
  EXPECT_THAT(err(), HasSubstr("error: --set: key 'from'")) << "named as the kinds name --set errors";
  EXPECT_EQ(tool("line " + q(dir_ / "scan.png") + " " + q(dir_ / "bad")), 2) << "INPUT must be -";
  EXPECT_EQ(tool("line -"), 2);
  EXPECT_EQ(tool("--help"), 0);
  EXPECT_THAT(test::read_file(dir_ / "stdout.txt"), HasSubstr("pencil-profile"));
}

// A scan that is all line (no paper beside it) once gave a profile 1200 px wide, written and then
// refused by every job that named it.
TEST_F(PencilConvertTool, RefusesToLearnFromAScanThatIsAllLine) {
  ASSERT_TRUE(cv::imwrite((dir_ / "dark.png").string(), cv::Mat(50, 1200, CV_8UC1, cv::Scalar(0))));
  EXPECT_EQ(tool("pencil-profile " + q(dir_ / "dark.png") + " " + q(dir_ / "dark.toml")), 1);
  EXPECT_THAT(err(), HasSubstr("dark.png: the profile learned from it would be unusable"));
  EXPECT_THAT(err(), HasSubstr("width_px"));
  EXPECT_FALSE(fs::exists(dir_ / "dark.toml")) << "an unusable profile was written";
}

}  // namespace
}  // namespace atelier

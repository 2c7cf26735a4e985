// One hand-drawn line (convert/sketch/line_job.h, issue 8): between its end points in the canvas the
// report describes, dark on its path and white away from it, reproducible by seed; bad keys named.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "algorithms/pencil/path.h"
#include "convert/convert.h"
#include "convert/sketch/line_job.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/unit/convert/sketch/line_job_fixture.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using test::PencilLineJob;

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

}  // namespace
}  // namespace atelier

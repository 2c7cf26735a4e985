// The atelier-convert commands that are not job kinds (tools/convert_commands.h), run as the real
// program: `line` draws a line, `pencil-profile` learns a pencil from a scan; exit codes as documented.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "algorithms/pencil/profile.h"
#include "algorithms/pencil/reference_scan.h"
#include "convert/sketch/line_job.h"
#include "convert/sketch/pencil_profile_file.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/unit/convert/sketch/line_job_fixture.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using test::PencilLineJob;

const fs::path kTool = fs::path(ATELIER_BINARY_DIR) / "bin" / "atelier-convert";

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

// End to end: a line drawing dropped into incoming/sketch/ comes out redrawn in pencil
// (preview.png, lines.svg, engrave.gcode, report.json) as a laser job that waits for the
// operator; started, the GRBL laser emulator burns what lines.svg shows. A blank page fails
// with a reason naming the file, and the daemon goes on.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "tests/e2e/burn_compare.h"
#include "tests/e2e/daemon_harness.h"

namespace fs = std::filesystem;
using atelier::test::BackgroundProcess;
using atelier::test::DaemonProcess;
using atelier::test::TempDir;
using nlohmann::json;

namespace {

constexpr double kPxPerMm = 5;
constexpr double kWorkMm = 400;

}  // namespace

TEST(E2ESketch, ALineDrawingIsRedrawnInPencilAndEngravedAsDrawn) {
  TempDir tmp;
  const fs::path link = tmp.path() / "laser", record = tmp.path() / "record.json", render = tmp.path() / "burn.png";
  BackgroundProcess emulator({atelier::test::binary("atelier-laser-emu").string(), "--link", link.string(),
                              "--record", record.string(), "--render", render.string(), "--px-per-mm", "5",
                              "--time-scale", "0.005"},
                             tmp.path() / "emu.log");
  for (int i = 0; i < 100 && !fs::exists(link); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  // At the bed's rear-left corner, so lines.svg's millimetres are the bed's.
  DaemonProcess daemon(tmp.path(), "[sketch]\npencil = \"6B\"\nwidth_mm = 60\nposition_mm = [0, 0]\n"
                                   "[[device]]\nname = \"laser\"\ndriver = \"grbl\"\nport = \"" + link.string() +
                                       "\"\nkinds = [\"sketch\"]\n");
  daemon.start();

  atelier::test::drop_file(atelier::test::test_image("pic3.png"), daemon.incoming("sketch") / "shapes.png");
  ASSERT_TRUE(daemon.wait_job_state("shapes.png", "ready")) << daemon.job_named("shapes.png").dump() << daemon.log();
  const json job = daemon.job_named("shapes.png");
  const fs::path done = job["output_dir"].get<std::string>();
  for (const char* f : {"preview.png", "lines.svg", "engrave.gcode", "report.json"})
    EXPECT_TRUE(fs::exists(done / f)) << f;
  const json report = json::parse(std::ifstream(done / "report.json"));
  EXPECT_EQ(report["pencil"]["name"], "6B");
  EXPECT_GT(report["strokes"].get<int>(), 10);
  const cv::Mat preview = cv::imread((done / "preview.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(preview.cols, 800);  // 400 px at the default scale 2
  EXPECT_GT(cv::countNonZero(preview < 160), 1000) << "no pencil marks in the preview";

  // A laser job waits for the operator; started, it burns what lines.svg draws.
  ASSERT_TRUE(daemon.request("start", {{"id", job["id"]}})["ok"]);
  ASSERT_TRUE(daemon.wait_job_state("shapes.png", "completed", std::chrono::seconds(120)))
      << daemon.job_named("shapes.png").dump() << daemon.log();
  emulator.stop();
  const json rec = json::parse(std::ifstream(record));
  EXPECT_EQ(rec["errors"], 0);
  cv::Mat burnt = cv::imread(render.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(burnt.empty());
  burnt = burnt < 250;
  cv::Mat intended(static_cast<int>(kWorkMm * kPxPerMm), static_cast<int>(kWorkMm * kPxPerMm), CV_8U, cv::Scalar(0));
  atelier::test::draw_strokes(done / "lines.svg", kPxPerMm, intended);
  ASSERT_GT(cv::countNonZero(intended), 1000);
  EXPECT_GT(atelier::test::covered(intended, burnt, 2), 0.95) << "a pencil line was not engraved";
  EXPECT_GT(atelier::test::covered(burnt, intended, 2), 0.95) << "engraved where no pencil line is";

  // A blank page has nothing to draw: it fails naming the file; the daemon carries on.
  cv::imwrite((tmp.path() / "blank.png").string(), cv::Mat(200, 300, CV_8UC3, cv::Scalar(255, 255, 255)));
  atelier::test::drop_file(tmp.path() / "blank.png", daemon.incoming("sketch") / "blank.png");
  ASSERT_TRUE(daemon.wait_job_state("blank.png", "failed")) << daemon.log();
  const std::string reason = daemon.job_named("blank.png")["reason"];
  EXPECT_NE(reason.find("blank.png: nothing to draw"), std::string::npos) << reason;
  EXPECT_TRUE(daemon.request("status")["ok"]);
}

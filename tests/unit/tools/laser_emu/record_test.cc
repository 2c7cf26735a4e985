// The laser emulator's record (tools/laser_emu/record.h): JSON with every field, the segment
// under way, and the render (PNG pixels).
#include <gtest/gtest.h>

#include <cmath>

#include "tests/support/laser_emu_rig.h"

namespace atelier::laser_emu {
namespace {

using testing::Rig;

TEST(LaserEmuRecord, JsonHasEveryFieldWithEpochTimes) {
  ControllerOptions o;
  o.epoch_at_zero_s = 1.7e9;
  o.work_w_mm = 100;
  o.work_h_mm = 80;
  Rig rig(o);
  rig.boot();
  ASSERT_EQ(rig.exchange("G1 X10 F600 M4 S300"), "ok\r\n");
  ASSERT_EQ(rig.exchange("G7"), "error:20\r\n");
  rig.run(2'000'000);
  const auto j = to_json(rig.record);
  ASSERT_EQ(j["segments"].size(), 3u);  // speeding up (0.02 s), cruising, stopping
  const auto& s = j["segments"][1];
  for (const char* key : {"t0", "t1", "x0", "y0", "x1", "y1", "s", "power", "mode", "feed"})
    EXPECT_TRUE(s.contains(key)) << key;
  EXPECT_GT(s["t0"].get<double>(), 1.7e9);
  EXPECT_NEAR(s["t1"].get<double>() - s["t0"].get<double>(), 0.98, 1e-6);  // 9.8 mm at 10 mm/s
  EXPECT_EQ(s["mode"], "M4");
  EXPECT_DOUBLE_EQ(s["power"].get<double>(), 0.3);
  EXPECT_EQ(j["rx_overflows"], 0);
  EXPECT_EQ(j["lines_received"], 2);
  EXPECT_EQ(j["errors"], 1);
  EXPECT_GT(j["max_rx_bytes"].get<int>(), 0);
  EXPECT_EQ(j["work_area_mm"], nlohmann::json({100.0, 80.0}));
  bool error_event = false, beam_off = false;
  for (const auto& e : j["events"]) {
    if (e["event"] == "error") error_event = e["code"] == 20 && e["line"] == 2;
    if (e["event"] == "beam_off") beam_off = true;
  }
  EXPECT_TRUE(error_event);
  EXPECT_TRUE(beam_off);
}

TEST(LaserEmuRecord, SnapshotClosesTheSegmentUnderWay) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G1 X100 F6000 M4 S1000"), "ok\r\n");
  rig.run(500'000);
  ASSERT_EQ(rig.record.segments.size(), 1u);  // the first 0.2 s (10 mm) speeding up
  const Record snap = rig.ctl.snapshot();
  ASSERT_EQ(snap.segments.size(), 2u);
  EXPECT_NEAR(snap.segments[1].x1, 40.0, 0.5);  // then 0.3 s at 100 mm/s
  EXPECT_EQ(snap.segments[1].power, 1.0);
}

TEST(LaserEmuRecord, RenderIsDarkWhereBurnedAndWhiteElsewhere) {
  ControllerOptions o;
  o.work_w_mm = 100;
  o.work_h_mm = 80;
  o.time_scale = 0.01;
  Rig rig(o);
  rig.boot();
  for (const char* line : {"G0 X10 Y10", "M4 S1000 G1 X30 F1200", "Y30", "X10", "Y10 S500", "M5"})
    ASSERT_EQ(rig.exchange(line), "ok\r\n") << line;
  const cv::Mat img = render_burn(rig.record, 5);
  ASSERT_EQ(img.cols, 500);
  ASSERT_EQ(img.rows, 400);
  EXPECT_EQ(img.at<uint8_t>(400 - 10 * 5, 20 * 5), 0);    // bottom edge y=10 at full power
  EXPECT_EQ(img.at<uint8_t>(400 - 30 * 5, 20 * 5), 0);    // top edge
  const int left = img.at<uint8_t>(400 - 20 * 5, 10 * 5);  // left edge at half power
  EXPECT_GT(left, 50);
  EXPECT_LT(left, 200);
  EXPECT_EQ(img.at<uint8_t>(400 - 20 * 5, 20 * 5), 255);  // inside the square
  EXPECT_EQ(img.at<uint8_t>(400 - 5 * 5, 5 * 5), 255);    // the G0 travel leaves no mark
  EXPECT_EQ(img.at<uint8_t>(400 - 10 * 5, 31 * 5), 255);  // just past the corner
}

}  // namespace
}  // namespace atelier::laser_emu

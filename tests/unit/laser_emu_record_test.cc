// The laser emulator's record (JSON) and render (PNG pixels), the G-code arc flattening and
// the command-line fault parsing.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/unit/laser_emu_rig.h"
#include "tools/laser_emu/faults.h"
#include "tools/laser_emu/gcode.h"

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
  ASSERT_EQ(j["segments"].size(), 1u);
  const auto& s = j["segments"][0];
  for (const char* key : {"t0", "t1", "x0", "y0", "x1", "y1", "s", "power", "mode", "feed"})
    EXPECT_TRUE(s.contains(key)) << key;
  EXPECT_GT(s["t0"].get<double>(), 1.7e9);
  EXPECT_NEAR(s["t1"].get<double>() - s["t0"].get<double>(), 1.0, 1e-6);
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
  EXPECT_TRUE(rig.record.segments.empty());
  const Record snap = rig.ctl.snapshot();
  ASSERT_EQ(snap.segments.size(), 1u);
  EXPECT_NEAR(snap.segments[0].x1, 50.0, 0.5);
  EXPECT_EQ(snap.segments[0].power, 1.0);
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

TEST(LaserEmuGcode, ArcsAreCutIntoChordsOnTheCircle) {
  Settings settings(400, 400);
  GcState state;
  const LineResult r = execute_gcode_line("G2X10Y0I5J0F100", state, settings);
  ASSERT_EQ(r.status, 0);
  // GRBL's count: floor(0.5 * pi * 5 / sqrt(0.002 * (2 * 5 - 0.002))) chords.
  ASSERT_EQ(r.actions.size(), 55u);
  for (const Action& a : r.actions) {
    EXPECT_EQ(a.kind, Action::Kind::line);
    EXPECT_NEAR(std::hypot(a.target[0] - 5, a.target[1]), 5.0, 1e-9);
    EXPECT_GE(a.target[1], -1e-9);  // clockwise from (0,0) to (10,0) passes over the top
  }
  EXPECT_EQ(r.actions.back().target, (Vec3{10, 0, 0}));
  EXPECT_EQ(state.position, (Vec3{10, 0, 0}));
  EXPECT_EQ(state.motion, 2);
}

TEST(LaserEmuGcode, InchesAndIncrementalAndG92) {
  Settings settings(400, 400);
  GcState state;
  ASSERT_EQ(execute_gcode_line("G20G91G0X1", state, settings).status, 0);
  EXPECT_DOUBLE_EQ(state.position[0], 25.4);
  ASSERT_EQ(execute_gcode_line("G21G90G92X0", state, settings).status, 0);
  const LineResult r = execute_gcode_line("G0X10", state, settings);
  ASSERT_EQ(r.status, 0);
  EXPECT_DOUBLE_EQ(r.actions.back().target[0], 35.4);  // work X10 = machine 35.4
  EXPECT_EQ(state.modes_report(), "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]");
}

TEST(LaserEmuFaults, SpecsAndWorkArea) {
  Faults f;
  EXPECT_EQ(apply_fault("drop-at-line=12", f), "");
  EXPECT_EQ(f.drop_at_line, 12);
  EXPECT_EQ(apply_fault("alarm-at-line=7:2", f), "");
  EXPECT_EQ(f.alarm_at_line, 7);
  EXPECT_EQ(f.alarm_code, 2);
  EXPECT_EQ(apply_fault("stall-at-line=3", f), "");
  EXPECT_EQ(f.stall_at_line, 3);
  EXPECT_NE(apply_fault("stall-at-line=0", f), "");
  EXPECT_NE(apply_fault("alarm-at-line=5:99", f), "");
  EXPECT_NE(apply_fault("explode=1", f).find("unknown fault"), std::string::npos);
  EXPECT_EQ(parse_work_area("300x200"), (std::pair<double, double>{300, 200}));
  EXPECT_FALSE(parse_work_area("300"));
  EXPECT_FALSE(parse_work_area("0x200"));
}

}  // namespace
}  // namespace atelier::laser_emu

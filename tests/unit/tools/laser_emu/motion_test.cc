// The laser emulator's motion and laser: timing at the feed rate, G0/M3/M4/S0 beam rules,
// feed hold, reset after a hold, dwell. Virtual time. (Alarms in motion: controller_alarm_test.cc.)
#include <gtest/gtest.h>

#include <algorithm>

#include "tests/support/laser_emu_rig.h"

namespace atelier::laser_emu {
namespace {

using testing::Rig;

bool has_event(const Record& r, const std::string& name, std::optional<int> code = {}) {
  return std::any_of(r.events.begin(), r.events.end(),
                     [&](const Event& e) { return e.event == name && (!code || e.code == code); });
}

std::string status(Rig& rig) {
  rig.take();
  rig.send("?");
  rig.run(10'000);  // a status report is under 100 bytes: out within 9 ms
  return rig.take();
}

TEST(LaserEmuMotion, MovesTakeLengthOverFeedTimesTheTimeScale) {
  ControllerOptions o;
  o.time_scale = 0.5;
  Rig rig(o);
  rig.boot();
  ASSERT_EQ(rig.exchange("G1 X100 F6000"), "ok\r\n");  // 100 mm at 100 mm/s: 1 s, halved
  rig.run(440'000);  // 200 mm/s on the clock
  EXPECT_EQ(rig.ctl.state(), MachineState::run);
  EXPECT_NEAR(rig.ctl.position()[0], 88.0, 0.5);
  rig.run(70'000);
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
  EXPECT_DOUBLE_EQ(rig.ctl.position()[0], 100.0);
  ASSERT_EQ(rig.record.segments.size(), 1u);
  const Segment& s = rig.record.segments[0];
  EXPECT_NEAR(s.t1 - s.t0, 0.5, 1e-6);
  EXPECT_EQ(s.x1, 100.0);
  EXPECT_EQ(s.feed, 6000.0);
  EXPECT_EQ(s.mode, "off");
}

TEST(LaserEmuMotion, RapidsRunAtTheMaxRateWithTheBeamOff) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("M4 S1000"), "ok\r\n");
  ASSERT_EQ(rig.exchange("G0 X60"), "ok\r\n");  // $110 = 6000 mm/min: 0.6 s
  rig.run(700'000);
  ASSERT_EQ(rig.record.segments.size(), 1u);
  EXPECT_NEAR(rig.record.segments[0].t1 - rig.record.segments[0].t0, 0.6, 1e-6);
  EXPECT_EQ(rig.record.segments[0].power, 0.0);
  EXPECT_EQ(rig.record.segments[0].mode, "off");
  EXPECT_EQ(rig.record.segments[0].s, 0.0);
}

TEST(LaserEmuMotion, M4PowerFollowsSAndS0TurnsTheBeamOff) {
  Rig rig;
  rig.boot();
  for (const char* line : {"M4 S500", "G0 X10", "G1 X20 F600", "G1 X30 S1000", "G1 X40 S0"})
    ASSERT_EQ(rig.exchange(line), "ok\r\n") << line;
  rig.run(5'000'000);
  ASSERT_EQ(rig.record.segments.size(), 4u);
  const auto& seg = rig.record.segments;
  EXPECT_EQ(seg[0].power, 0.0);  // G0
  EXPECT_EQ(seg[1].power, 0.5);
  EXPECT_EQ(seg[1].mode, "M4");
  EXPECT_EQ(seg[1].s, 500.0);
  EXPECT_EQ(seg[2].power, 1.0);
  EXPECT_EQ(seg[3].power, 0.0);
  EXPECT_EQ(seg[3].mode, "off");
  // Consecutive blocks run without a pause; the beam goes off where S0 starts.
  EXPECT_DOUBLE_EQ(seg[2].t0, seg[1].t1);
  ASSERT_TRUE(has_event(rig.record, "beam_off"));
  EXPECT_DOUBLE_EQ(rig.record.events.back().t, seg[3].t0);
  EXPECT_EQ(rig.ctl.laser_s(), 0.0);  // M4: off when stopped
}

TEST(LaserEmuMotion, M3KeepsTheBeamOnWhenStoppedUntilM5) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("M3 S250"), "ok\r\n");
  ASSERT_EQ(rig.exchange("G1 X5 F600"), "ok\r\n");  // 0.5 s
  rig.run(1'000'000);
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
  EXPECT_EQ(rig.ctl.laser_s(), 250.0);  // constant power: still burning (laser_mode.md)
  ASSERT_EQ(rig.exchange("M5"), "ok\r\n");
  EXPECT_EQ(rig.ctl.laser_s(), 0.0);
  ASSERT_EQ(rig.record.segments.size(), 2u);
  const Segment& dwell = rig.record.segments[1];
  EXPECT_EQ(dwell.x0, 5.0);
  EXPECT_EQ(dwell.x1, 5.0);
  EXPECT_EQ(dwell.power, 0.25);
  EXPECT_EQ(dwell.mode, "M3");
  EXPECT_NEAR(dwell.t1 - dwell.t0, 0.5, 0.01);
  EXPECT_TRUE(has_event(rig.record, "beam_off"));
}

TEST(LaserEmuMotion, FeedHoldDeceleratesStopsTheBeamAndResumes) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G1 X200 F6000 M4 S1000"), "ok\r\n");
  rig.run(500'000);
  rig.send("!");
  EXPECT_EQ(status(rig).rfind("<Hold:1|", 0), 0u);
  EXPECT_GT(rig.ctl.laser_s(), 0.0);  // still moving, still cutting (M4: scaled down)
  rig.run(200'000);                   // 100 mm/s at 500 mm/s^2: 0.2 s, 10 mm
  EXPECT_EQ(status(rig).rfind("<Hold:0|", 0), 0u);
  EXPECT_EQ(rig.ctl.laser_s(), 0.0);
  const double stopped_at = rig.ctl.position()[0];
  ASSERT_EQ(rig.record.segments.size(), 2u);
  const Segment& cruise = rig.record.segments[0];
  const Segment& decel = rig.record.segments[1];
  EXPECT_NEAR(decel.x1 - cruise.x1, 10.0, 1e-6);
  EXPECT_NEAR(decel.t1 - decel.t0, 0.2, 1e-6);
  EXPECT_EQ(decel.x1, stopped_at);
  EXPECT_NEAR(decel.power, 0.5, 1e-9);  // M4 average over a linear slow-down
  EXPECT_TRUE(has_event(rig.record, "hold"));
  EXPECT_TRUE(has_event(rig.record, "beam_off"));
  rig.run(1'000'000);
  EXPECT_EQ(rig.ctl.position()[0], stopped_at);  // holds until resumed
  rig.send("~");
  rig.run(1000);
  EXPECT_EQ(rig.ctl.state(), MachineState::run);
  EXPECT_GT(rig.ctl.laser_s(), 0.0);
  rig.run(2'000'000);
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
  EXPECT_EQ(rig.ctl.position()[0], 200.0);
  EXPECT_TRUE(has_event(rig.record, "resume"));
}

TEST(LaserEmuMotion, ResetAfterAHoldKeepsThePositionWithoutAlarm) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G1 X200 F6000 M4 S500"), "ok\r\n");
  rig.run(500'000);
  rig.send("!");
  rig.run(300'000);
  const double x = rig.ctl.position()[0];
  rig.take();
  rig.send("\x18");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "\r\nGrbl 1.1h ['$' for help]\r\n");
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
  EXPECT_EQ(rig.ctl.position()[0], x);
  EXPECT_EQ(rig.ctl.planner_blocks(), 0);
}

TEST(LaserEmuMotion, DwellWaitsForMotionThenForItsTime) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G1 X10 F600"), "ok\r\n");  // 1 s
  rig.send("G4 P0.5\n");
  const int64_t sent = rig.t;
  ASSERT_TRUE(rig.run_until("ok\r\n", 3'000'000));
  EXPECT_NEAR(static_cast<double>(rig.t - sent), 1'500'000.0, 2'000.0);
}

// Found by fuzz_laser_emu_gcode (tests/fuzz/regressions/laser_emu_gcode/huge-dwell): P seconds
// in ns overflowed int64 (undefined behaviour), and the dwell ended at once.
TEST(LaserEmuMotion, AHugeDwellKeepsWaiting) {
  Rig rig;
  rig.boot();
  rig.send("G4 P99999999999\n");
  rig.run(10'000'000);
  EXPECT_EQ(rig.take(), "") << "the dwell's ok came before its time";
}

// Found by fuzz_laser_emu_gcode (tests/fuzz/regressions/laser_emu_gcode/zero-steps-per-mm):
// with $100=0 an X+Y move computed X as 0/0 mm, and NaN times went into an int64 cast.
TEST(LaserEmuMotion, AnAxisWithoutStepsStaysWhileTheOthersMove) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("$100=0"), "ok\r\n");
  ASSERT_EQ(rig.exchange("G93 G1 X5 Y5 F2"), "ok\r\n");  // inverse time: 30 s
  rig.run(40'000'000);
  rig.take();
  EXPECT_EQ(status(rig).rfind("<Idle|MPos:0.000,5.000,0.000|", 0), 0u);
}

TEST(LaserEmuMotion, StatusReportFields) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(status(rig), "<Idle|MPos:0.000,0.000,0.000|FS:0,0|WCO:0.000,0.000,0.000>\r\n");
  EXPECT_EQ(status(rig), "<Idle|MPos:0.000,0.000,0.000|FS:0,0|Ov:100,100,100>\r\n");
  ASSERT_EQ(rig.exchange("G1 X100 F1200 M4 S800"), "ok\r\n");
  rig.run(1'000'000);
  const std::string s = status(rig);
  EXPECT_EQ(s.rfind("<Run|MPos:20.", 0), 0u) << s;
  EXPECT_NE(s.find("|FS:1200,800"), std::string::npos) << s;
  ASSERT_EQ(rig.exchange("G92 X0", 6'000'000), "ok\r\n");  // waits for the move: 4 more seconds
  ASSERT_EQ(rig.exchange("$10=0"), "ok\r\n");   // WPos
  EXPECT_EQ(status(rig), "<Idle|WPos:0.000,0.000,0.000|FS:0,0|WCO:100.000,0.000,0.000>\r\n");
}

}  // namespace
}  // namespace atelier::laser_emu

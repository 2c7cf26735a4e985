// The laser emulator's motion and laser: timing with GRBL's acceleration ($120/$121 = 500
// mm/s^2 here), G0/M3/M4/S0 beam rules, feed hold, reset after a hold, dwell. Virtual time.
// (Alarms in motion: controller_alarm_test.cc.)
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

TEST(LaserEmuMotion, MovesAccelerateCruiseAndStopTimesTheTimeScale) {
  ControllerOptions o;
  o.time_scale = 0.5;
  Rig rig(o);
  rig.boot();
  // 100 mm at 100 mm/s, 500 mm/s^2: 0.2 s (10 mm) up, 0.8 s cruising, 0.2 s down = 1.2 s, halved.
  ASSERT_EQ(rig.exchange("G1 X100 F6000"), "ok\r\n");
  rig.run(440'000);  // 0.88 s unscaled: 10 mm + 0.68 s at 100 mm/s
  EXPECT_EQ(rig.ctl.state(), MachineState::run);
  EXPECT_NEAR(rig.ctl.position()[0], 78.0, 0.5);
  rig.run(150'000);  // 1.18 s: slowing down for the end
  EXPECT_EQ(rig.ctl.state(), MachineState::run);
  EXPECT_GT(rig.ctl.position()[0], 99.0);
  rig.run(20'000);
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
  EXPECT_DOUBLE_EQ(rig.ctl.position()[0], 100.0);
  // One piece per phase: accelerating, cruising, decelerating.
  ASSERT_EQ(rig.record.segments.size(), 3u);
  const auto& seg = rig.record.segments;
  EXPECT_NEAR(seg[0].t1 - seg[0].t0, 0.1, 1e-6);
  EXPECT_NEAR(seg[0].x1, 10.0, 1e-3);
  EXPECT_NEAR(seg[1].t1 - seg[1].t0, 0.4, 1e-6);
  EXPECT_NEAR(seg[1].x1, 90.0, 1e-3);
  EXPECT_NEAR(seg[2].t1 - seg[0].t0, 0.6, 1e-6);
  EXPECT_EQ(seg[2].x1, 100.0);
  for (const Segment& piece : seg) {
    EXPECT_EQ(piece.feed, 6000.0);
    EXPECT_EQ(piece.mode, "off");
  }
}

TEST(LaserEmuMotion, RapidsRunAtTheMaxRateWithTheBeamOff) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("M4 S1000"), "ok\r\n");
  ASSERT_EQ(rig.exchange("G0 X60"), "ok\r\n");  // $110 = 6000 mm/min: 0.2 + 0.4 + 0.2 s
  rig.run(900'000);
  ASSERT_EQ(rig.record.segments.size(), 3u);
  EXPECT_NEAR(rig.record.segments[2].t1 - rig.record.segments[0].t0, 0.8, 1e-6);
  for (const Segment& piece : rig.record.segments) {
    EXPECT_EQ(piece.power, 0.0);
    EXPECT_EQ(piece.mode, "off");
    EXPECT_EQ(piece.s, 0.0);
  }
}

TEST(LaserEmuMotion, M4PowerFollowsSAndS0TurnsTheBeamOff) {
  Rig rig;
  rig.boot();
  for (const char* line : {"M4 S500", "G0 X10", "G1 X20 F600", "G1 X30 S1000", "G1 X40 S0"})
    ASSERT_EQ(rig.exchange(line), "ok\r\n") << line;
  rig.run(5'000'000);
  const auto& seg = rig.record.segments;
  ASSERT_GE(seg.size(), 4u);
  // S changes on motion lines take effect with their block, without a stop (no buffer sync
  // in laser mode): the pieces follow one another without a gap.
  for (size_t i = 1; i < seg.size(); ++i) EXPECT_DOUBLE_EQ(seg[i].t0, seg[i - 1].t1);
  for (const Segment& piece : seg) {
    const double mid = 0.5 * (piece.x0 + piece.x1);
    if (mid < 10) {
      EXPECT_EQ(piece.power, 0.0);  // G0
    } else if (mid < 20) {
      EXPECT_EQ(piece.power, 0.5);  // at F600 all along: the G0 hands over at 10 mm/s
      EXPECT_EQ(piece.mode, "M4");
      EXPECT_EQ(piece.s, 500.0);
    } else if (mid < 30) {
      EXPECT_EQ(piece.power, 1.0);
    } else {
      EXPECT_EQ(piece.power, 0.0);
      EXPECT_EQ(piece.mode, "off");
    }
  }
  ASSERT_TRUE(has_event(rig.record, "beam_off"));
  const auto s0 = std::find_if(seg.begin(), seg.end(), [](const Segment& p) { return p.x0 >= 30 - 1e-9; });
  ASSERT_NE(s0, seg.end());
  EXPECT_DOUBLE_EQ(rig.record.events.back().t, s0->t0);  // the beam goes off where S0 starts
  EXPECT_EQ(rig.ctl.laser_s(), 0.0);  // M4: off when stopped
}

TEST(LaserEmuMotion, M4BurnsLighterWhereTheHeadAccelerates) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G1 X20 F6000 M4 S1000"), "ok\r\n");  // 10 mm up to speed, 10 mm down
  rig.run(2'000'000);
  ASSERT_EQ(rig.record.segments.size(), 2u);
  // Power follows speed, which rises linearly in time from 0 to 100 mm/s: half on average.
  EXPECT_NEAR(rig.record.segments[0].power, 0.5, 1e-6);
  EXPECT_NEAR(rig.record.segments[1].power, 0.5, 1e-6);
}

TEST(LaserEmuMotion, M3KeepsTheBeamOnWhenStoppedUntilM5) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("M3 S250"), "ok\r\n");
  ASSERT_EQ(rig.exchange("G1 X5 F600"), "ok\r\n");  // 10 mm/s: 0.5 s + 0.02 s of ramps
  rig.run(1'000'000);
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
  EXPECT_EQ(rig.ctl.laser_s(), 250.0);  // constant power: still burning (laser_mode.md)
  ASSERT_EQ(rig.exchange("M5"), "ok\r\n");
  EXPECT_EQ(rig.ctl.laser_s(), 0.0);
  ASSERT_EQ(rig.record.segments.size(), 4u);  // up, cruise, down, standing
  const Segment& dwell = rig.record.segments[3];
  EXPECT_EQ(dwell.x0, 5.0);
  EXPECT_EQ(dwell.x1, 5.0);
  EXPECT_EQ(dwell.power, 0.25);
  EXPECT_EQ(dwell.mode, "M3");
  EXPECT_NEAR(dwell.t1 - dwell.t0, 1.0 - 0.52, 0.01);
  EXPECT_TRUE(has_event(rig.record, "beam_off"));
}

TEST(LaserEmuMotion, FeedHoldDeceleratesStopsTheBeamAndResumes) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G1 X200 F6000 M4 S1000"), "ok\r\n");
  rig.run(500'000);  // up to speed (0.2 s, 10 mm), then cruising at 100 mm/s
  rig.send("!");
  EXPECT_EQ(status(rig).rfind("<Hold:1|", 0), 0u);
  EXPECT_GT(rig.ctl.laser_s(), 0.0);  // still moving, still cutting (M4: scaled down)
  rig.run(200'000);                   // 100 mm/s at 500 mm/s^2: 0.2 s, 10 mm
  EXPECT_EQ(status(rig).rfind("<Hold:0|", 0), 0u);
  EXPECT_EQ(rig.ctl.laser_s(), 0.0);
  const double stopped_at = rig.ctl.position()[0];
  ASSERT_EQ(rig.record.segments.size(), 3u);
  const Segment& cruise = rig.record.segments[1];
  const Segment& decel = rig.record.segments[2];
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
  ASSERT_EQ(rig.exchange("G1 X10 F600"), "ok\r\n");  // 1 s + 0.02 s of ramps
  rig.send("G4 P0.5\n");
  const int64_t sent = rig.t;
  ASSERT_TRUE(rig.run_until("ok\r\n", 3'000'000));
  EXPECT_NEAR(static_cast<double>(rig.t - sent), 1'520'000.0, 2'000.0);
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
  EXPECT_EQ(s.rfind("<Run|MPos:19.6", 0), 0u) << s;  // 0.4 mm in 0.04 s up to 20 mm/s, then 0.96 s at it
  EXPECT_NE(s.find("|FS:1200,800"), std::string::npos) << s;
  ASSERT_EQ(rig.exchange("G92 X0", 6'000'000), "ok\r\n");  // waits for the move: 4 more seconds
  ASSERT_EQ(rig.exchange("$10=0"), "ok\r\n");   // WPos
  EXPECT_EQ(status(rig), "<Idle|WPos:0.000,0.000,0.000|FS:0,0|WCO:100.000,0.000,0.000>\r\n");
}

}  // namespace
}  // namespace atelier::laser_emu

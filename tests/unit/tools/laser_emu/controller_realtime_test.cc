// The extended real-time bytes of the GRBL 1.1h laser controller model
// (tools/laser_emu/controller.h), as serial.c and protocol.c handle them and as the real
// firmware answered them side by side through grbl-sim: the overrides 0x90-0x9D and what "Ov:"
// shows, how override bytes coalesce, the laser's spindle stop in a hold ("[MSG:Restoring
// spindle]", 0x9E), flood coolant (M8, 0xA0, "A:F"), and the safety door 0x84. Virtual time.
#include <gtest/gtest.h>

#include <string>

#include "tests/support/laser_emu_rig.h"

namespace atelier::laser_emu {
namespace {

using testing::Rig;

std::string status(Rig& rig) {
  rig.take();
  rig.send("?");
  rig.run(10'000);
  return rig.take();
}

// The "|Ov:..." field (and "|A:..." after it), or "" when this report has none.
std::string ov(const std::string& report) {
  const auto at = report.find("|Ov:");
  return at == std::string::npos ? "" : report.substr(at + 1, report.find('>') - at - 1);
}

// The report a change of override, spindle or coolant shows in: the next one, or the one after
// when the next carries "|WCO:" (report.c then defers "|Ov:" by one report). "" otherwise.
std::string changed(Rig& rig) {
  const std::string first = status(rig);
  if (!ov(first).empty()) return first;
  if (first.find("|WCO:") == std::string::npos) return "";
  return status(rig);
}

// Real-time bytes one at a time, 20 ms apart (a pendant's buttons).
void press(Rig& rig, const std::string& bytes) {
  for (const char c : bytes) {
    rig.send(std::string(1, c));
    rig.run(20'000);
  }
}

TEST(LaserEmuRealtime, FeedRapidAndSpindleOverridesShowInTheNextReportAndClamp) {
  Rig rig;
  rig.boot();
  EXPECT_NE(status(rig).find("|WCO:"), std::string::npos);  // a session's first report
  EXPECT_EQ(ov(status(rig)), "Ov:100,100,100");  // and Ov in the one after
  EXPECT_EQ(ov(status(rig)), "");  // then every 10th while idle
  press(rig, "\x91");
  EXPECT_EQ(ov(changed(rig)), "Ov:110,100,100");  // a change shows at once
  press(rig, std::string(12, '\x91'));
  EXPECT_EQ(ov(changed(rig)), "Ov:200,100,100");  // MAX_FEED_RATE_OVERRIDE
  press(rig, std::string(25, '\x92'));
  EXPECT_EQ(ov(changed(rig)), "Ov:10,100,100");  // MIN_FEED_RATE_OVERRIDE
  press(rig, "\x90\x93\x93\x94");
  EXPECT_EQ(ov(changed(rig)), "Ov:101,100,100");  // reset, +1, +1, -1
  press(rig, "\x97");
  EXPECT_EQ(ov(changed(rig)), "Ov:101,25,100");
  press(rig, "\x96");
  EXPECT_EQ(ov(changed(rig)), "Ov:101,50,100");
  press(rig, "\x95\x9a\x9c");
  EXPECT_EQ(ov(changed(rig)), "Ov:101,100,111");
  press(rig, std::string(30, '\x9b'));
  EXPECT_EQ(ov(changed(rig)), "Ov:101,100,10");  // MIN_SPINDLE_SPEED_OVERRIDE
  press(rig, "\x99\x9d\x9d");
  EXPECT_EQ(ov(changed(rig)), "Ov:101,100,98");
  press(rig, "\x86\xa1");  // unassigned, and mist without ENABLE_M7: thrown away
  EXPECT_EQ(ov(status(rig)), "");
  rig.send("\x18");  // a reset puts every override back to 100 %
  ASSERT_TRUE(rig.run_until("help]\r\n"));
  status(rig);
  EXPECT_EQ(ov(changed(rig)), "Ov:100,100,100");
}

TEST(LaserEmuRealtime, OverrideBytesCoalesceOnlyWhileTheMainLoopCannotPoll) {
  Rig rig;
  rig.boot();
  // Idle, nine 0x9B on the wire back to back (86.8 us apart): each is applied on arrival.
  rig.send(std::string(9, '\x9b'));
  rig.run(20'000);
  EXPECT_EQ(ov(changed(rig)), "Ov:100,100,10");
  press(rig, "\x99");
  // "$$" is ~700 bytes: the main loop sits in serial_write() on a full TX buffer for ~50 ms
  // and polls nothing meanwhile, so the flags set by nine bytes count once.
  rig.send("$$\n");
  rig.run(5'000);
  rig.send(std::string(9, '\x9b'));
  ASSERT_TRUE(rig.run_until("$132=200.000\r\nok\r\n"));
  EXPECT_EQ(ov(changed(rig)), "Ov:100,100,90");
}

TEST(LaserEmuRealtime, FeedOverrideChangesTheSpeedOfAMoveButNotOfAJog) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G1 X-100 F600"), "ok\r\n");  // 10 mm/s, 10 s
  rig.run(1'000'000);
  EXPECT_NE(status(rig).find("|FS:600,"), std::string::npos);
  press(rig, std::string(10, '\x91'));  // 200 %
  rig.run(500'000);
  EXPECT_NE(status(rig).find("|FS:1200,"), std::string::npos);
  press(rig, "\x90");
  rig.run(500'000);
  EXPECT_NE(status(rig).find("|FS:600,"), std::string::npos);
  rig.run(10'000'000);
  ASSERT_EQ(rig.ctl.state(), MachineState::idle);
  press(rig, std::string(10, '\x91'));
  ASSERT_EQ(rig.exchange("$J=G91X50F600"), "ok\r\n");
  rig.run(1'000'000);
  EXPECT_NE(status(rig).find("|FS:600,"), std::string::npos);  // PL_COND_FLAG_NO_FEED_OVERRIDE
  // Rapids follow the rapid override: 25 % of $110 = 1500 mm/min.
  rig.run(5'000'000);
  press(rig, "\x97");
  ASSERT_EQ(rig.exchange("G0 X-200"), "ok\r\n");
  rig.run(1'000'000);
  EXPECT_NE(status(rig).find("|FS:1500,"), std::string::npos);
}

TEST(LaserEmuRealtime, SpindleOverrideScalesTheLaserPowerUpToS30) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G1 X-100 F600 M3 S500"), "ok\r\n");
  rig.run(1'000'000);
  EXPECT_EQ(rig.ctl.laser_s(), 500.0);
  press(rig, "\x9a");
  EXPECT_EQ(rig.ctl.laser_s(), 550.0);
  EXPECT_NE(status(rig).find("|FS:600,550|"), std::string::npos);
  press(rig, std::string(12, '\x9a'));  // 200 %: 1000, $30
  EXPECT_EQ(rig.ctl.laser_s(), 1000.0);
  rig.run(9'000'000);
  ASSERT_EQ(rig.ctl.state(), MachineState::idle);
  // The record burned at the override's power: a piece at 0.5 of full, later ones at 1.0.
  bool half = false, full = false;
  for (const Segment& s : rig.record.segments) {
    half |= s.power > 0.49 && s.power < 0.51;
    full |= s.power > 0.99;
  }
  EXPECT_TRUE(half);
  EXPECT_TRUE(full);
}

TEST(LaserEmuRealtime, SpindleOverrideAtRestInLaserModeFiresTheBeamAsTheRealOneDoes) {
  // protocol_exec_rt_system(): in Idle a spindle override change calls spindle_set_state()
  // with the parser's M3 and S - in laser mode that turns the beam on standing still.
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("M3 S500"), "ok\r\n");
  EXPECT_EQ(rig.ctl.laser_s(), 0.0);  // laser mode: M3 alone does not fire
  press(rig, "\x9a");
  EXPECT_NE(changed(rig).find("|FS:0,550|Ov:100,100,110|A:S>"), std::string::npos);
  press(rig, "\x99");
  EXPECT_NE(changed(rig).find("|FS:0,500|Ov:100,100,100|A:S>"), std::string::npos);
  ASSERT_EQ(rig.exchange("M4"), "ok\r\n");
  press(rig, "\x9a");
  EXPECT_EQ(rig.ctl.laser_s(), 0.0);  // M4 is forced to 0 in laser mode
}

TEST(LaserEmuRealtime, FloodCoolantFromM8AndTheToggleShowsAsAF) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("M7"), "error:20\r\n");  // mist needs ENABLE_M7
  ASSERT_EQ(rig.exchange("M8"), "ok\r\n");
  EXPECT_NE(changed(rig).find("|Ov:100,100,100|A:F>"), std::string::npos);
  ASSERT_EQ(rig.exchange("M9"), "ok\r\n");
  EXPECT_NE(changed(rig).find("|Ov:100,100,100>"), std::string::npos);
  press(rig, "\xa0");  // toggles flood, and the parser's mode with it
  EXPECT_NE(changed(rig).find("|A:F>"), std::string::npos);
  EXPECT_EQ(rig.exchange("$G"), "[GC:G0 G54 G17 G21 G90 G94 M5 M8 T0 F0 S0]\r\nok\r\n");
  press(rig, "\xa0");
  EXPECT_EQ(rig.exchange("$G"), "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]\r\nok\r\n");
}

TEST(LaserEmuRealtime, AHoldWithTheLaserOnRestoresTheSpindleOnResume) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G1 X-100 F600 M3 S100"), "ok\r\n");
  rig.run(500'000);
  rig.send("!");
  rig.run(2'000);
  EXPECT_NE(status(rig).find("<Hold:1|"), std::string::npos);
  EXPECT_EQ(rig.ctl.laser_s(), 100.0);  // still burning while it slows down
  rig.run(500'000);
  const std::string held = status(rig);
  EXPECT_EQ(held.rfind("<Hold:0|", 0), 0u) << held;
  EXPECT_NE(held.find("|FS:0,0|"), std::string::npos) << held;  // DISABLE_LASER_DURING_HOLD
  rig.send("~");
  rig.run(5'000);
  EXPECT_EQ(rig.take(), "[MSG:Restoring spindle]\r\n");
  rig.run(1'000'000);
  EXPECT_NE(status(rig).find("<Run|"), std::string::npos);
  EXPECT_EQ(rig.ctl.laser_s(), 100.0);
  // 0x9E in a hold turns the beam back on at once (same message), "~" then just resumes.
  rig.send("!");
  rig.run(500'000);
  EXPECT_EQ(rig.ctl.laser_s(), 0.0);
  rig.send("\x9e");
  rig.run(5'000);
  EXPECT_EQ(rig.take(), "[MSG:Restoring spindle]\r\n");
  EXPECT_NE(changed(rig).find("|FS:0,100|Ov:100,100,100|A:S>"), std::string::npos);
  rig.send("~");
  rig.run(100'000);
  EXPECT_EQ(rig.take(), "");
  EXPECT_EQ(rig.ctl.state(), MachineState::run);
  // With M5 there is nothing to restore.
  rig.run(10'000'000);
  ASSERT_EQ(rig.exchange("M5"), "ok\r\n");
  rig.send("!");
  rig.run(10'000);
  rig.send("~");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "");
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
}

TEST(LaserEmuRealtime, OutsideLaserModeASpindleRunsThroughAHoldAndM4IsReported) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("$32=0"), "ok\r\n");
  ASSERT_EQ(rig.exchange("M4 S200"), "ok\r\n");
  EXPECT_NE(status(rig).find("|FS:0,200|"), std::string::npos);
  EXPECT_NE(changed(rig).find("|A:C>"), std::string::npos);
  ASSERT_EQ(rig.exchange("M3 S300 G1 X-50 F600"), "ok\r\n");
  rig.run(500'000);
  rig.send("!");
  rig.run(500'000);
  EXPECT_EQ(rig.ctl.state_name(), "Hold:0");
  EXPECT_EQ(rig.ctl.laser_s(), 300.0);  // no DISABLE_LASER_DURING_HOLD for a spindle
  rig.send("~");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "");
}

TEST(LaserEmuRealtime, SafetyDoorAtRestHoldsLinesUntilResumed) {
  Rig rig;
  rig.boot();
  rig.send("\x84");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "[MSG:Check Door]\r\n");
  EXPECT_EQ(status(rig).rfind("<Door:0|", 0), 0u);  // no door switch: it reads closed at once
  rig.send("G0 X-1\n");
  rig.run(200'000);
  EXPECT_EQ(rig.take(), "");  // the main loop is suspended
  rig.send("~");
  rig.run(200'000);
  EXPECT_EQ(rig.take(), "ok\r\n");
  rig.run(1'000'000);
  EXPECT_EQ(rig.ctl.position()[0], -1.0);
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
}

TEST(LaserEmuRealtime, SafetyDoorInMotionStopsTheBeamAndResumesWithoutARestoreMessage) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G1 X-100 F600 M3 S200"), "ok\r\n");
  rig.run(500'000);
  rig.send("\x84");
  rig.run(2'000);
  EXPECT_EQ(status(rig).rfind("<Door:2|", 0), 0u);  // decelerating
  rig.run(500'000);
  const std::string door = status(rig);
  EXPECT_EQ(door.rfind("<Door:0|", 0), 0u) << door;
  EXPECT_NE(door.find("|FS:0,0|"), std::string::npos) << door;
  rig.send("\x84");  // again: the message again, nothing else
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "[MSG:Check Door]\r\n");
  rig.send("!");  // a feed hold does not take over a door
  rig.run(10'000);
  EXPECT_EQ(rig.ctl.state_name(), "Door:0");
  rig.send("~");
  rig.run(500'000);
  EXPECT_EQ(rig.take(), "");  // a laser has no spindle delay and no restore message
  EXPECT_NE(status(rig).find("<Run|"), std::string::npos);
  EXPECT_EQ(rig.ctl.laser_s(), 200.0);
}

TEST(LaserEmuRealtime, SafetyDoorWithFloodOnRestoresForOneSecond) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("M8"), "ok\r\n");
  rig.send("\x84");
  rig.run(10'000);
  EXPECT_EQ(status(rig).find("A:F"), std::string::npos);  // coolant off in the door
  rig.send("~");
  rig.run(10'000);
  const std::string restoring = status(rig);
  EXPECT_EQ(restoring.rfind("<Door:3|", 0), 0u) << restoring;  // SAFETY_DOOR_COOLANT_DELAY
  EXPECT_NE(restoring.find("|A:F>"), std::string::npos) << restoring;
  rig.run(1'000'000);
  EXPECT_EQ(status(rig).rfind("<Idle|", 0), 0u);
}

TEST(LaserEmuRealtime, SafetyDoorWhileJoggingCancelsTheJogFirst) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("$J=G91X-50F3000"), "ok\r\n");
  rig.run(200'000);
  rig.send("\x84");
  rig.run(2'000);
  EXPECT_EQ(rig.ctl.state_name(), "Jog");  // the jog cancel decelerates first
  rig.run(500'000);
  EXPECT_EQ(rig.ctl.state_name(), "Door:0");
  EXPECT_EQ(rig.ctl.planner_blocks(), 0);
  rig.send("~");
  rig.run(10'000);
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
  EXPECT_GT(rig.ctl.position()[0], -50.0);  // the rest of the jog is gone
}

TEST(LaserEmuRealtime, BufferFieldCountsTheReceiveRingAsGrblDoes) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("$10=3"), "ok\r\n");
  // serial_get_rx_buffer_available(): 128 with the ring empty (not the 127 it can hold).
  EXPECT_NE(status(rig).find("|Bf:15,128|"), std::string::npos);
}

}  // namespace
}  // namespace atelier::laser_emu

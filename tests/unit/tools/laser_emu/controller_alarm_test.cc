// Alarms of the GRBL 1.1h laser controller model (tools/laser_emu/controller.h) as
// protocol.c, report.c and limits.c give them: report_alarm_message()'s 500 ms delay, the
// critical-event loop of ALARM:1/2 ("[MSG:Reset to continue]", a 0x18 sent before it lost,
// no status reports), the executing line's "ok" after the reset, then the banner and the lock.
#include <gtest/gtest.h>

#include "tests/support/laser_emu_rig.h"

namespace atelier::laser_emu {
namespace {

using testing::Rig;

constexpr const char* kBanner = "\r\nGrbl 1.1h ['$' for help]\r\n";
constexpr const char* kLocked = "[MSG:'$H'|'$X' to unlock]\r\n";

ControllerOptions soft_limits_on() {
  ControllerOptions o;
  o.settings = {{22, 1}, {20, 1}};
  return o;
}

TEST(LaserEmuAlarm, SoftLimitAlarmWaits500msLosesAnEarlyResetAndAnswersTheLineAfterTheReset) {
  Rig rig(soft_limits_on());
  rig.run_until(kLocked);  // homing on: power-up is locked
  rig.take();
  ASSERT_EQ(rig.exchange("$X"), "[MSG:Caution: Unlocked]\r\nok\r\n");
  // Stock 1.1h: machine space is -400..0, so X10 is outside.
  rig.send("G0 X10\n");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "ALARM:2\r\n");
  EXPECT_TRUE(rig.ctl.critical_alarm());
  rig.send("?");     // not answered
  rig.send("\x18");  // before "[MSG:Reset to continue]": lost
  rig.run(480'000);
  EXPECT_EQ(rig.take(), "");
  rig.run(20'000);  // 500 ms after the alarm
  EXPECT_EQ(rig.take(), "[MSG:Reset to continue]\r\n");
  rig.send("?$X\n");
  rig.run(1'000'000);
  EXPECT_EQ(rig.take(), "");  // frozen: no report, no answer
  EXPECT_TRUE(rig.ctl.critical_alarm());
  rig.send("\x18");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), std::string("ok\r\n") + kBanner + kLocked);  // the offending line's ok first
  EXPECT_FALSE(rig.ctl.critical_alarm());
  EXPECT_EQ(rig.ctl.state(), MachineState::alarm);
  EXPECT_EQ(rig.ctl.position()[0], 0.0);
}

TEST(LaserEmuAlarm, SoftLimitWhileMovingStopsUnderControlThenAlarm2KeepingThePosition) {
  Rig rig(soft_limits_on());
  rig.run_until(kLocked);
  rig.take();
  ASSERT_EQ(rig.exchange("$X"), "[MSG:Caution: Unlocked]\r\nok\r\n");
  ASSERT_EQ(rig.exchange("G1 X-100 F6000 M4 S500"), "ok\r\n");
  rig.run(300'000);
  rig.send("G1 X-500\n");  // beyond -$130 = -400
  rig.run(5'000);
  EXPECT_EQ(rig.ctl.state_name(), "Hold:1");  // limits_soft_check(): a feed hold first
  rig.run(300'000);
  EXPECT_EQ(rig.take(), "ALARM:2\r\n");
  const double x = rig.ctl.position()[0];
  EXPECT_LT(x, 0.0);
  EXPECT_GT(x, -100.0);
  EXPECT_EQ(rig.ctl.laser_s(), 0.0);
  rig.run(500'000);
  EXPECT_EQ(rig.take(), "[MSG:Reset to continue]\r\n");
  rig.send("\x18");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), std::string("ok\r\n") + kBanner + kLocked);
  EXPECT_EQ(rig.ctl.position()[0], x);  // position kept: no homing needed to trust it
  EXPECT_EQ(rig.exchange("G0 X0"), "error:9\r\n");
}

TEST(LaserEmuAlarm, HardLimitAlarmAnswersTheLineItStruckAfterTheReset) {
  ControllerOptions o;
  o.alarm_at_line = 2;
  Rig rig(o);
  rig.boot();
  ASSERT_EQ(rig.exchange("G1 X-100 F600 M4 S500"), "ok\r\n");
  rig.run(500'000);
  rig.send("G1 X-20\n");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "ALARM:1\r\n");
  EXPECT_EQ(rig.ctl.laser_s(), 0.0);  // beam off at once
  const double x = rig.ctl.position()[0];
  rig.run(495'000);
  EXPECT_EQ(rig.take(), "[MSG:Reset to continue]\r\n");
  EXPECT_EQ(rig.ctl.position()[0], x);  // stopped dead
  rig.send("\x18");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), std::string("ok\r\n") + kBanner + kLocked);
  EXPECT_EQ(rig.ctl.last_acknowledged_line(), 2);
}

TEST(LaserEmuAlarm, ResetInMotionIsAlarm3ThenTheBanner500msLater) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G1 X-200 F6000 M4 S500"), "ok\r\n");
  rig.run(300'000);
  rig.send("\x18");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "ALARM:3\r\n");
  rig.send("?");  // lost in the delay
  rig.run(480'000);
  EXPECT_EQ(rig.take(), "");
  rig.run(20'000);
  EXPECT_EQ(rig.take(), std::string(kBanner) + kLocked);
  EXPECT_EQ(rig.ctl.state(), MachineState::alarm);
}

TEST(LaserEmuAlarm, InjectedNonCriticalAlarmAnswersItsLineThenResets) {
  ControllerOptions o;
  o.alarm_at_line = 1;
  o.alarm_code = 6;
  Rig rig(o);
  rig.boot();
  rig.send("G0 X-1\n");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "ALARM:6\r\n");
  rig.run(500'000);
  EXPECT_EQ(rig.take(), std::string("ok\r\n") + kBanner + kLocked);
  EXPECT_EQ(rig.ctl.state(), MachineState::alarm);
}

}  // namespace
}  // namespace atelier::laser_emu

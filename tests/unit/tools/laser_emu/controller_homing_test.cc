// Homing ($H) and machine space of the GRBL 1.1h laser controller model
// (tools/laser_emu/controller.h) for both builds: stock 1.1h (every axis at -$13x..0 after
// homing, the home pulled off by $27) and HOMING_FORCE_SET_ORIGIN ("Z" in [OPT:], homed axes
// at 0, those homing towards negative in 0..$13x), with soft limits checked against it as
// system_check_travel_limits() does; and the startup lines $N0/$N1.
#include <gtest/gtest.h>

#include "tests/support/laser_emu_rig.h"

namespace atelier::laser_emu {
namespace {

using testing::Rig;

ControllerOptions homing_build(bool force) {
  ControllerOptions o;
  o.settings = {{22, 1}, {20, 1}, {23, 3}};  // X and Y home towards negative (front-left)
  o.force_set_origin = force;
  return o;
}

void boot_locked(Rig& rig) {
  ASSERT_TRUE(rig.run_until("[MSG:'$H'|'$X' to unlock]\r\n"));
  rig.take();
}

TEST(LaserEmuHoming, StockBuildHomesToMinusTravelPlusPullOffAndLimitsToMinusTravelToZero) {
  Rig rig(homing_build(false));
  boot_locked(rig);
  EXPECT_EQ(rig.exchange("G0 X-10"), "error:9\r\n");  // locked until homed
  EXPECT_EQ(rig.exchange("$I"), "[VER:1.1h.20190830:]\r\n[OPT:V,15,128]\r\nok\r\n");
  rig.send("$H\n");
  rig.run(1'000'000);
  EXPECT_EQ(rig.ctl.state_name(), "Home");
  EXPECT_EQ(rig.take(), "");
  // Z (200 mm travel, switch taken 100 mm away) then X and Y (400 mm, 200 mm away): seek at
  // $25=500 mm/min, pull off $27=1 mm, locate at $24=25 mm/min, pull off, $26=250 ms four
  // times: 15.64 s + 27.64 s.
  rig.run(42'200'000);
  EXPECT_EQ(rig.take(), "");
  ASSERT_TRUE(rig.run_until("ok\r\n", 200'000));
  EXPECT_EQ(rig.take(), "ok\r\n");
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
  EXPECT_EQ(rig.ctl.position()[0], -399.0);  // homed towards negative: -$130 + $27
  EXPECT_EQ(rig.ctl.position()[1], -399.0);
  EXPECT_EQ(rig.ctl.position()[2], -1.0);    // towards positive: -$27
  rig.send("?");
  rig.run(10'000);
  EXPECT_EQ(rig.take().rfind("<Idle|MPos:-399.000,-399.000,-1.000|", 0), 0u);
  EXPECT_EQ(rig.exchange("G0 X-390 Y-395"), "ok\r\n");
  rig.run(5'000'000);
  rig.send("G0 X10\n");  // positive X is outside the stock space
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "ALARM:2\r\n");
}

TEST(LaserEmuHoming, ForceSetOriginBuildHomesToZeroAndLimitsToZeroToTravel) {
  Rig rig(homing_build(true));
  boot_locked(rig);
  EXPECT_EQ(rig.exchange("$I"), "[VER:1.1h.20190830:]\r\n[OPT:VZ,15,128]\r\nok\r\n");
  ASSERT_EQ(rig.exchange("$H", 60'000'000), "ok\r\n");
  EXPECT_EQ(rig.ctl.position(), (Vec3{0, 0, 0}));
  EXPECT_EQ(rig.exchange("G0 X390 Y10"), "ok\r\n");
  EXPECT_EQ(rig.exchange("G0 Z-5"), "ok\r\n");  // Z homes towards positive: -200..0
  rig.run(15'000'000);  // idle again, whatever the acceleration
  ASSERT_EQ(rig.ctl.state(), MachineState::idle);
  rig.take();
  rig.send("G0 X401\n");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "ALARM:2\r\n");
}

TEST(LaserEmuHoming, HomingAgainFromNearTheSwitchesIsQuickAndResetDuringHomingIsAlarm6) {
  Rig rig(homing_build(false));
  boot_locked(rig);
  ASSERT_EQ(rig.exchange("$H", 60'000'000), "ok\r\n");
  // 1 mm from each switch now: 2 x (3 mm at 500 mm/min + 1 mm at 25 mm/min + 1 s) = 7.52 s.
  rig.send("$H\n");
  rig.run(7'400'000);
  EXPECT_EQ(rig.take(), "");
  rig.run(200'000);
  EXPECT_EQ(rig.take(), "ok\r\n");
  rig.send("$H\n");
  rig.run(1'000'000);
  rig.send("\x18");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "ALARM:6\r\n");
  rig.run(500'000);
  EXPECT_EQ(rig.take(), "ok\r\n\r\nGrbl 1.1h ['$' for help]\r\n[MSG:'$H'|'$X' to unlock]\r\n");
}

TEST(LaserEmuHoming, WithHomingOffSoftLimitsCannotBeOnAtBoot) {
  ControllerOptions o;
  o.settings = {{20, 1}};  // GRBL refuses $20=1 while $22=0 (error:10)
  Record record;
  EXPECT_THROW(Controller(o, record, 0), std::invalid_argument);
}

TEST(LaserEmuStartup, StartupLinesAreCheckedWhenStoredAndRunAfterEveryReset) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("$N0=G20G91"), "ok\r\n");  // executed to check it
  // F in $13's units (mm here) whatever G20 says, as the real 1.1h prints it.
  EXPECT_EQ(rig.exchange("$G"), "[GC:G0 G54 G17 G20 G91 G94 M5 M9 T0 F0 S0]\r\nok\r\n");
  EXPECT_EQ(rig.exchange("$N1=G1X1"), "error:22\r\n");  // no feed rate: not stored
  EXPECT_EQ(rig.exchange("$N"), "$N0=G20G91\r\n$N1=\r\nok\r\n");
  rig.send("\x18");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "\r\nGrbl 1.1h ['$' for help]\r\n>G20G91:ok\r\n");
  EXPECT_EQ(rig.exchange("$G"), "[GC:G0 G54 G17 G20 G91 G94 M5 M9 T0 F0 S0]\r\nok\r\n");
  EXPECT_EQ(rig.exchange("$RST=*"), "[MSG:Restoring defaults]\r\nok\r\n");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "\r\nGrbl 1.1h ['$' for help]\r\n");  // wiped with everything else
  EXPECT_EQ(rig.exchange("$N"), "$N0=\r\n$N1=\r\nok\r\n");
}

TEST(LaserEmuStartup, ALineThatRanWhenStoredCanFailAfterAResetAndSaysSo) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G1 X-1 F100"), "ok\r\n");
  rig.run(2'000'000);  // stored only when idle
  EXPECT_EQ(rig.exchange("$N1=G1X-2"), "ok\r\n");  // the feed rate is modal: known now
  rig.run(2'000'000);
  rig.send("\x18");
  rig.run(10'000);
  // gc_init() clears the feed rate: the stored line fails at every reset.
  EXPECT_EQ(rig.take(), "\r\nGrbl 1.1h ['$' for help]\r\n>G1X-2:error:22\r\n");
}

}  // namespace
}  // namespace atelier::laser_emu

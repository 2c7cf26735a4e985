// The GRBL 1.1h laser emulator's line protocol: banner, $ commands, error codes, line
// filtering, alarm lock. Virtual time; no pty.
#include <gtest/gtest.h>

#include "tests/unit/laser_emu_rig.h"

namespace atelier::laser_emu {
namespace {

using testing::Rig;

TEST(LaserEmuProtocol, BannerAtPowerOnPacedAtTheBaudRate) {
  Rig rig;
  rig.run(1000);  // 1 ms: at 86.8 us per byte only 11 of the banner's 29 bytes are out
  EXPECT_EQ(rig.out.size(), 11u);
  rig.run(5000);
  EXPECT_EQ(rig.take(), "\r\nGrbl 1.1h ['$' for help]\r\n");
  EXPECT_EQ(rig.ctl.state_name(), "Idle");
}

TEST(LaserEmuProtocol, BuildInfoAndSettings) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("$I"), "[VER:1.1h.20190825:]\r\n[OPT:V,15,128]\r\nok\r\n");
  const std::string settings = rig.exchange("$$");
  EXPECT_EQ(settings.rfind("$0=10\r\n$1=25\r\n", 0), 0u) << settings;
  for (const char* line : {"$10=1\r\n", "$20=1\r\n", "$22=0\r\n", "$30=1000\r\n", "$31=0\r\n", "$32=1\r\n",
                           "$110=6000.000\r\n", "$120=500.000\r\n", "$130=400.000\r\n", "$131=400.000\r\n"})
    EXPECT_NE(settings.find(line), std::string::npos) << line;
  EXPECT_EQ(settings.substr(settings.size() - 4), "ok\r\n");
  EXPECT_EQ(rig.exchange("$G"), "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]\r\nok\r\n");
  EXPECT_EQ(rig.exchange("$N"), "$N0=\r\n$N1=\r\nok\r\n");
  EXPECT_EQ(rig.exchange("$"), "[HLP:$$ $# $G $I $N $x=val $Nx=line $J=line $SLP $C $X $H ~ ! ? ctrl-x]\r\nok\r\n");
}

TEST(LaserEmuProtocol, WorkAreaBecomesTheSoftLimits) {
  ControllerOptions o;
  o.work_w_mm = 300;
  o.work_h_mm = 200;
  Rig rig(o);
  rig.boot();
  const std::string settings = rig.exchange("$$");
  EXPECT_NE(settings.find("$130=300.000\r\n$131=200.000\r\n"), std::string::npos);
}

TEST(LaserEmuProtocol, SettingsAreStoredWithGrblsChecks) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("$10=3"), "ok\r\n");
  EXPECT_NE(rig.exchange("$$").find("$10=3\r\n"), std::string::npos);
  EXPECT_EQ(rig.exchange("$100=-5"), "error:4\r\n");
  EXPECT_EQ(rig.exchange("$0=2"), "error:6\r\n");
  EXPECT_EQ(rig.exchange("$20=1"), "error:10\r\n");  // soft limits need homing ($22)
  EXPECT_EQ(rig.exchange("$7=1"), "error:3\r\n");
  EXPECT_EQ(rig.exchange("$300=1"), "error:3\r\n");
  EXPECT_EQ(rig.exchange("$$$"), "error:3\r\n");
  EXPECT_EQ(rig.exchange("$H"), "error:5\r\n");  // homing disabled
  EXPECT_EQ(rig.exchange("$22=1"), "ok\r\n");
  EXPECT_EQ(rig.exchange("$20=1"), "ok\r\n");
  EXPECT_EQ(rig.exchange("$H"), "ok\r\n");
}

TEST(LaserEmuProtocol, GcodeErrorCodesAsGrbl) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("G1 X10"), "error:22\r\n");      // feed rate never set
  EXPECT_EQ(rig.exchange("G1 X"), "error:2\r\n");         // bad number
  EXPECT_EQ(rig.exchange("1G0"), "error:1\r\n");          // expected command letter
  EXPECT_EQ(rig.exchange("G5"), "error:20\r\n");          // unsupported
  EXPECT_EQ(rig.exchange("M100"), "error:20\r\n");
  EXPECT_EQ(rig.exchange("G20 G21"), "error:21\r\n");     // modal group violation
  EXPECT_EQ(rig.exchange("G1.5 X1"), "error:23\r\n");     // non-integer G
  EXPECT_EQ(rig.exchange("G92 G0 X1"), "error:24\r\n");   // axis command conflict
  EXPECT_EQ(rig.exchange("G0 X1 X2"), "error:25\r\n");    // word repeated
  EXPECT_EQ(rig.exchange("G4"), "error:28\r\n");          // P missing
  EXPECT_EQ(rig.exchange("G1 X1 F-5"), "error:4\r\n");    // negative F
  EXPECT_EQ(rig.exchange("G0 X1 P5"), "error:36\r\n");    // unused words
  EXPECT_EQ(rig.exchange("G2 X10 F100"), "error:35\r\n"); // arc without offsets
  EXPECT_EQ(rig.exchange("G2 X10 Y0 I1 J0 F100"), "error:33\r\n");  // end not on the circle
  EXPECT_EQ(rig.exchange("G0 X1 F100"), "ok\r\n");
  EXPECT_EQ(rig.record.errors, 14);
  ASSERT_FALSE(rig.record.events.empty());
  EXPECT_EQ(rig.record.events.front().event, "error");
  EXPECT_EQ(rig.record.events.front().code, 22);
  EXPECT_EQ(rig.record.events.front().line, 1);
}

TEST(LaserEmuProtocol, LinesLongerThanTheLineBufferAreError11) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("G0X" + std::string(76, '0')), "ok\r\n");         // 79 characters fit
  EXPECT_EQ(rig.exchange("G0X" + std::string(77, '0')), "error:11\r\n");   // 80 do not
  // Spaces and comments do not count.
  EXPECT_EQ(rig.exchange("G0 X1 " + std::string(100, ' ') + "(" + std::string(100, 'c') + ")"), "ok\r\n");
}

TEST(LaserEmuProtocol, FilteringCommentsCaseAndLineEnds) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("g21 (millimetres) g90 ; absolute"), "ok\r\n");
  EXPECT_EQ(rig.exchange("(just a comment)"), "ok\r\n");
  EXPECT_EQ(rig.exchange(""), "ok\r\n");
  rig.send("G21\r\n");  // CR and LF each end a line, as in protocol.c
  rig.run(5000);
  EXPECT_EQ(rig.take(), "ok\r\nok\r\n");
  EXPECT_EQ(rig.ctl.lines_received(), 5);
}

TEST(LaserEmuProtocol, CheckModeParsesWithoutMotionAndLeavesWithAReset) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("$C"), "[MSG:Enabled]\r\nok\r\n");
  EXPECT_EQ(rig.ctl.state(), MachineState::check);
  EXPECT_EQ(rig.exchange("G1 X50 Y20 F1000 M4 S800"), "ok\r\n");
  EXPECT_EQ(rig.exchange("G1 X10"), "ok\r\n");
  EXPECT_EQ(rig.exchange("G1 Q1"), "error:20\r\n");
  rig.send("?");
  rig.run(10000);
  EXPECT_EQ(rig.take().rfind("<Check|MPos:0.000,0.000,0.000|FS:0,0", 0), 0u);
  EXPECT_EQ(rig.ctl.planner_blocks(), 0);
  EXPECT_TRUE(rig.record.segments.empty());
  EXPECT_EQ(rig.exchange("$C"), "[MSG:Disabled]\r\nok\r\n");
  rig.run(5000);
  EXPECT_EQ(rig.take(), "\r\nGrbl 1.1h ['$' for help]\r\n");
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
  EXPECT_EQ(rig.exchange("$G"), "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]\r\nok\r\n");  // parser reset
}

TEST(LaserEmuProtocol, UnlockAndCheckModeNeedTheRightState) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("$X"), "ok\r\n");  // no alarm: no effect
  rig.send("G0 X500\n");                    // outside the 400 mm work area
  ASSERT_TRUE(rig.run_until("[MSG:Reset to continue]\r\n"));
  rig.send("\x18");
  ASSERT_TRUE(rig.run_until("[MSG:'$H'|'$X' to unlock]\r\n"));
  rig.take();
  EXPECT_EQ(rig.exchange("$C"), "error:8\r\n");
  EXPECT_EQ(rig.exchange("G0 X1"), "error:9\r\n");
  EXPECT_EQ(rig.exchange("$I").substr(0, 5), "[VER:");  // $ commands work in Alarm
  EXPECT_EQ(rig.exchange("$X"), "[MSG:Caution: Unlocked]\r\nok\r\n");
  EXPECT_EQ(rig.exchange("G0 X1"), "ok\r\n");
}

}  // namespace
}  // namespace atelier::laser_emu

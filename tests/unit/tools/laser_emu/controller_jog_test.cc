// "$J=" jogging of the GRBL 1.1h laser controller model (tools/laser_emu/controller.h), as
// jog.c and gcode.c's jog rules give it: answered once queued, state Jog, the parser's modes
// untouched, its errors (8, 15, 16, 22, 36), and the 0x85 jog cancel (decelerate, flush,
// Idle with the position kept).
#include <gtest/gtest.h>

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

TEST(LaserEmuJog, AJogIsAnsweredAtOnceRunsAsJogAndLeavesTheParserModes) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("$J=G91G21X25.000Y15.000F3000"), "ok\r\n");  // what atelierctl sends
  EXPECT_EQ(status(rig).rfind("<Jog|MPos:", 0), 0u);
  EXPECT_EQ(rig.exchange("G0 X1"), "error:9\r\n");  // G-code is locked out while jogging
  EXPECT_EQ(rig.exchange("$J=G91X5F3000"), "ok\r\n");  // jogs queue behind each other
  rig.run(2'000'000);
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
  EXPECT_EQ(rig.ctl.position(), (Vec3{30, 15, 0}));
  EXPECT_EQ(rig.exchange("$G"), "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]\r\nok\r\n");  // not G91, not G1
  EXPECT_EQ(rig.exchange("$J=X0Y0F6000"), "ok\r\n");  // absolute jog in the parser's G90
  rig.run(1'000'000);
  EXPECT_EQ(rig.ctl.position(), (Vec3{0, 0, 0}));
}

TEST(LaserEmuJog, JogErrorsAreGrbls) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("$J=X10"), "error:22\r\n");          // F is required
  ASSERT_EQ(rig.exchange("G1 F500"), "ok\r\n");
  EXPECT_EQ(rig.exchange("$J=X10"), "error:22\r\n");          // even with a modal feed rate
  EXPECT_EQ(rig.exchange("$J=G0X10F100"), "error:16\r\n");    // no motion mode of its own
  EXPECT_EQ(rig.exchange("$J=M3X10F100"), "error:16\r\n");
  EXPECT_EQ(rig.exchange("$J=X10F100S5"), "error:36\r\n");    // S and T are unused words
  EXPECT_EQ(rig.exchange("$J=G90G91X10F100"), "error:21\r\n");
  EXPECT_EQ(rig.exchange("$JX10F100"), "error:3\r\n");
  EXPECT_EQ(rig.ctl.position(), (Vec3{0, 0, 0}));
  ASSERT_EQ(rig.exchange("G1 X50 F600"), "ok\r\n");
  EXPECT_EQ(rig.exchange("$J=X10F100"), "error:8\r\n");       // only from Idle or Jog
}

TEST(LaserEmuJog, JogErrorsComeInGcodeCsOrder) {
  // Checked against the real 1.1h: the parser's word errors first, then the missing F, the
  // other block checks, the unused S/T words, and last the commands a jog may not carry.
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("$J=X1X2S5"), "error:25\r\n");        // repeated word, before F
  EXPECT_EQ(rig.exchange("$J=X1S-5"), "error:4\r\n");          // negative value, before F
  EXPECT_EQ(rig.exchange("$J=G0X1"), "error:22\r\n");          // F before the G0 check
  EXPECT_EQ(rig.exchange("$J=N99999999X1F10"), "error:27\r\n");
  EXPECT_EQ(rig.exchange("$J=X1F100T300"), "error:38\r\n");    // tool number, before unused T
  EXPECT_EQ(rig.exchange("$J=G4X1F100"), "error:28\r\n");      // G4 without P, before 16
  EXPECT_EQ(rig.exchange("$J=G4P1X1F100"), "error:16\r\n");
  EXPECT_EQ(rig.exchange("$J=G2X1R1F100"), "error:16\r\n");
  EXPECT_EQ(rig.exchange("$J=X1F100S5G0"), "error:36\r\n");    // unused words before 16
  EXPECT_EQ(rig.exchange("$J=X1F-100"), "error:4\r\n");
  EXPECT_EQ(rig.exchange("$J=N5X-1F600"), "ok\r\n");          // N is allowed
  rig.run(500'000);
  EXPECT_EQ(rig.ctl.position()[0], -1.0);
}

TEST(LaserEmuJog, AJogWithoutAxisWordsGoesToMachineZeroAsTheRealOneDoes) {
  // gcode.c fills the target only from axis words: "$J=F..." jogs to MPos 0,0,0.
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G0 X-20 Y-10"), "ok\r\n");
  rig.run(1'000'000);
  ASSERT_EQ(rig.ctl.position(), (Vec3{-20, -10, 0}));
  EXPECT_EQ(rig.exchange("$J=G91F3000"), "ok\r\n");
  rig.run(2'000'000);
  EXPECT_EQ(rig.ctl.position(), (Vec3{0, 0, 0}));
}

TEST(LaserEmuJog, AJogKeepsM3OnAndCancellingItLeavesTheParserAlone) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("M3 S100"), "ok\r\n");
  ASSERT_EQ(rig.exchange("$J=G91X-50F3000"), "ok\r\n");
  rig.run(300'000);
  EXPECT_EQ(rig.ctl.laser_s(), 100.0);  // jog_execute() plans with the parser's spindle and S
  rig.send("\x85");
  rig.run(500'000);
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
  EXPECT_EQ(rig.exchange("$G"), "[GC:G0 G54 G17 G21 G90 G94 M3 M9 T0 F0 S100]\r\nok\r\n");  // M3 stays
}

TEST(LaserEmuJog, AJogBeyondTheSoftLimitsIsError15WithoutAnAlarm) {
  ControllerOptions o;
  o.settings = {{22, 1}, {20, 1}};
  Rig rig(o);
  ASSERT_TRUE(rig.run_until("[MSG:'$H'|'$X' to unlock]\r\n"));
  rig.take();
  EXPECT_EQ(rig.exchange("$J=G91X-10F1000"), "error:8\r\n");  // locked in Alarm
  ASSERT_EQ(rig.exchange("$X"), "[MSG:Caution: Unlocked]\r\nok\r\n");
  EXPECT_EQ(rig.exchange("$J=G91X10F1000"), "error:15\r\n");  // stock space is -400..0
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
  EXPECT_EQ(rig.exchange("$J=G91X-10F1000"), "ok\r\n");
  rig.run(1'000'000);
  EXPECT_EQ(rig.ctl.position()[0], -10.0);
}

TEST(LaserEmuJog, JogCancelDeceleratesFlushesAndKeepsThePosition) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("$J=G91X100F3000"), "ok\r\n");  // 2 s
  ASSERT_EQ(rig.exchange("$J=G91Y100F3000"), "ok\r\n");
  rig.run(500'000);
  rig.send("\x85");
  rig.run(2'000);
  EXPECT_EQ(rig.ctl.state_name(), "Jog");  // decelerating
  rig.run(500'000);
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
  EXPECT_EQ(rig.ctl.planner_blocks(), 0);  // the queued jog is gone too
  const Vec3 at = rig.ctl.position();
  EXPECT_GT(at[0], 20.0);
  EXPECT_LT(at[0], 40.0);
  EXPECT_EQ(at[1], 0.0);
  rig.run(3'000'000);
  EXPECT_EQ(rig.ctl.position(), at);
  // The parser follows the cancelled position: the next relative jog starts from it.
  ASSERT_EQ(rig.exchange("$J=G91X1F3000"), "ok\r\n");
  rig.run(500'000);
  EXPECT_NEAR(rig.ctl.position()[0], at[0] + 1, 0.01);
  rig.send("\x85");  // no effect when not jogging
  rig.run(10'000);
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
}

}  // namespace
}  // namespace atelier::laser_emu

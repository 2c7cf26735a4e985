// The G-code parser of the laser emulator (tools/laser_emu/gcode.h): GRBL's error codes, arcs cut
// into chords, inches, incremental moves and G92.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/support/laser_emu_rig.h"
#include "tools/laser_emu/gcode.h"

namespace atelier::laser_emu {
namespace {

using testing::Rig;

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

// Numbers GRBL keeps in small integers or floats: range-checked before any cast (these were
// undefined behaviour: casts of 1e59 or of a 10^11-chord count to int).
TEST(LaserEmuGcode, HugeNumbersGetGrblsErrorCodesNotUndefinedBehaviour) {
  Settings settings(400, 400);
  GcState state;
  const std::string digits60(60, '9');
  EXPECT_EQ(execute_gcode_line("G" + digits60, state, settings).status, 2);  // beyond a float
  EXPECT_EQ(execute_gcode_line("G1X" + digits60 + "F100", state, settings).status, 2);
  EXPECT_EQ(execute_gcode_line("G256", state, settings).status, 20);         // over GRBL's uint8
  EXPECT_EQ(execute_gcode_line("M4294967296", state, settings).status, 20);
  EXPECT_EQ(execute_gcode_line("G99999999999999999999", state, settings).status, 20);
  EXPECT_EQ(execute_gcode_line("T99999999999999999999", state, settings).status, 38);
  EXPECT_EQ(execute_gcode_line("N99999999999999999999G0X1", state, settings).status, 27);
  // A full circle of radius 10^20 mm would take ~5e11 chords, past GRBL's uint16 counter.
  EXPECT_EQ(execute_gcode_line("G3X0.001Y0I100000000000000000000J0F100", state, settings).status, 33);
  EXPECT_EQ(state.position, (Vec3{0, 0, 0}));  // nothing of a refused line was applied
  // Integer settings live in a uint8, as in GRBL: $23=300 is 44, $23=1e70 stays below 256.
  Settings s2(400, 400);
  EXPECT_EQ(s2.store(23, 300), 0);
  EXPECT_EQ(s2.get(23), 44);
  EXPECT_EQ(s2.store(23, 1e70), 0);
  EXPECT_LT(s2.get(23), 256);
}

TEST(LaserEmuGcode, OnlyTheFirstEightDigitsCountAsInGrbl) {
  EXPECT_EQ([] {
    double v = 0;
    size_t pos = 0;
    read_grbl_float("123456789", pos, v);
    return v;
  }(), 123456780.0);
  double v = 0;
  size_t pos = 0;
  ASSERT_TRUE(read_grbl_float("1.234567891", pos, v));
  EXPECT_DOUBLE_EQ(v, 1.2345678);
  EXPECT_EQ(pos, 11u);
}

}  // namespace
}  // namespace atelier::laser_emu

// Work offsets of the GRBL 1.1h laser controller model (tools/laser_emu/controller.h and
// gcode.h), as gcode.c and report.c give them: G10 L2/L20 into G54..G59 (kept in "EEPROM"
// across resets, wiped by $RST=#), G28/G30 and their .1, G43.1/G49, and how they show in
// "$#" and in the status report's WCO.
#include <gtest/gtest.h>

#include "tests/support/laser_emu_rig.h"

namespace atelier::laser_emu {
namespace {

using testing::Rig;

std::string params(Rig& rig) { return rig.exchange("$#"); }

TEST(LaserEmuOffsets, G10L20SetsWorkZeroAtTheHeadAndItSurvivesAReset) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G0 X-30 Y-20"), "ok\r\n");
  rig.run(1'000'000);
  ASSERT_EQ(rig.exchange("G10 L20 P1 X0 Y0"), "ok\r\n");  // atelierctl laser origin
  EXPECT_EQ(params(rig).rfind("[G54:-30.000,-20.000,0.000]\r\n[G55:0.000,0.000,0.000]\r\n", 0), 0u);
  rig.send("?");
  rig.run(10'000);
  const std::string report = rig.take();
  EXPECT_NE(report.find("|WCO:-30.000,-20.000,0.000"), std::string::npos) << report;
  ASSERT_EQ(rig.exchange("$10=0"), "ok\r\n");  // WPos
  rig.send("?");
  rig.run(10'000);
  EXPECT_EQ(rig.take().rfind("<Idle|WPos:0.000,0.000,0.000|", 0), 0u);
  ASSERT_EQ(rig.exchange("G0 X10 Y5"), "ok\r\n");
  rig.run(1'000'000);
  EXPECT_EQ(rig.ctl.position(), (Vec3{-20, -15, 0}));
  rig.send("\x18");
  rig.run(10'000);
  rig.take();
  EXPECT_EQ(params(rig).rfind("[G54:-30.000,-20.000,0.000]", 0), 0u);  // EEPROM
  EXPECT_EQ(rig.exchange("$RST=#"), "[MSG:Restoring defaults]\r\nok\r\n");
  rig.run(10'000);
  rig.take();
  EXPECT_EQ(params(rig).rfind("[G54:0.000,0.000,0.000]", 0), 0u);
}

TEST(LaserEmuOffsets, G10L2WritesAnySystemAndItsErrorsAreGrbls) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G10 L2 P2 X5 Y-3"), "ok\r\n");
  EXPECT_NE(params(rig).find("[G55:5.000,-3.000,0.000]\r\n"), std::string::npos);
  ASSERT_EQ(rig.exchange("G55 G0 X0 Y0"), "ok\r\n");
  rig.run(1'000'000);
  EXPECT_EQ(rig.ctl.position(), (Vec3{5, -3, 0}));
  ASSERT_EQ(rig.exchange("G10 L2 P0 Z-1"), "ok\r\n");  // P0: the active system (G55), Z only
  EXPECT_NE(params(rig).find("[G55:5.000,-3.000,-1.000]\r\n"), std::string::npos);
  EXPECT_EQ(rig.exchange("G10 X1"), "error:28\r\n");       // no L, no P
  EXPECT_EQ(rig.exchange("G10 L2 P7 X1"), "error:29\r\n");  // G54..G59 only
  EXPECT_EQ(rig.exchange("G10 L3 P1 X1"), "error:20\r\n");
  EXPECT_EQ(rig.exchange("G10 L2 P1"), "error:26\r\n");     // no axis words
  EXPECT_EQ(rig.exchange("G10 L2 P1 R1 X1"), "error:20\r\n");
  EXPECT_EQ(rig.exchange("G0 G10 L2 P1 X1"), "error:24\r\n");  // axis words claimed twice
}

TEST(LaserEmuOffsets, G28AndG30GoToTheStoredPositionsThroughAnIntermediatePoint) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G0 X-50 Y-40"), "ok\r\n");
  ASSERT_EQ(rig.exchange("G28.1"), "ok\r\n");
  ASSERT_EQ(rig.exchange("G0 X-10 Y-5"), "ok\r\n");
  ASSERT_EQ(rig.exchange("G30.1"), "ok\r\n");
  const std::string p = params(rig);
  EXPECT_NE(p.find("[G28:-50.000,-40.000,0.000]\r\n[G30:-10.000,-5.000,0.000]\r\n"), std::string::npos) << p;
  ASSERT_EQ(rig.exchange("G0 X0 Y0"), "ok\r\n");
  ASSERT_EQ(rig.exchange("G28 X-20"), "ok\r\n");  // via X-20, then only X goes home
  rig.run(2'000'000);
  EXPECT_EQ(rig.ctl.position(), (Vec3{-50, 0, 0}));
  ASSERT_EQ(rig.exchange("G30"), "ok\r\n");  // no axis words: straight to G30
  rig.run(2'000'000);
  EXPECT_EQ(rig.ctl.position(), (Vec3{-10, -5, 0}));
  EXPECT_EQ(rig.exchange("G0 X1"), "ok\r\n");  // the parser's position followed
  rig.run(1'000'000);
  EXPECT_EQ(rig.ctl.position(), (Vec3{1, -5, 0}));
}

TEST(LaserEmuOffsets, ToolLengthOffsetShowsInTloAndWco) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G43.1 Z2.5"), "ok\r\n");
  EXPECT_NE(params(rig).find("[TLO:2.500]\r\n"), std::string::npos);
  rig.send("?");
  rig.run(10'000);
  EXPECT_NE(rig.take().find("|WCO:0.000,0.000,2.500"), std::string::npos);
  ASSERT_EQ(rig.exchange("G0 Z0"), "ok\r\n");  // work Z0 is machine Z 2.5
  rig.run(1'000'000);
  EXPECT_EQ(rig.ctl.position()[2], 2.5);
  EXPECT_EQ(rig.exchange("G43.1 X1"), "error:37\r\n");
  EXPECT_EQ(rig.exchange("G43.1 Z1 X1"), "error:37\r\n");
  EXPECT_EQ(rig.exchange("G43 Z1"), "error:20\r\n");
  ASSERT_EQ(rig.exchange("G49"), "ok\r\n");
  EXPECT_NE(params(rig).find("[TLO:0.000]\r\n"), std::string::npos);
  rig.send("\x18");  // G43.1 is parser state: a reset clears it
  rig.run(10'000);
  rig.take();
  ASSERT_EQ(rig.exchange("G43.1 Z3"), "ok\r\n");
  rig.send("\x18");
  rig.run(10'000);
  rig.take();
  EXPECT_NE(params(rig).find("[TLO:0.000]\r\n"), std::string::npos);
}

}  // namespace
}  // namespace atelier::laser_emu

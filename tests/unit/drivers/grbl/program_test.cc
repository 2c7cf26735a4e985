// G-code made ready for GRBL (drivers/grbl/program.h): stripping, limits, header values,
// extent, time estimates; the frame job.
#include <gtest/gtest.h>

#include "drivers/grbl/program.h"

namespace atelier::grbl {
namespace {

TEST(GrblProgram, StripsCommentsAndSpacesAndKeepsSourceLines) {
  const Program p = parse_program(
      "; s_max=1000\n"
      "; bounds=0,0,100,50\n"
      "\n"
      "g21 g90 (metric, absolute)\r\n"
      "  G0 X10 Y10 ; travel\n"
      "(a whole-line comment)\n"
      "%\n"
      "G1 X20 Y10 F600 S500\n",
      3000);
  ASSERT_EQ(p.lines.size(), 3u);
  EXPECT_EQ(p.lines[0], "G21G90");
  EXPECT_EQ(p.lines[1], "G0X10Y10");
  EXPECT_EQ(p.lines[2], "G1X20Y10F600S500");
  EXPECT_EQ(p.source_line, (std::vector<int>{4, 5, 8}));
  EXPECT_EQ(p.source_text[1], "  G0 X10 Y10 ; travel");
  EXPECT_EQ(p.source_text[0], "g21 g90 (metric, absolute)");  // "\r" dropped
  ASSERT_TRUE(p.s_max);
  EXPECT_DOUBLE_EQ(*p.s_max, 1000);
  ASSERT_TRUE(p.bounds);
  EXPECT_DOUBLE_EQ(p.bounds->max_x, 100);
  EXPECT_DOUBLE_EQ(p.bounds->max_y, 50);
}

TEST(GrblProgram, RefusesLinesLongerThanGrblsBuffer) {
  const std::string ok79 = "G1X" + std::string(76, '1');
  EXPECT_NO_THROW(parse_program(ok79 + "\n", 3000));
  // Spaces and comments do not count: GRBL removes them before its 80-byte buffer.
  EXPECT_NO_THROW(parse_program("G1 X1 Y1 F100 ; " + std::string(200, 'c') + "\n", 3000));
  try {
    parse_program("G0X0\n\nG1X" + std::string(77, '1') + "\n", 3000);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("line 3: longer than 79 characters", 0), 0u) << e.what();
  }
}

TEST(GrblProgram, RefusesRealTimeBytesAndSystemCommands) {
  EXPECT_THROW(parse_program("G1X1?\n", 3000), std::runtime_error);
  EXPECT_NO_THROW(parse_program("G1X1 (why? because!)\n", 3000));  // inside a comment: removed
  try {
    parse_program("G0X0\nG1X\x84\n", 3000);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "line 2: byte 0x84 outside a comment: GRBL reads 0x80-0xFF as real-time commands");
  }
  try {
    parse_program("G0X0\n$32=0\n", 3000);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("line 2: '$32=0' is a GRBL system command", 0), 0u) << e.what();
  }
  EXPECT_THROW(parse_program("; bounds=0,0,10\nG0X0\n", 3000), std::runtime_error);
  EXPECT_THROW(parse_program("; s_max=-3\nG0X0\n", 3000), std::runtime_error);
}

TEST(GrblProgram, ComputesTheExtentWhenNoHeaderGivesIt) {
  const Program p = parse_program(
      "G21 G90\n"
      "G0 X10 Y5\n"
      "G1 X30 Y5 F600\n"
      "G91\n"
      "G1 Y20\n"         // relative: to (30, 25)
      "G90 G20\n"
      "G0 X1 Y1\n",      // inches: (25.4, 25.4)
      3000);
  ASSERT_TRUE(p.bounds);
  EXPECT_DOUBLE_EQ(p.bounds->min_x, 10);
  EXPECT_DOUBLE_EQ(p.bounds->min_y, 5);
  EXPECT_DOUBLE_EQ(p.bounds->max_x, 30);
  EXPECT_DOUBLE_EQ(p.bounds->max_y, 25.4);
  EXPECT_FALSE(parse_program("M5\n", 3000).bounds);  // nothing moves
}

TEST(GrblProgram, ArcsCountTheirBulgeAndLength) {
  // A full circle of radius 10 around (10, 0), from (0, 0), clockwise.
  const Program p = parse_program("G0X0Y0\nG2 X0 Y0 I10 J0 F600\n", 6000);
  ASSERT_TRUE(p.bounds);
  EXPECT_NEAR(p.bounds->min_x, 0, 1e-9);
  EXPECT_NEAR(p.bounds->max_x, 20, 1e-9);
  EXPECT_NEAR(p.bounds->min_y, -10, 1e-9);
  EXPECT_NEAR(p.bounds->max_y, 10, 1e-9);
  EXPECT_NEAR(p.seconds[1], 2 * 3.14159265358979 * 10 / 600 * 60, 1e-6);
  // Half circle by radius: (0,0) -> (20,0), R10, counter-clockwise goes below the axis.
  const Program r = parse_program("G0X0Y0\nG3 X20 Y0 R10 F600\n", 6000);
  EXPECT_NEAR(r.bounds->min_y, -10, 1e-9);
  EXPECT_NEAR(r.bounds->max_y, 0, 1e-9);
  EXPECT_NEAR(r.seconds[1], 3.14159265358979 * 10 / 600 * 60, 1e-6);
}

TEST(GrblProgram, EstimatesSecondsPerLine) {
  const Program p = parse_program(
      "G21 G90\n"
      "G0 X30 Y40\n"        // 50 mm at rapid 3000 mm/min: 1 s
      "G1 X30 Y100 F600\n"  // 60 mm at 600 mm/min: 6 s
      "G4 P0.5\n"           // dwell 0.5 s
      "M5\n",
      3000);
  ASSERT_EQ(p.seconds.size(), 5u);
  EXPECT_DOUBLE_EQ(p.seconds[0], 0);
  EXPECT_NEAR(p.seconds[1], 1.0, 1e-9);
  EXPECT_NEAR(p.seconds[2], 6.0, 1e-9);
  EXPECT_NEAR(p.seconds[3], 0.5, 1e-9);
  EXPECT_NEAR(p.total_seconds(), 7.5, 1e-9);
}

TEST(GrblProgram, FrameTracesTheBoxWithTheBeamOff) {
  const Program f = frame_program(Bounds{5, 10, 105, 60.5}, 3000);
  EXPECT_EQ(f.lines, (std::vector<std::string>{"M5", "G90G21", "G0X5Y10", "G1X105Y10F3000S0", "G1X105Y60.5",
                                               "G1X5Y60.5", "G1X5Y10", "G4P0.01"}));
  ASSERT_TRUE(f.bounds);
  EXPECT_DOUBLE_EQ(f.bounds->max_y, 60.5);
  // 2 * (100 + 50.5) mm at 3000 mm/min plus the dwell.
  EXPECT_NEAR(f.total_seconds() - f.seconds[2], 301.0 / 3000 * 60 + 0.01, 1e-9);
}

}  // namespace
}  // namespace atelier::grbl

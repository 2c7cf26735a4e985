// G-code made ready for GRBL (drivers/grbl/program.h): stripping, limits, header values,
// extent, time estimates; the frame job.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

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
  // GRBL cuts it into floor(pi*r / sqrt(tol*(2r-tol))) = 157 chords ($12 = 0.002 mm), run at
  // 10 mm/s (the corners between chords are shallow) plus 10/500 s to speed up and stop; the
  // tolerance is for targets rounded to 4 um steps.
  constexpr double kPi = 3.14159265358979;
  EXPECT_NEAR(p.seconds[1], 157 * 20 * std::sin(kPi / 157) / 10 + 10.0 / 500, 2e-3);
  // Half circle by radius: (0,0) -> (20,0), R10, counter-clockwise goes below the axis.
  const Program r = parse_program("G0X0Y0\nG3 X20 Y0 R10 F600\n", 6000);
  EXPECT_NEAR(r.bounds->min_y, -10, 1e-9);
  EXPECT_NEAR(r.bounds->max_y, 0, 1e-9);
  EXPECT_NEAR(r.seconds[1], 78 * 20 * std::sin(kPi / 156) / 10 + 10.0 / 500, 2e-3);
}

// Time of a trapezoid that reaches its cruise speed: d mm from v0 to v1 at most vn, mm/s.
double trapezoid(double d, double v0, double vn, double v1, double a) {
  const double ramps = (vn * vn - v0 * v0) / (2 * a) + (vn * vn - v1 * v1) / (2 * a);
  return (vn - v0) / a + (vn - v1) / a + (d - ramps) / vn;
}

TEST(GrblProgram, EstimatesSecondsPerLine) {
  const Program p = parse_program(
      "G21 G90\n"
      "G0 X30 Y40\n"        // 50 mm at rapid: X and Y each at most 3000 mm/min
      "G1 X30 Y100 F600\n"  // 60 mm at 600 mm/min
      "G4 P0.5\n"           // dwell 0.5 s (the head stops first)
      "M5\n",
      3000);
  ASSERT_EQ(p.seconds.size(), 5u);
  EXPECT_DOUBLE_EQ(p.seconds[0], 0);
  // Along (0.6, 0.8) the rapid is min(3000/0.6, 3000/0.8) = 3750 mm/min (62.5 mm/s) and the
  // acceleration min(500/0.6, 500/0.8) = 625 mm/s^2. The corner into (0, 1): GRBL's
  // cos = -0.8, sin(theta/2) = sqrt(0.9), junction direction (-0.6, 0.2)/|..| allows
  // 500/0.9487 mm/s^2; v^2 = a * 0.01 * s / (1 - s).
  const double sd2 = std::sqrt(0.9);
  const double aj = 500 / (0.6 / std::hypot(0.6, 0.2));
  const double vj = std::sqrt(aj * 0.010 * sd2 / (1 - sd2));  // 9.87 mm/s
  EXPECT_NEAR(p.seconds[1], trapezoid(50, 0, 62.5, vj, 625), 1e-6);
  EXPECT_NEAR(p.seconds[2], trapezoid(60, vj, 10, 0, 500), 1e-6);
  EXPECT_NEAR(p.seconds[3], 0.5, 1e-9);
  EXPECT_NEAR(p.total_seconds(), p.seconds[1] + p.seconds[2] + 0.5, 1e-9);
}

TEST(GrblProgram, LaserPowerChangesStopTheHeadOnlyWhereGrblSynchronises) {
  laser::MotionSettings motion;  // 500 mm/s^2
  // Two collinear 10 mm burns at 50 mm/s with the power changed on the move (laser mode: no
  // stop) and on a line of its own (S alone while the laser is on: GRBL empties its planner).
  const Program flowing = parse_program("M4 S100\nG1 X10 F3000\nG1 X20 S500\nM5\n", motion);
  const Program stopping = parse_program("M4 S100\nG1 X10 F3000\nS500\nG1 X20\nM5\n", motion);
  const double alone = 2 * 0.1 + (10 - 2 * 2.5) / 50;  // 10 mm from rest to rest: 0.3 s
  EXPECT_NEAR(stopping.total_seconds(), 2 * alone, 1e-9);
  EXPECT_NEAR(flowing.total_seconds(), 0.1 + 15.0 / 50 + 0.1, 1e-9);  // one 20 mm trapezoid
  // M3 to M4 is a spindle state change: it synchronises too.
  const Program switching = parse_program("M3 S100\nG1 X10 F3000\nM4\nG1 X20\nM5\n", motion);
  EXPECT_NEAR(switching.total_seconds(), 2 * alone, 1e-9);
}

TEST(GrblProgram, DenseEngraveIsSlowerThanLengthOverFeed) {
  // 20 rows of 200 pixels of 0.1 mm at 6000 mm/min, power changing every pixel (M4 laser
  // mode: no stops), back and forth. The 15-block look-ahead holds it to sqrt(2*a*1.4 mm).
  std::string g = "M4 S0\nG1 F6000\n";
  for (int row = 0; row < 20; ++row) {
    g += "G0 Y" + std::to_string(row * 0.1) + "\n";
    for (int px = 1; px <= 200; ++px) {
      const double x = row % 2 ? 20 - px * 0.1 : px * 0.1;
      g += "G1 X" + std::to_string(x) + " S" + std::to_string(px % 7 * 100) + "\n";
    }
  }
  g += "M5\n";
  laser::MotionSettings motion;
  const Program p = parse_program(g, motion);
  const double naive = 20 * 20.0 / 100;  // 4 s of burning at 100 mm/s
  const double v = std::sqrt(2 * 500 * 1.4), capped = 20 * 20.0 / v;  // 10.7 s at 37.4 mm/s
  EXPECT_GT(p.total_seconds(), capped);
  // Each row also speeds up from and slows to a near stop (at most v/a more) and steps 0.1 mm
  // in Y at rapid (a triangle: 2*sqrt(0.1/500) = 0.028 s).
  EXPECT_LT(p.total_seconds(), capped + 20 * (v / 500 + 2 * std::sqrt(0.1 / 500)));
  EXPECT_GT(p.total_seconds(), 2.5 * naive);
}

TEST(GrblProgram, FrameTracesTheBoxWithTheBeamOff) {
  const Program f = frame_program(Bounds{5, 10, 105, 60.5}, 3000);
  EXPECT_EQ(f.lines, (std::vector<std::string>{"M5", "G90G21", "G0X5Y10", "G1X105Y10F3000S0", "G1X105Y60.5",
                                               "G1X5Y60.5", "G1X5Y10", "G4P0.01"}));
  ASSERT_TRUE(f.bounds);
  EXPECT_DOUBLE_EQ(f.bounds->max_y, 60.5);
  // 50 mm/s round 90-degree corners: v^2 = 500*sqrt2 * 0.01 * s/(1-s) with s = sqrt(0.5);
  // the last side stops for the dwell.
  const double s = std::sqrt(0.5), vj = std::sqrt(500 * std::sqrt(2.0) * 0.010 * s / (1 - s));
  EXPECT_NEAR(f.seconds[4], trapezoid(50.5, vj, 50, vj, 500), 1e-6);
  EXPECT_NEAR(f.seconds[5], trapezoid(100, vj, 50, vj, 500), 1e-6);
  EXPECT_NEAR(f.seconds[6], trapezoid(50.5, vj, 50, 0, 500), 1e-6);
  EXPECT_NEAR(f.seconds[7], 0.01, 1e-9);
  // 2 * (100 + 50.5) mm at 3000 mm/min plus the dwell, plus at most 0.1 s per side to speed
  // up and slow down.
  EXPECT_GT(f.total_seconds() - f.seconds[2], 301.0 / 3000 * 60 + 0.01);
  EXPECT_LT(f.total_seconds() - f.seconds[2], 301.0 / 3000 * 60 + 0.01 + 4 * 0.1);
}

}  // namespace
}  // namespace atelier::grbl

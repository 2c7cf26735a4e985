// raster: photo engraving's algorithm: darkness, dithering, power, scan runs, G-code, timing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <sstream>

#include "algorithms/laser/raster.h"

namespace atelier::laser {
namespace {

using ::testing::HasSubstr;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

double share_on(const Grid<uint8_t>& dots) {
  return std::accumulate(dots.v.begin(), dots.v.end(), 0.0) / static_cast<double>(dots.v.size());
}

TEST(RasterDither, DiffusionKernelsSpreadTheWholeErrorForwards) {
  for (Dither d : {Dither::floyd_steinberg, Dither::jarvis, Dither::stucki}) {
    const auto k = diffusion_kernel(d);
    ASSERT_FALSE(k.empty()) << dither_name(d);
    double sum = 0;
    for (const auto& t : k) {
      sum += t.w;
      EXPECT_TRUE(t.dy > 0 || (t.dy == 0 && t.dx > 0)) << dither_name(d) << ": a tap on a visited pixel";
    }
    EXPECT_NEAR(sum, 1.0, 1e-12) << dither_name(d);
  }
  EXPECT_EQ(diffusion_kernel(Dither::floyd_steinberg).size(), 4u);
  EXPECT_EQ(diffusion_kernel(Dither::jarvis).size(), 12u);
  EXPECT_EQ(diffusion_kernel(Dither::stucki).size(), 12u);
  EXPECT_NEAR(diffusion_kernel(Dither::jarvis)[0].w, 7.0 / 48, 1e-12);
  EXPECT_NEAR(diffusion_kernel(Dither::stucki)[0].w, 8.0 / 42, 1e-12);
}

// Error diffusion keeps a flat grey's darkness as the share of burned dots, and a ramp's
// darkness column by column (the photo's tones survive).
TEST(RasterDither, ErrorDiffusionKeepsTheMeanDarkness) {
  for (Dither d : {Dither::floyd_steinberg, Dither::jarvis, Dither::stucki}) {
    for (float level : {0.1f, 0.25f, 0.5f, 0.8f}) {
      Grid<float> flat(96, 96, level);
      EXPECT_NEAR(share_on(dither(flat, d)), level, 0.01) << dither_name(d) << " at " << level;
    }
    Grid<float> ramp(64, 256);
    for (int r = 0; r < ramp.rows; ++r)
      for (int c = 0; c < ramp.cols; ++c) ramp.at(r, c) = static_cast<float>(c) / (ramp.cols - 1);
    const Grid<uint8_t> dots = dither(ramp, d);
    for (int band = 0; band < 4; ++band) {
      double on = 0, want = 0;
      for (int r = 0; r < dots.rows; ++r)
        for (int c = band * 16; c < band * 16 + 16; ++c) on += dots.at(r, c), want += ramp.at(r, c);
      EXPECT_NEAR(on / (16.0 * dots.rows), want / (16.0 * dots.rows), 0.03) << dither_name(d) << " band " << band;
    }
  }
}

TEST(RasterDither, OrderedIsThe8x8BayerPattern) {
  // A quarter grey burns exactly 16 dots of every 8 x 8 tile, the same in every tile.
  Grid<float> flat(32, 24, 0.25f);
  const Grid<uint8_t> dots = dither(flat, Dither::ordered);
  for (int tr = 0; tr < 3; ++tr)
    for (int tc = 0; tc < 4; ++tc) {
      int on = 0;
      for (int r = 0; r < 8; ++r)
        for (int c = 0; c < 8; ++c) {
          on += dots.at(tr * 8 + r, tc * 8 + c);
          EXPECT_EQ(dots.at(tr * 8 + r, tc * 8 + c), dots.at(r, c));
        }
      EXPECT_EQ(on, 16);
    }
  // Bayer's first levels: the darkest-first dot is (0,0), then (4,4), then (0,4) and (4,0)
  // are the next two, so a 4/64 grey burns exactly those four.
  Grid<float> light(8, 8, 4.0f / 64);
  const Grid<uint8_t> four = dither(light, Dither::ordered);
  EXPECT_EQ(share_on(four) * 64, 4);
  EXPECT_EQ(four.at(0, 0), 1);
  EXPECT_EQ(four.at(4, 4), 1);
  EXPECT_EQ(four.at(0, 4), 1);
  EXPECT_EQ(four.at(4, 0), 1);
}

TEST(RasterDither, ThresholdBurnsWhatIsDarkerThanIt) {
  Grid<float> g(3, 1);
  g.v = {0.3f, 0.5f, 0.7f};
  EXPECT_EQ(dither(g, Dither::threshold).v, (std::vector<uint8_t>{0, 0, 1}));
  EXPECT_EQ(dither(g, Dither::threshold, 0.2).v, (std::vector<uint8_t>{1, 1, 1}));
}

TEST(RasterPower, GreyscaleMapsDarknessIntoThePowerRangeWithGamma) {
  Grid<uint8_t> grey(4, 1);
  grey.v = {0, 128, 254, 255};
  PowerSettings s;
  s.dither = Dither::greyscale;
  s.min_power_pct = 20;
  s.max_power_pct = 80;
  s.s_max = 1000;
  const double d128 = 1 - 128 / 255.0, d254 = 1 - 254 / 255.0;
  EXPECT_EQ(power_grid(grey, s).v,
            (std::vector<int>{800, int(std::lround(200 + 600 * d128)), int(std::lround(200 + 600 * d254)), 0}))
      << "black at max, white not burned, the lightest grey at about min";
  s.gamma = 2;
  EXPECT_EQ(power_grid(grey, s).at(0, 1), std::lround(200 + 600 * d128 * d128));
  s.gamma = 1;
  s.negative = true;
  EXPECT_EQ(power_grid(grey, s).at(0, 3), 800) << "negative: white burns at max";
  EXPECT_EQ(power_grid(grey, s).at(0, 0), 0) << "negative: black is not burned";
  // Dithered dots burn at max power, whatever min is.
  s.negative = false;
  s.dither = Dither::threshold;
  EXPECT_EQ(power_grid(grey, s).v, (std::vector<int>{800, 0, 0, 0}));
}

TEST(RasterPower, UnusableSettingsAreRefused) {
  Grid<uint8_t> grey(2, 2, 0);
  PowerSettings s;
  s.gamma = 0;
  EXPECT_THROW(power_grid(grey, s), PlanError);
  s.gamma = 1;
  s.min_power_pct = 60;
  s.max_power_pct = 50;
  EXPECT_THROW(power_grid(grey, s), PlanError);
  s.min_power_pct = 0;
  s.max_power_pct = 101;
  EXPECT_THROW(power_grid(grey, s), PlanError);
}

Grid<int> rows_of(const std::vector<std::vector<int>>& rows) {
  Grid<int> g(static_cast<int>(rows[0].size()), static_cast<int>(rows.size()));
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c) g.at(r, c) = rows[static_cast<size_t>(r)][static_cast<size_t>(c)];
  return g;
}

TEST(RasterScan, EqualNeighboursMergeIntoOneRunAndMarginsAreSkipped) {
  const auto lines = scan_lines(rows_of({{0, 0, 5, 5, 5, 0, 7, 0, 0}}), true);
  ASSERT_EQ(lines.size(), 1u);
  const auto& runs = lines[0].runs;
  ASSERT_EQ(runs.size(), 3u);
  EXPECT_EQ(runs[0].col0, 2);
  EXPECT_EQ(runs[0].col1, 5);
  EXPECT_EQ(runs[0].s, 5);
  EXPECT_EQ(runs[1].s, 0) << "the gap is crossed at S0, at speed";
  EXPECT_EQ(runs[2].col0, 6);
  EXPECT_EQ(runs[2].col1, 7);
}

TEST(RasterScan, BlankLinesAreSkippedAndDirectionsAlternate) {
  const Grid<int> g = rows_of({{0, 0, 0}, {1, 2, 0}, {0, 0, 0}, {0, 3, 3}, {4, 0, 0}});
  const auto lines = scan_lines(g, true);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0].row, 1);
  EXPECT_EQ(lines[1].row, 3);
  EXPECT_EQ(lines[2].row, 4);
  EXPECT_TRUE(lines[0].forward);
  EXPECT_FALSE(lines[1].forward) << "the next scanned line comes back";
  EXPECT_TRUE(lines[2].forward);
  EXPECT_EQ(lines[0].runs.front().s, 1);
  EXPECT_EQ(lines[0].runs.back().s, 2);
  const auto one_way = scan_lines(g, false);
  for (const auto& l : one_way) EXPECT_TRUE(l.forward);
}

RasterPlacement place_at(double x, double y, double dot, double line) {
  RasterPlacement p;
  p.x_mm = x;
  p.y_mm = y;
  p.dot_mm = dot;
  p.line_mm = line;
  return p;
}

TEST(RasterGcode, EachLineRunsUpAndOutAtSpeedWithOneG1PerRun) {
  // Two rows of 8 dots of 0.5 mm; the image's front-left corner at (10, 20), lines 1 mm apart.
  const Grid<int> g = rows_of({{0, 0, 500, 500, 0, 900, 0, 0}, {0, 0, 0, 300, 300, 300, 0, 0}});
  RasterMotion motion;
  motion.speed_mm_min = 3000;
  motion.overscan_mm = 2.5;
  Machine m;
  const RasterJob job = raster_gcode(g, scan_lines(g, true), place_at(10, 20, 0.5, 1), motion, m, "test");
  const auto lines = lines_of(job.gcode);
  const std::vector<std::string> want{"; atelier laser job", "; s_max=1000", "; bounds=11,20.5,13,21.5", "G21 G90",
                                      "; test",              "M4 S0",
                                      // Row 0 (top, Y 21.5) left to right: run-up, 3 runs, run-out.
                                      "G0 X8.5 Y21.5", "G1 X11 F3000", "G1 X12 S500", "G1 X12.5 S0",
                                      "G1 X13 S900", "G1 X15.5 S0",
                                      // Row 1 (Y 20.5) right to left.
                                      "G0 Y20.5", "G1 X13", "G1 X11.5 S300", "G1 X9 S0", "M5"};
  EXPECT_EQ(lines, want);
  EXPECT_EQ(job.burn_moves, 3u);
  EXPECT_NEAR(job.burn_length_mm, 1 + 0.5 + 1.5, 1e-9);
  EXPECT_EQ(job.scanned_rows, 2u);
  EXPECT_FALSE(job.overscan_clipped);
}

TEST(RasterGcode, OverscanFollowsSpeedAndAccelerationAndStaysOnTheBed) {
  EXPECT_NEAR(overscan_for(3000, 500), 1.1 * 50 * 50 / 1000.0, 1e-12);   // 2.75 mm
  EXPECT_NEAR(overscan_for(6000, 500), 4 * overscan_for(3000, 500), 1e-12);
  EXPECT_NEAR(overscan_for(3000, 1000), overscan_for(3000, 500) / 2, 1e-12);
  const Grid<int> g = rows_of({{1, 1}});
  RasterMotion motion;
  motion.overscan_mm = 5;
  Machine m;
  m.width_mm = 100;
  const RasterJob job = raster_gcode(g, scan_lines(g, true), place_at(1, 1, 0.5, 0.5), motion, m, "");
  EXPECT_THAT(job.gcode, HasSubstr("G0 X0 Y1.25\n")) << job.gcode;
  EXPECT_TRUE(job.overscan_clipped);
}

TEST(RasterGcode, AJobOutsideTheWorkAreaOrWithNothingToBurnIsRefused) {
  const Grid<int> g = rows_of({{1, 1}});
  Machine m;
  m.width_mm = 100;
  m.height_mm = 100;
  try {
    raster_gcode(g, scan_lines(g, true), place_at(99.5, 10, 0.5, 0.5), RasterMotion{}, m, "");
    FAIL() << "no PlanError";
  } catch (const PlanError& e) {
    EXPECT_THAT(e.what(), HasSubstr("X 99.5..100.5 mm"));
    EXPECT_THAT(e.what(), HasSubstr("100 x 100 mm work area"));
  }
  const Grid<int> blank = rows_of({{0, 0}});
  EXPECT_THROW(raster_gcode(blank, scan_lines(blank, true), place_at(1, 1, 0.5, 0.5), RasterMotion{}, m, ""),
               PlanError);
}

}  // namespace
}  // namespace atelier::laser

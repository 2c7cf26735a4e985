// The GRBL 1.1h planner model: move times and junction speeds against hand computations from
// planner.c's formulas (mm/s here; the model works in mm/min like GRBL).
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <vector>

#include "algorithms/laser/motion_planner.h"

namespace atelier::laser {
namespace {

double total(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

PlannedMove g1(double x, double y, double f) { return {{x, y, 0}, f, false}; }

TEST(LaserMotionPlanner, StraightLineIsATrapezoid) {
  MotionSettings s;  // 500 mm/s^2 on X and Y
  // 100 mm at 50 mm/s: 0.1 s and 2.5 mm to reach speed, the same to stop, 95 mm cruising.
  auto t = move_seconds({g1(100, 0, 3000)}, s);
  ASSERT_EQ(t.size(), 1u);
  EXPECT_NEAR(t[0], 0.1 + 95.0 / 50 + 0.1, 1e-9);
  // 1 mm asked at 100 mm/s never gets there: a triangle peaking at sqrt(a*d) = 22.36 mm/s.
  auto tri = move_seconds({g1(1, 0, 6000)}, s);
  EXPECT_NEAR(tri[0], 2 * std::sqrt(500.0 * 1) / 500, 1e-9);
}

TEST(LaserMotionPlanner, RightAngleCornerUsesJunctionDeviation) {
  MotionSettings s;
  s.junction_deviation_mm = 0.010;
  auto p = plan_profiles({g1(100, 0, 3000), g1(100, 100, 3000)}, s);
  ASSERT_EQ(p.size(), 2u);
  // 90 degrees: sin(theta/2) = sqrt(0.5); the junction direction (-1,1)/sqrt2 allows
  // 500*sqrt2 mm/s^2; v^2 = a * $11 * s/(1-s).
  const double sd2 = std::sqrt(0.5);
  const double v = std::sqrt(500 * std::sqrt(2.0) * 0.010 * sd2 / (1 - sd2));  // 4.13 mm/s
  EXPECT_NEAR(p[0].exit_mm_min / 60, v, 1e-6);
  EXPECT_NEAR(p[1].entry_mm_min / 60, v, 1e-6);
  EXPECT_NEAR(p[1].exit_mm_min, 0, 1e-12);
  const double decel = (50 - v) / 500, decel_mm = (2500 - v * v) / 1000;
  EXPECT_NEAR(p[0].seconds, 0.1 + decel + (100 - 2.5 - decel_mm) / 50, 1e-9);
  EXPECT_NEAR(p[1].seconds, p[0].seconds, 1e-9);  // the mirror image
  // A larger deviation lets the corner go faster, so the job is shorter.
  s.junction_deviation_mm = 0.1;
  EXPECT_LT(total(move_seconds({g1(100, 0, 3000), g1(100, 100, 3000)}, s)),
            p[0].seconds + p[1].seconds - 0.005);
}

TEST(LaserMotionPlanner, BackAndForthRasterStopsAtEveryReversal) {
  MotionSettings s;
  std::vector<PlannedMove> raster;
  for (int row = 0; row < 40; ++row) raster.push_back(g1(row % 2 ? 0 : 10, 0, 6000));
  auto p = plan_profiles(raster, s);
  // A reversal's junction speed is 0: each 10 mm pass is its own triangle (peak 70.7 mm/s),
  // 0.283 s, nearly three times the 0.1 s that length / feed says.
  for (const auto& b : p) {
    EXPECT_NEAR(b.entry_mm_min, 0, 1e-9);
    EXPECT_NEAR(b.exit_mm_min, 0, 1e-9);
    EXPECT_NEAR(b.seconds, 2 * std::sqrt(500.0 * 10) / 500, 1e-9);
  }
}

TEST(LaserMotionPlanner, LongChainOfShortBlocksIsLimitedByTheFifteenBlockWindow) {
  MotionSettings s;
  std::vector<PlannedMove> line;  // 100 mm as 1000 collinear 0.1 mm moves (engrave pixels)
  for (int i = 1; i <= 1000; ++i) line.push_back(g1(i * 0.1, 0, 6000));
  auto p = plan_profiles(line, s);
  // Block i is prepared with blocks i..i+14 in the planner and the last one must stop, so
  // block i+1 may enter at most at v^2 = 2*a*(14 * 0.1 mm): 37.4 mm/s, not the 100 asked.
  const double v = std::sqrt(2 * 500 * 14 * 0.1);
  EXPECT_NEAR(p[500].entry_mm_min / 60, v, 1e-6);
  EXPECT_NEAR(p[500].exit_mm_min / 60, v, 1e-6);
  // Inside the block the head speeds up and slows again (a saw tooth): peak^2 = v^2 + a*d.
  const double peak = std::sqrt(v * v + 500 * 0.1);
  EXPECT_NEAR(p[500].seconds, 2 * (peak - v) / 500, 1e-9);
  const double t = total(move_seconds(line, s));
  EXPECT_GT(t, 100 / peak);
  EXPECT_LT(t, 100 / v + 0.2);
  // With a planner deep enough to see the whole line it is one trapezoid: 1.2 s.
  s.planner_blocks = 2000;
  EXPECT_NEAR(total(move_seconds(line, s)), 0.2 + 80.0 / 100 + 0.2, 1e-6);
}

TEST(LaserMotionPlanner, SyncStopsBetweenMovesAndRapidsUseAxisLimits) {
  MotionSettings s;
  const double one = move_seconds({g1(10, 0, 3000)}, s)[0];
  // Collinear moves flow through; with the planner emptied between them both stop.
  EXPECT_LT(total(move_seconds({g1(10, 0, 3000), g1(20, 0, 3000)}, s)), 2 * one - 0.05);
  PlannedMove second = g1(20, 0, 3000);
  second.from_rest = true;
  EXPECT_NEAR(total(move_seconds({g1(10, 0, 3000), second}, s)), 2 * one, 1e-9);
  // G0 along the diagonal: each axis at most 6000 mm/min, so 6000*sqrt2 along the path, and
  // Z's lower limits bound a move with Z in it.
  s.max_rate_mm_min = {6000, 3000, 500};
  auto p = plan_profiles({{{300, 300, 0}, 0, true}}, s);
  EXPECT_NEAR(p[0].nominal_mm_min, 3000 * std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(p[0].accel_mm_min2, 500 * 3600 * std::sqrt(2.0), 1e-3);
}

TEST(LaserMotionPlanner, TargetsRoundToWholeSteps) {
  MotionSettings s;
  s.steps_per_mm = {80, 80, 80};
  // 0.004 mm is 0.32 steps: no step, no block, no time (GRBL's PLAN_EMPTY_BLOCK).
  auto p = plan_profiles({g1(0.004, 0, 1000), g1(0.01, 0, 1000)}, s);
  EXPECT_EQ(p[0].millimeters, 0);
  EXPECT_EQ(p[0].seconds, 0);
  EXPECT_NEAR(p[1].millimeters, 1 / 80.0, 1e-12);  // 0.8 steps rounds to one 0.0125 mm step
  // Starting off the origin: the head is at 5 mm, so going to 5 mm is empty.
  EXPECT_EQ(move_seconds({g1(5, 0, 1000)}, s, {5, 0, 0})[0], 0);
}

TEST(LaserMotionPlanner, SettingsFromGrblNumbers) {
  auto s = motion_settings_from({{11, 0.02}, {100, 80}, {101, 81}, {102, 400}, {110, 5000},
                                 {111, 4000}, {112, 300}, {120, 1000}, {121, 900}, {122, 50},
                                 {130, 400}});
  EXPECT_EQ(s.junction_deviation_mm, 0.02);
  EXPECT_EQ(s.steps_per_mm, (std::array<double, 3>{80, 81, 400}));
  EXPECT_EQ(s.max_rate_mm_min, (std::array<double, 3>{5000, 4000, 300}));
  EXPECT_EQ(s.accel_mm_s2, (std::array<double, 3>{1000, 900, 50}));
  EXPECT_EQ(motion_settings_from({}).accel_mm_s2, MotionSettings{}.accel_mm_s2);
  s.accel_mm_s2[1] = 0;
  EXPECT_THROW(move_seconds({g1(1, 1, 100)}, s), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::laser

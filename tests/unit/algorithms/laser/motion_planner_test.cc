// GRBL 1.1h's planner as a model: figures worked by hand from planner.c's formulas.
#include "algorithms/laser/motion_planner.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

namespace atelier::laser {
namespace {

MotionSettings settings_500() {
  MotionSettings s;
  s.max_rate_mm_min = {6000, 6000, 500};
  s.accel_mm_s2 = {500, 500, 100};
  s.steps_per_mm = {80, 80, 80};
  s.junction_deviation_mm = 0.010;
  return s;
}

PlannedMove line(double x, double y, double feed) { return PlannedMove{{x, y, 0}, feed, false, false}; }

double total(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

TEST(MotionPlanner, AStraightLineAcceleratesCruisesAndStops) {
  // 100 mm at 100 mm/s, 500 mm/s^2: 0.2 s and 10 mm up, 80 mm cruising, 0.2 s down.
  const auto s = move_seconds({line(100, 0, 6000)}, settings_500());
  ASSERT_EQ(s.size(), 1u);
  EXPECT_NEAR(s[0], 1.2, 1e-9);
}

TEST(MotionPlanner, CollinearMovesRunThroughTheirJunctionAtFullSpeed) {
  const auto s = move_seconds({line(50, 0, 6000), line(100, 0, 6000)}, settings_500());
  EXPECT_NEAR(total(s), 1.2, 1e-9);
  EXPECT_NEAR(s[0], 0.2 + 0.4, 1e-9);  // up to speed, then cruising to the junction
}

TEST(MotionPlanner, ARightAngleSlowsToTheJunctionDeviationSpeed) {
  // cos(theta) = 0, sin(theta/2) = 0.7071; junction accel along (-1,1)/sqrt2: 707.1 mm/s^2.
  // v^2 = 707.1 * 0.01 * 0.7071 / (1 - 0.7071) = 17.07 -> 4.131 mm/s at the corner.
  const auto p = plan_moves({line(50, 0, 6000), line(50, 50, 6000)}, settings_500());
  const double v = std::sqrt(707.10678 * 0.01 * 0.70710678 / (1 - 0.70710678));
  EXPECT_NEAR(p[0].exit_mm_min / 60, v, 1e-3);
  EXPECT_NEAR(p[1].entry_mm_min / 60, v, 1e-3);
  const double decel_s = (100 - v) / 500, decel_mm = (100 * 100 - v * v) / 1000;
  EXPECT_NEAR(p[0].seconds, 0.2 + (50 - 10 - decel_mm) / 100 + decel_s, 1e-6);
  EXPECT_NEAR(p[0].seconds, p[1].seconds, 1e-9);
}

TEST(MotionPlanner, AReversalStopsDeadAsInARasterScan) {
  // Back and forth over 10 mm: each stroke from rest to rest (MINIMUM_JUNCTION_SPEED 0).
  std::vector<PlannedMove> moves;
  for (int i = 0; i < 10; ++i) moves.push_back(line(i % 2 == 0 ? 10 : 0, 0, 6000));
  const auto s = move_seconds(moves, settings_500());
  // 10 mm from rest to rest with 500 mm/s^2 never reaches 100 mm/s: 2*sqrt(10/500) s.
  for (double t : s) EXPECT_NEAR(t, 2 * std::sqrt(10.0 / 500), 1e-9);
}

TEST(MotionPlanner, ManyShortMovesAreLimitedByTheFifteenBlockLookAhead) {
  // 1000 moves of 0.1 mm: a move's exit must allow stopping within the 14 after it, so the
  // head tops out near sqrt(2 * 500 * 1.4) = 37.4 mm/s, not 100 mm/s.
  std::vector<PlannedMove> moves;
  for (int i = 1; i <= 1000; ++i) moves.push_back(line(i * 0.1, 0, 6000));
  const double with_15 = total(move_seconds(moves, settings_500()));
  MotionSettings deep = settings_500();
  deep.planner_blocks = 2000;
  const double unbounded = total(move_seconds(moves, deep));
  EXPECT_NEAR(unbounded, 1.2, 1e-6);
  EXPECT_GT(with_15, 100 / 37.5);
  EXPECT_LT(with_15, 100 / 37.4 + 0.2);
}

TEST(MotionPlanner, ARapidRunsAtTheAxesLimitAlongItsDirection) {
  MotionSettings s = settings_500();
  s.max_rate_mm_min = {6000, 3000, 500};
  s.accel_mm_s2 = {1e9, 1e9, 1e9};  // (practically) no ramps: the rate alone
  // Diagonal: X may go 100 mm/s / 0.7071, Y only 50 / 0.7071 = 70.7 mm/s along the move.
  const auto t = move_seconds({PlannedMove{{100, 100, 0}, 0, true, false}}, s);
  EXPECT_NEAR(t[0], std::hypot(100, 100) / 70.710678, 1e-4);
}

TEST(MotionPlanner, ABufferSyncMakesTheMoveBeforeItStop) {
  std::vector<PlannedMove> moves{line(50, 0, 6000), line(100, 0, 6000)};
  moves[1].from_rest = true;  // e.g. an M5 between them
  const auto p = plan_moves(moves, settings_500());
  EXPECT_EQ(p[0].exit_mm_min, 0);
  EXPECT_EQ(p[1].entry_mm_min, 0);
  EXPECT_NEAR(p[0].seconds, 0.2 + 0.3 + 0.2, 1e-9);
}

TEST(MotionPlanner, AMoveWithoutStepsIsDropped) {
  const auto p = plan_moves({line(0.001, 0, 6000), line(10, 0, 600)}, settings_500());
  EXPECT_EQ(p[0].seconds, 0);  // 0.001 mm is 0.08 steps at 80 steps/mm
  EXPECT_GT(p[1].seconds, 1.0);
}

TEST(MotionPlanner, TheProfileGivesSpeedAndDistanceAlongTheMove) {
  const MoveProfile p = trapezoid(100, 0, 6000, 0, 500);
  EXPECT_NEAR(p.seconds, 1.2, 1e-9);
  EXPECT_NEAR(p.distance_at(0.2), 10, 1e-9);
  EXPECT_NEAR(p.speed_at(0.1), 3000, 1e-6);
  EXPECT_NEAR(p.speed_at(0.6), 6000, 1e-6);
  EXPECT_NEAR(p.distance_at(0.6), 50, 1e-9);
  EXPECT_NEAR(p.distance_at(1.2), 100, 1e-9);
  double last = 0;
  for (double t = 0; t <= 1.2; t += 0.01) {
    EXPECT_GE(p.distance_at(t), last - 1e-12);
    last = p.distance_at(t);
  }
}

TEST(MotionPlanner, SettingsComeFromTheControllersDollarValues) {
  const MotionSettings s = motion_settings_from({{11, 0.02}, {110, 8000}, {121, 300}, {100, 0}});
  EXPECT_EQ(s.junction_deviation_mm, 0.02);
  EXPECT_EQ(s.max_rate_mm_min[0], 8000);
  EXPECT_EQ(s.accel_mm_s2[1], 300);
  EXPECT_EQ(s.steps_per_mm[0], 250);  // a non-positive value keeps the default
}

}  // namespace
}  // namespace atelier::laser

// Fabricability of one veneer piece (issue 5): what a user is told before a piece is cut.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "algorithms/parquetry/fabricability.h"

namespace atelier::parquetry {
namespace {

using ::testing::HasSubstr;

std::vector<cv::Point2d> rect(double x, double y, double w, double h) {
  return {{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}};
}

// An L: a 14 x 6 mm foot with an arm `arm` mm wide and 8 mm tall rising from its left end.
std::vector<cv::Point2d> ell(double arm) {
  return {{0, 0}, {arm, 0}, {arm, 8}, {14, 8}, {14, 14}, {0, 14}};
}

// The number just before " mm" after `after` in `text` (e.g. "sliver 1.0 mm thin").
double number_after(const std::string& text, const std::string& after) {
  const std::size_t at = text.find(after);
  if (at == std::string::npos) return NAN;
  return std::stod(text.substr(at + after.size()));
}

TEST(ParquetryFabricability, AFourteenMillimetreSquarePasses) {
  EXPECT_EQ(fabricability_problem(rect(3, 7, 14, 14), 5, 2), std::nullopt);
  // Either orientation.
  auto ccw = rect(3, 7, 14, 14);
  std::reverse(ccw.begin(), ccw.end());
  EXPECT_EQ(fabricability_problem(ccw, 5, 2), std::nullopt);
}

TEST(ParquetryFabricability, AFourMillimetreSquareIsTooSmallAcross) {
  const auto problem = fabricability_problem(rect(0, 0, 4, 4), 5, 2);
  ASSERT_TRUE(problem.has_value());
  EXPECT_THAT(*problem, HasSubstr("mm across, below the 5 mm minimum"));
  EXPECT_NEAR(number_after(*problem, "is "), 4.0, 0.11) << *problem;
  // A 4 x 30 strip is as narrow: across is the inscribed circle, not the length.
  const auto strip = fabricability_problem(rect(0, 0, 30, 4), 5, 2);
  ASSERT_TRUE(strip.has_value());
  EXPECT_NEAR(number_after(*strip, "is "), 4.0, 0.11) << *strip;
  // 5.5 mm passes the 5 mm minimum.
  EXPECT_EQ(fabricability_problem(rect(0, 0, 5.5, 5.5), 5, 2), std::nullopt);
}

TEST(ParquetryFabricability, AThinArmIsASliverAndAThickOneIsNot) {
  const auto thin = fabricability_problem(ell(1.0), 5, 2);
  ASSERT_TRUE(thin.has_value());
  EXPECT_THAT(*thin, HasSubstr("has a sliver"));
  EXPECT_THAT(*thin, HasSubstr("(minimum 2 mm)"));
  EXPECT_NEAR(number_after(*thin, "sliver "), 1.0, 0.15) << *thin;
  EXPECT_EQ(fabricability_problem(ell(3.0), 5, 2), std::nullopt);
  // The same 3 mm arm is a sliver when features must be 4 mm.
  const auto strict = fabricability_problem(ell(3.0), 5, 4);
  ASSERT_TRUE(strict.has_value());
  EXPECT_NEAR(number_after(*strict, "sliver "), 3.0, 0.15) << *strict;
}

TEST(ParquetryFabricability, ABowTieCrossesItself) {
  const std::vector<cv::Point2d> bow_tie{{0, 0}, {14, 14}, {14, 0}, {0, 14}};
  EXPECT_EQ(fabricability_problem(bow_tie, 5, 2), std::optional<std::string>("crosses itself"));
}

// Two 10 mm squares 2 mm apart joined by a neck `neck` mm wide.
std::vector<cv::Point2d> dumbbell(double neck) {
  const double a = 5 - neck / 2, b = 5 + neck / 2;
  return {{0, 0}, {10, 0}, {10, a}, {12, a}, {12, 0}, {22, 0},
          {22, 10}, {12, 10}, {12, b}, {10, b}, {10, 10}, {0, 10}};
}

TEST(ParquetryFabricability, TwoSquaresJoinedByANeckFallApart) {
  // 0.01 mm: no laser leaves that standing.
  const auto hair = fabricability_problem(dumbbell(0.01), 5, 2);
  ASSERT_TRUE(hair.has_value());
  EXPECT_THAT(*hair, HasSubstr("falls apart into 2 parts"));
  // 1 mm: holds on the sheet, breaks in the sanding.
  EXPECT_EQ(fabricability_problem(dumbbell(1.0), 5, 2),
            std::optional<std::string>("falls apart into 2 parts joined by a neck thinner than 2 mm"));
  // 3 mm: one piece.
  EXPECT_EQ(fabricability_problem(dumbbell(3.0), 5, 2), std::nullopt);
}

TEST(ParquetryFabricability, AWavyEdgedCellPasses) {
  // A 14 mm cell whose edges wiggle 1 mm either side twice along each side (as the sides of a
  // morphed grid cell do), flat where they meet at the corners.
  auto wave = [](double t) {
    const double s = std::sin(CV_PI * t / 14);
    return 1.0 * std::sin(2 * CV_PI * t / 7) * s * s;
  };
  std::vector<cv::Point2d> cell;
  const int n = 56;
  for (int k = 0; k < n; ++k) cell.push_back({14.0 * k / n, wave(14.0 * k / n)});
  for (int k = 0; k < n; ++k) cell.push_back({14 + wave(14.0 * k / n), 14.0 * k / n});
  for (int k = n; k > 0; --k) cell.push_back({14.0 * k / n, 14 + wave(14.0 * k / n)});
  for (int k = n; k > 0; --k) cell.push_back({wave(14.0 * k / n), 14.0 * k / n});
  EXPECT_EQ(fabricability_problem(cell, 5, 2), std::nullopt);
}

TEST(ParquetryFabricability, DegenerateOutlinesAreNamed) {
  EXPECT_EQ(fabricability_problem({{0, 0}, {10, 0}}, 5, 2), std::optional<std::string>("has no area"));
  EXPECT_EQ(fabricability_problem({{0, 0}, {10, 0}, {20, 0}}, 5, 2), std::optional<std::string>("has no area"));
  EXPECT_THROW(fabricability_problem(rect(0, 0, 14, 14), -1, 2), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::parquetry

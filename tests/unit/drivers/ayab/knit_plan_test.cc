// Needle placement, knitting modes and row order of the AYAB knit plan (drivers/ayab/knit_plan.h).
#include <gtest/gtest.h>

#include "drivers/ayab/knit_plan.h"

namespace atelier::ayab {
namespace {

// A pattern whose row r has contrast stitches at columns r and r + 3 (mod width).
cv::Mat diagonal(int rows, int cols) {
  cv::Mat m(rows, cols, CV_8UC1, cv::Scalar(0));
  for (int r = 0; r < rows; ++r) {
    m.at<uint8_t>(r, r % cols) = 1;
    m.at<uint8_t>(r, (r + 3) % cols) = 1;
  }
  return m;
}

std::vector<int> selected(const Bytes& d) {
  std::vector<int> out;
  for (int n = 0; n < static_cast<int>(d.size()) * 8; ++n)
    if (needle_selected(d, n)) out.push_back(n);
  return out;
}

TEST(AyabKnitPlan, CentresThePatternOnTheBed) {
  const KnitPlan p = plan_knitting(diagonal(4, 40), {});
  EXPECT_EQ(p.start_needle, 80);
  EXPECT_EQ(p.stop_needle, 119);
  PlanParams kh270;
  kh270.machine = MachineType::kh270;
  const KnitPlan q = plan_knitting(diagonal(4, 41), kh270);
  EXPECT_EQ(q.start_needle, 35);  // (112 - 41) / 2
  EXPECT_EQ(q.stop_needle, 75);
  ASSERT_FALSE(q.passes.empty());
  EXPECT_EQ(q.passes[0].size(), 14u);
}

TEST(AyabKnitPlan, StartNeedleOverridesCentring) {
  PlanParams params;
  params.start_needle = 5;
  const KnitPlan p = plan_knitting(diagonal(2, 40), params);
  EXPECT_EQ(p.start_needle, 5);
  EXPECT_EQ(p.stop_needle, 44);
  params.start_needle = 161;  // 161 + 40 = 201 > 200
  try {
    plan_knitting(diagonal(2, 40), params);
    FAIL() << "expected PlanError";
  } catch (const PlanError& e) {
    EXPECT_NE(std::string(e.what()).find("starts at needle 161"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("200 needles"), std::string::npos) << e.what();
  }
}

TEST(AyabKnitPlan, TooWideNamesBothWidths) {
  try {
    plan_knitting(diagonal(2, 230), {});
    FAIL() << "expected PlanError";
  } catch (const PlanError& e) {
    EXPECT_STREQ(e.what(), "pattern is 230 stitches wide but the KH-930 has 200 needles");
  }
  PlanParams kh270;
  kh270.machine = MachineType::kh270;
  try {
    plan_knitting(diagonal(2, 113), kh270);
    FAIL() << "expected PlanError";
  } catch (const PlanError& e) {
    EXPECT_STREQ(e.what(), "pattern is 113 stitches wide but the KH-270 has 112 needles");
  }
  EXPECT_NO_THROW(plan_knitting(diagonal(2, 112), kh270));
  EXPECT_NO_THROW(plan_knitting(diagonal(2, 200), {}));
}

TEST(AyabKnitPlan, SingleBedSelectsContrastNeedlesColumnByColumn) {
  const cv::Mat pat = diagonal(5, 40);
  const KnitPlan p = plan_knitting(pat, {});
  ASSERT_EQ(p.passes.size(), 5u);
  EXPECT_EQ(p.passes_per_row, 1);
  for (int i = 0; i < 5; ++i) {
    const int r = 4 - i;  // bottom row first (AyabKnitPlan.TheBottomRowIsKnittedFirst...)
    EXPECT_EQ(p.pattern_row[i], r);
    ASSERT_EQ(p.passes[i].size(), 25u);
    // needle = start + column; needle n is bit (n & 7) of byte (n >> 3)
    std::vector<int> want = {80 + r, 80 + r + 3};
    EXPECT_EQ(selected(p.passes[i]), want) << "row " << r;
    const int n = 80 + r;
    EXPECT_TRUE((p.passes[i][n >> 3] >> (n & 7)) & 1);
  }
}

TEST(AyabKnitPlan, MirrorPutsColumnZeroOnTheRightmostNeedle) {
  cv::Mat pat(1, 10, CV_8UC1, cv::Scalar(0));
  pat.at<uint8_t>(0, 0) = 1;
  PlanParams params;
  params.start_needle = 20;
  params.mirror = true;
  const KnitPlan p = plan_knitting(pat, params);
  EXPECT_EQ(selected(p.passes[0]), std::vector<int>{29});
  params.mirror = false;
  EXPECT_EQ(selected(plan_knitting(pat, params).passes[0]), std::vector<int>{20});
}

// As AYAB desktop (engine.py: "start to knit with the bottom first"): the cast-on edge is the
// bottom of the picture, so the fabric, cast-on edge down, is the picture upright.
TEST(AyabKnitPlan, TheBottomRowIsKnittedFirstByDefault) {
  // An asymmetric pattern: row r selects only column r, so every row is different.
  cv::Mat pat(4, 10, CV_8UC1, cv::Scalar(0));
  for (int r = 0; r < 4; ++r) pat.at<uint8_t>(r, r) = 1;
  PlanParams params;
  params.start_needle = 0;
  const KnitPlan p = plan_knitting(pat, params);
  ASSERT_EQ(p.passes.size(), 4u);
  EXPECT_EQ(p.pattern_row, (std::vector<int>{3, 2, 1, 0}));
  EXPECT_EQ(selected(p.passes[0]), std::vector<int>{3});  // pattern.png's bottom row
  EXPECT_EQ(selected(p.passes[3]), std::vector<int>{0});  // its top row, knitted last
}

TEST(AyabKnitPlan, FirstRowTopKnitsPatternRowZeroFirst) {
  const cv::Mat pat = diagonal(6, 30);
  PlanParams params;
  params.first_row_top = true;
  const KnitPlan top = plan_knitting(pat, params);
  const KnitPlan bottom = plan_knitting(pat, {});
  ASSERT_EQ(top.passes.size(), 6u);
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(top.pattern_row[i], i);
    EXPECT_EQ(top.passes[i], bottom.passes[5 - i]);
  }
}

TEST(AyabKnitPlan, ClassicRibberColourOrderFollowsTheKnittedRowsBottomFirst) {
  cv::Mat pat(3, 4, CV_8UC1, cv::Scalar(0));
  pat.at<uint8_t>(2, 3) = 1;  // the bottom row, knitted first
  PlanParams params;
  params.mode = KnitMode::classic_ribber;
  params.start_needle = 0;
  const KnitPlan p = plan_knitting(pat, params);
  EXPECT_EQ(p.pattern_row, (std::vector<int>{2, 2, 1, 1, 0, 0}));
  EXPECT_EQ(p.colour, (std::vector<uint8_t>{0, 1, 1, 0, 0, 1}));  // A B, B A, A B as knitted
  EXPECT_EQ(selected(p.passes[0]), (std::vector<int>{0, 1, 2}));  // bottom row, background
  EXPECT_EQ(selected(p.passes[1]), (std::vector<int>{3}));        // bottom row, contrast
}

TEST(AyabKnitPlan, ClassicRibberPassesABThenBA) {
  cv::Mat pat(3, 4, CV_8UC1, cv::Scalar(0));
  pat.at<uint8_t>(0, 1) = 1;
  pat.at<uint8_t>(1, 2) = 1;
  pat.at<uint8_t>(2, 3) = 1;
  PlanParams params;
  params.mode = KnitMode::classic_ribber;
  params.start_needle = 0;
  params.first_row_top = true;  // pattern rows in the order 0, 1, 2
  const KnitPlan p = plan_knitting(pat, params);
  EXPECT_EQ(p.passes_per_row, 2);
  ASSERT_EQ(p.passes.size(), 6u);
  EXPECT_EQ(p.colour, (std::vector<uint8_t>{0, 1, 1, 0, 0, 1}));
  EXPECT_EQ(p.pattern_row, (std::vector<int>{0, 0, 1, 1, 2, 2}));
  // Pass for colour k selects the needles whose stitch has colour k.
  EXPECT_EQ(selected(p.passes[0]), (std::vector<int>{0, 2, 3}));  // row 0, background
  EXPECT_EQ(selected(p.passes[1]), (std::vector<int>{1}));        // row 0, contrast
  EXPECT_EQ(selected(p.passes[2]), (std::vector<int>{2}));        // row 1, contrast first
  EXPECT_EQ(selected(p.passes[3]), (std::vector<int>{0, 1, 3}));  // row 1, background
}

TEST(AyabKnitPlan, CircularAlternatesWithBlankPasses) {
  cv::Mat pat(1, 4, CV_8UC1, cv::Scalar(0));
  pat.at<uint8_t>(0, 0) = 1;
  PlanParams params;
  params.mode = KnitMode::circular;
  params.start_needle = 10;
  const KnitPlan p = plan_knitting(pat, params);
  ASSERT_EQ(p.passes.size(), 4u);
  EXPECT_EQ(selected(p.passes[0]), (std::vector<int>{11, 12, 13}));
  EXPECT_TRUE(selected(p.passes[1]).empty());
  EXPECT_EQ(selected(p.passes[2]), std::vector<int>{10});
  EXPECT_TRUE(selected(p.passes[3]).empty());
}

TEST(AyabKnitPlan, ModeNames) {
  EXPECT_EQ(knit_mode_from_name("single-bed"), KnitMode::single_bed);
  EXPECT_EQ(knit_mode_from_name("classic-ribber"), KnitMode::classic_ribber);
  EXPECT_EQ(knit_mode_from_name("circular"), KnitMode::circular);
  EXPECT_FALSE(knit_mode_from_name("heart-of-pluto"));
  EXPECT_EQ(knit_mode_name(KnitMode::classic_ribber), "classic-ribber");
}

}  // namespace
}  // namespace atelier::ayab

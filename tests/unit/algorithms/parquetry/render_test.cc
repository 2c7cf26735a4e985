// The parquetry preview (algorithms/parquetry/render.h): each piece shows the wood under its
// source outline, turned as the plan says, with dark joints.
#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/core.hpp>

#include "algorithms/parquetry/render.h"

namespace atelier {
namespace {

// The preview takes each piece's wood from under its source outline: a 10 mm piece whose
// source is a red square on a grey sheet comes out red, turned as the plan says.
TEST(ParquetryRenderTest, EachPieceShowsTheWoodUnderItsSourceOutline) {
  parquetry::Sheet sheet;
  sheet.id = "s";
  sheet.dpi = 25.4;  // 1 px = 1 mm
  sheet.image = cv::Mat(100, 100, CV_8UC3, cv::Scalar(128, 128, 128));
  sheet.image(cv::Rect(20, 30, 10, 10)).setTo(cv::Scalar(0, 0, 255));   // red at (20..30, 30..40)
  sheet.image(cv::Rect(60, 10, 10, 5)).setTo(cv::Scalar(255, 0, 0));   // blue, 10 wide 5 high
  parquetry::Plan plan;
  plan.width_mm = 20;
  plan.height_mm = 10;
  auto piece = [](int id, double x0, const cv::Matx23d& to_sheet) {
    parquetry::Piece p;
    p.id = id;
    p.sheet_id = "s";
    p.target_mm = {{x0, 0}, {x0 + 10, 0}, {x0 + 10, 10}, {x0, 10}};
    p.to_sheet = to_sheet;
    return p;
  };
  plan.pieces.push_back(piece(1, 0, {1, 0, 20, 0, 1, 30}));  // shifted onto the red square
  // Turned 90 degrees, (x, y) -> (70 - y, x): the blue block (sheet x 60..70, y 10..15)
  // lands on result x 10..15 over the piece's whole height; unturned it would be a
  // horizontal strip.
  plan.pieces.push_back(piece(2, 10, {0, -1, 70, 1, 0, 0}));
  cv::Mat img = parquetry::render_plan(plan, {sheet});
  ASSERT_EQ(img.size(), cv::Size(80, 40));                    // 4 px/mm
  EXPECT_EQ(img.at<cv::Vec3b>(20, 20), cv::Vec3b(0, 0, 255));  // piece 1's middle: red
  EXPECT_EQ(img.at<cv::Vec3b>(8, 50), cv::Vec3b(255, 0, 0));   // piece 2, x 12.5, y 2: blue
  EXPECT_EQ(img.at<cv::Vec3b>(32, 50), cv::Vec3b(255, 0, 0));  // x 12.5, y 8: blue
  EXPECT_EQ(img.at<cv::Vec3b>(20, 70), cv::Vec3b(128, 128, 128));  // x 17.5: grey
  // Joints: the outline between the pieces is dark.
  int darkest = 255;
  for (int x = 38; x <= 42; ++x) darkest = std::min<int>(darkest, img.at<cv::Vec3b>(20, x)[2]);
  EXPECT_LT(darkest, 80);
  EXPECT_DOUBLE_EQ(parquetry::render_px_per_mm(plan, {}), 4);
  parquetry::RenderOptions capped;
  capped.max_px = 40;
  EXPECT_DOUBLE_EQ(parquetry::render_px_per_mm(plan, capped), 2);
}

}  // namespace
}  // namespace atelier

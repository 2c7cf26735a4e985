// Veneer sheets at the working resolution (algorithms/parquetry/sheet.h).
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "algorithms/parquetry/sheet.h"

namespace atelier::parquetry {
namespace {

TEST(ParquetrySheet, WorkingPixelsAreExactlyOneOverPxPerMmOfTheScan) {
  // 161 px at 25.4 dpi: 161 mm. At 0.5 px/mm: 80 whole pixels (the last half pixel would
  // hang off the sheet), and a mark at 100-102 mm lands on pixel 50, not stretched to 80.5.
  Sheet s;
  s.id = "x";
  s.dpi = 25.4;
  s.image = cv::Mat(20, 161, CV_8UC3, cv::Scalar(0, 0, 0));
  s.image.colRange(100, 102).setTo(cv::Scalar(255, 255, 255));
  EXPECT_EQ(sheet_size_px(s, 0.5), cv::Size(80, 10));
  const cv::Mat at = resample_sheet(s.image, s, 0.5);
  ASSERT_EQ(at.size(), cv::Size(80, 10));
  cv::Mat grey;
  cv::cvtColor(at, grey, cv::COLOR_BGR2GRAY);
  cv::Point brightest;
  cv::minMaxLoc(grey.row(5), nullptr, nullptr, nullptr, &brightest);
  EXPECT_EQ(brightest.x, 50);
  EXPECT_GT(grey.at<uchar>(5, 50), 200);
}

}  // namespace
}  // namespace atelier::parquetry

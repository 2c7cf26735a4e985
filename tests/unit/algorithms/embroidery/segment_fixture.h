// Helpers shared by the segment and colour tests: test images and drawings segmented with the
// default parameters.
#pragma once

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <string>

#include "algorithms/embroidery/segment.h"

namespace atelier::embroidery::test {

inline cv::Mat load(const std::string& name, int flags = cv::IMREAD_COLOR) {
  cv::Mat m = cv::imread(std::string(ATELIER_TEST_DATA) + "/" + name, flags);
  EXPECT_FALSE(m.empty()) << name;
  return m;
}

// A drawing: black shapes on a white sheet, as in the issue (eW 4 px, sW 24 px).
inline Segmentation segment_drawing(const cv::Mat1b& shape) {
  cv::Mat3b img(shape.size(), cv::Vec3b(255, 255, 255));
  img.setTo(cv::Vec3b(0, 0, 0), shape);
  return segment(img, ColorParams{}, LabelParams{});
}

}  // namespace atelier::embroidery::test

// Helpers shared by the stroke and hatching tests: test images, segment lengths.
#pragma once

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <string>

#include "algorithms/pencil/strokes.h"

namespace atelier::pencil::testing {

inline cv::Mat load(const std::string& name) {
  cv::Mat image = cv::imread(std::string(ATELIER_TEST_DATA) + "/" + name, cv::IMREAD_UNCHANGED);
  EXPECT_FALSE(image.empty()) << name;
  return image;
}

inline double length(const Segment& s) { return cv::norm(s.to - s.from); }

}  // namespace atelier::pencil::testing

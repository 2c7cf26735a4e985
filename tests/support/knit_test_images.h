// Test helper for the knit tests: loads the real images in tests/data (test-only I/O; the
// knit library itself never reads files).
#pragma once

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <string>

namespace atelier::knit::testing {

inline cv::Mat load_test_image(const std::string& name, int flags = cv::IMREAD_UNCHANGED) {
  const std::string path = std::string(ATELIER_TEST_DATA) + "/" + name;
  cv::Mat image = cv::imread(path, flags);
  if (image.empty()) ADD_FAILURE() << "cannot read test image " << path;
  return image;
}

}  // namespace atelier::knit::testing

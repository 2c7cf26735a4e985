// Test helper shared by the similarity and preview tests: a random 0/1 stitch grid.
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>

namespace atelier::knit::testing {

inline cv::Mat random_grid(cv::Size size, uint64_t seed) {
  cv::Mat g(size, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(g, cv::RNG::UNIFORM, 0, 2);
  return g;
}

}  // namespace atelier::knit::testing

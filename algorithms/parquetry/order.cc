#include "algorithms/parquetry/order.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/saliency.hpp>
#include <random>
#include <stdexcept>

namespace atelier::parquetry {

std::vector<double> patch_priority(const cv::Mat& target, int cols, int rows, int patch,
                                   Order order) {
  std::vector<double> priority(static_cast<std::size_t>(cols) * rows);
  if (order == Order::saliency) {
    cv::Ptr<cv::saliency::StaticSaliencyFineGrained> method =
        cv::saliency::StaticSaliencyFineGrained::create();
    cv::Mat map;
    if (!method->computeSaliency(target, map)) {
      throw std::runtime_error("parquetry: the saliency map could not be computed");
    }
    cv::Mat map32;
    map.convertTo(map32, CV_64F);
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        priority[r * cols + c] =
            -cv::mean(map32(cv::Rect(c * patch, r * patch, patch, patch)))[0] * (map.depth() == CV_8U ? 1.0 : 255.0);
      }
    }
  } else {
    const double cx = cols / 2.0, cy = rows / 2.0;
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        priority[r * cols + c] = std::hypot(c + 0.5 - cx, r + 0.5 - cy) / std::hypot(cx, cy);
      }
    }
  }
  return priority;
}

std::vector<int> patch_order(const cv::Mat& target, int cols, int rows, int patch, Order order,
                             std::uint64_t seed) {
  const std::vector<double> priority = patch_priority(target, cols, rows, patch, order);
  std::vector<int> cells(priority.size());
  std::iota(cells.begin(), cells.end(), 0);
  std::mt19937_64 rng(seed);
  std::shuffle(cells.begin(), cells.end(), rng);
  std::stable_sort(cells.begin(), cells.end(),
                   [&](int a, int b) { return priority[a] < priority[b]; });
  return cells;
}

}  // namespace atelier::parquetry

#include "algorithms/knit/stitch_grid.h"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

namespace atelier::knit {

cv::Mat to_gray(const cv::Mat& image) {
  if (image.empty()) throw std::invalid_argument("to_gray: the image is empty");
  if (image.depth() != CV_8U)
    throw std::invalid_argument("to_gray: the image must be 8-bit per channel");
  cv::Mat gray;
  switch (image.channels()) {
    case 1:
      return image.clone();
    case 3:
      cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
      return gray;
    case 4: {
      // Grey conversion is linear and white stays white, so compositing the grey on white
      // equals the grey of the colour composited on white.
      cv::cvtColor(image, gray, cv::COLOR_BGRA2GRAY);
      cv::Mat alpha, g, a;
      cv::extractChannel(image, alpha, 3);
      gray.convertTo(g, CV_32F);
      alpha.convertTo(a, CV_32F, 1.0 / 255.0);
      cv::Mat composed = g.mul(a) + (1.0 - a) * 255.0;
      composed.convertTo(gray, CV_8U);  // rounds and saturates
      return gray;
    }
    default:
      throw std::invalid_argument("to_gray: the image must have 1, 3 or 4 channels, it has " +
                                  std::to_string(image.channels()));
  }
}

namespace {

void check_params(const GaugeParams& params) {
  if (params.width < 1)
    throw std::invalid_argument("to_stitch_grid: width must be at least 1 stitch, got " +
                                std::to_string(params.width));
  if (!(params.stitches_per_10cm > 0) || !std::isfinite(params.stitches_per_10cm))
    throw std::invalid_argument("to_stitch_grid: stitches_per_10cm must be a positive number");
  if (!(params.rows_per_10cm > 0) || !std::isfinite(params.rows_per_10cm))
    throw std::invalid_argument("to_stitch_grid: rows_per_10cm must be a positive number");
}

}  // namespace

long stitch_rows(long picture_w, long picture_h, const GaugeParams& params) {
  check_params(params);
  if (picture_w <= 0 || picture_h <= 0) return 0;
  const bool vertical = params.orientation == Orientation::vertical;
  const double across = static_cast<double>(vertical ? picture_h : picture_w);
  const double down = static_cast<double>(vertical ? picture_w : picture_h);
  // Stitches are wider than tall when rows_per_10cm > stitches_per_10cm: more rows are
  // needed for the same picture height.
  return std::lround(params.width * down / across * params.rows_per_10cm / params.stitches_per_10cm);
}

cv::Mat to_stitch_grid(const cv::Mat& image, const GaugeParams& params) {
  check_params(params);
  cv::Mat gray = to_gray(image);
  if (params.orientation == Orientation::vertical) {
    cv::Mat rotated;
    cv::rotate(gray, rotated, cv::ROTATE_90_CLOCKWISE);
    gray = rotated;
  }
  const long rows = stitch_rows(image.cols, image.rows, params);
  if (rows < 1)
    throw std::invalid_argument("to_stitch_grid: the picture is too flat for " +
                                std::to_string(params.width) + " stitches (0 rows)");
  if (rows > kMaxRows)
    throw std::invalid_argument("to_stitch_grid: the pattern would have " + std::to_string(rows) +
                                " rows, more than the limit of " + std::to_string(kMaxRows) +
                                "; lower the width or check the gauge");
  const cv::Size size(params.width, static_cast<int>(rows));
  const bool shrinking = size.width <= gray.cols && size.height <= gray.rows;
  cv::Mat grid;
  cv::resize(gray, grid, size, 0, 0, shrinking ? cv::INTER_AREA : cv::INTER_LINEAR);
  return grid;
}

}  // namespace atelier::knit

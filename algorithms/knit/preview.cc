#include "algorithms/knit/preview.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace atelier::knit {
namespace {

cv::Scalar scaled(const cv::Vec3b& c, double k) {
  return cv::Scalar(std::min(255.0, c[0] * k), std::min(255.0, c[1] * k), std::min(255.0, c[2] * k));
}

// One stitch of one yarn: two slanted legs meeting at the bottom centre (the knit "V"),
// each shaded light at its outer top and dark along its inner edge, on a darker gap colour
// that shows between the legs and between neighbouring stitches.
cv::Mat stitch_tile(const cv::Vec3b& yarn, int w, int h) {
  // Drawn at 4x and shrunk with area averaging for smooth edges at any stitch size.
  const int s = 4, W = w * s, H = h * s;
  cv::Mat big(H, W, CV_8UC3, scaled(yarn, 0.55));
  for (int side = 0; side < 2; ++side) {
    const double sign = side == 0 ? -1.0 : 1.0;
    const cv::Point2d top(W / 2.0 + sign * W * 0.27, H * 0.05), bottom(W / 2.0, H * 0.98);
    const cv::Point2d dir = bottom - top;
    const double len = std::hypot(dir.x, dir.y);
    const double angle = std::atan2(dir.y, dir.x) * 180.0 / CV_PI;
    const cv::Point2d mid = (top + bottom) * 0.5;
    const auto at = [](const cv::Point2d& p) { return cv::Point(cvRound(p.x), cvRound(p.y)); };
    // Body of the leg in the yarn colour, then a thinner highlight shifted to its outer side.
    cv::ellipse(big, at(mid), cv::Size(cvRound(len * 0.56), cvRound(W * 0.2)), angle, 0, 360,
                scaled(yarn, 0.85), cv::FILLED, cv::LINE_AA);
    const cv::Point2d outer(sign * W * 0.04, -H * 0.03);
    cv::ellipse(big, at(mid + outer), cv::Size(cvRound(len * 0.46), cvRound(W * 0.12)), angle, 0,
                360, scaled(yarn, 1.0), cv::FILLED, cv::LINE_AA);
    cv::ellipse(big, at(mid + outer * 1.6), cv::Size(cvRound(len * 0.3), cvRound(W * 0.05)), angle,
                0, 360, scaled(yarn, 1.18), cv::FILLED, cv::LINE_AA);
  }
  cv::GaussianBlur(big, big, cv::Size(), s * 0.5);
  cv::Mat tile;
  cv::resize(big, tile, cv::Size(w, h), 0, 0, cv::INTER_AREA);
  return tile;
}

}  // namespace

cv::Mat render_preview(const cv::Mat& grid, const PreviewStyle& style) {
  if (grid.empty() || grid.type() != CV_8UC1)
    throw std::invalid_argument("render_preview: the grid must be a non-empty CV_8UC1 image");
  if (style.stitch_px < 1)
    throw std::invalid_argument("render_preview: stitch_px must be at least 1");
  if (!(style.stitch_aspect > 0) || !std::isfinite(style.stitch_aspect))
    throw std::invalid_argument("render_preview: stitch_aspect must be a positive number");
  const int w = style.stitch_px;
  const int h = std::max(1, static_cast<int>(std::lround(w * style.stitch_aspect)));
  const cv::Mat tiles[2] = {stitch_tile(style.background, w, h), stitch_tile(style.contrast, w, h)};
  cv::Mat out(grid.rows * h, grid.cols * w, CV_8UC3);
  for (int y = 0; y < grid.rows; ++y) {
    const uint8_t* g = grid.ptr<uint8_t>(y);
    for (int x = 0; x < grid.cols; ++x)
      tiles[g[x] != 0 ? 1 : 0].copyTo(out(cv::Rect(x * w, y * h, w, h)));
  }
  return out;
}

}  // namespace atelier::knit

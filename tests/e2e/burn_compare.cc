#include "tests/e2e/burn_compare.h"

#include <opencv2/imgproc.hpp>
#include <vector>

#include "convert/common/svg_paths.h"

namespace atelier::test {

void draw_strokes(const std::filesystem::path& svg, double px_per_mm, cv::Mat& mask) {
  const auto drawing = atelier::read_svg(svg, 0.05);
  for (const auto& shape : drawing.shapes) {
    if (shape.stroke.empty()) continue;
    for (const auto& path : shape.paths) {
      std::vector<cv::Point> pts;
      for (const auto& p : path.points) pts.emplace_back(cvRound(p.x * px_per_mm), cvRound(p.y * px_per_mm));
      cv::polylines(mask, pts, path.closed, cv::Scalar(255), 1);
    }
  }
}

double covered(const cv::Mat& a, const cv::Mat& b, int tolerance_px) {
  cv::Mat near;
  cv::dilate(b, near, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * tolerance_px + 1, 2 * tolerance_px + 1}));
  const double total = cv::countNonZero(a);
  return total == 0 ? 0 : cv::countNonZero(a & near) / total;
}

}  // namespace atelier::test

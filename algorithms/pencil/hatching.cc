#include "algorithms/pencil/hatching.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

namespace atelier::pencil {

namespace {

constexpr double kSampleStep = 0.25;  // px along a hatch line: fine enough not to skip a pixel

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

void validate(const HatchParams& p) {
  require(std::isfinite(p.dark_level) && p.dark_level >= 0 && p.dark_level <= 1, "dark_level must be in [0, 1]");
  require(std::isfinite(p.cross_level) && p.cross_level >= 0 && p.cross_level <= p.dark_level,
          "cross_level must be in [0, dark_level]");
  require(std::isfinite(p.spacing_px) && p.spacing_px >= 1, "spacing_px must be >= 1");
  require(std::isfinite(p.angle_deg), "angle_deg must be finite");
  require(std::isfinite(p.min_length_px) && p.min_length_px >= 0, "min_length_px must be >= 0");
  require(std::isfinite(p.min_area_px) && p.min_area_px >= 0, "min_area_px must be >= 0");
}

// Pixels of `grey` below `level` (0..1), less the 8-connected regions smaller than min_area.
cv::Mat1b dark_mask(const cv::Mat& grey, double level, double min_area) {
  cv::Mat1b mask = grey < level * 255.0;
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  std::vector<uchar> keep(n, 0);
  for (int i = 1; i < n; ++i) keep[i] = stats.at<int>(i, cv::CC_STAT_AREA) >= min_area;
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x) mask(y, x) = keep[labels.at<int>(y, x)] ? 255 : 0;
  return mask;
}

// One layer: lines at `angle` spaced `spacing` apart, clipped to `mask`.
void hatch_layer(const cv::Mat1b& mask, double angle_deg, const HatchParams& p, std::vector<Segment>& out) {
  const double a = angle_deg * CV_PI / 180.0;
  const cv::Point2d u(std::cos(a), std::sin(a)), n(-std::sin(a), std::cos(a));
  const cv::Point2d corners[] = {{-0.5, -0.5}, {mask.cols - 0.5, -0.5}, {-0.5, mask.rows - 0.5},
                                 {mask.cols - 0.5, mask.rows - 0.5}};
  double cmin = 1e300, cmax = -1e300, tmin = 1e300, tmax = -1e300;
  for (const cv::Point2d& c : corners) {
    cmin = std::min(cmin, c.dot(n)), cmax = std::max(cmax, c.dot(n));
    tmin = std::min(tmin, c.dot(u)), tmax = std::max(tmax, c.dot(u));
  }
  const long samples = static_cast<long>(std::ceil((tmax - tmin) / kSampleStep));
  auto inside = [&](cv::Point2d q) {
    const int x = static_cast<int>(std::lround(q.x)), y = static_cast<int>(std::lround(q.y));
    return x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && mask(y, x) != 0;
  };
  for (long k = static_cast<long>(std::ceil(cmin / p.spacing_px)); k * p.spacing_px <= cmax; ++k) {
    const cv::Point2d base = n * (k * p.spacing_px);
    bool in_run = false;
    cv::Point2d first, last;
    for (long i = 0; i <= samples + 1; ++i) {
      const cv::Point2d q = base + u * (tmin + i * kSampleStep);
      const bool in = i <= samples && inside(q);
      if (in) {
        if (!in_run) first = q;
        last = q, in_run = true;
      } else if (in_run) {
        if (cv::norm(last - first) >= std::max(p.min_length_px, 1e-9)) out.push_back({first, last});
        in_run = false;
      }
    }
  }
}

}  // namespace

std::vector<Segment> hatch_lines(const cv::Mat& image, const HatchParams& params) {
  validate(params);
  const cv::Mat paper = on_white_paper(image);
  std::vector<Segment> out;
  try {
    cv::Mat grey;
    if (paper.channels() == 3)
      cv::cvtColor(paper, grey, cv::COLOR_BGR2GRAY);
    else
      grey = paper;
    cv::GaussianBlur(grey, grey, cv::Size(), params.spacing_px / 4.0, params.spacing_px / 4.0, cv::BORDER_REPLICATE);
    if (params.dark_level > 0) hatch_layer(dark_mask(grey, params.dark_level, params.min_area_px), params.angle_deg,
                                           params, out);
    if (params.cross_level > 0)
      hatch_layer(dark_mask(grey, params.cross_level, params.min_area_px), params.angle_deg + 90, params, out);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(std::string("hatch_lines: OpenCV failed: ") + e.what());
  }
  return out;
}

}  // namespace atelier::pencil

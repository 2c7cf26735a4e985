#include "algorithms/parquetry/fabricability.h"

#include <algorithm>
#include <boost/geometry.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/ring.hpp>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace atelier::parquetry {

namespace {

namespace bg = boost::geometry;
using BPoint = bg::model::d2::point_xy<double>;
using BRing = bg::model::ring<BPoint>;

std::string format(const char* fmt, double a, double b) {
  char buf[128];
  std::snprintf(buf, sizeof buf, fmt, a, b);
  return buf;
}

// The outline's own validity: Boost.Geometry says whether a ring crosses or touches itself.
std::optional<std::string> outline_problem(const std::vector<cv::Point2d>& polygon,
                                           double min_feature_mm) {
  BRing ring;
  for (const cv::Point2d& p : polygon) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return "has invalid coordinates";
    ring.push_back({p.x, p.y});
  }
  bg::correct(ring);  // closes it and fixes the orientation Boost expects
  if (ring.size() < 4) return "has no area";
  bg::validity_failure_type failure = bg::no_failure;
  if (bg::is_valid(ring, failure) && std::abs(bg::area(ring)) > 1e-12) return std::nullopt;
  // A bow-tie can have zero signed area: crossings are named before emptiness.
  if (failure == bg::failure_self_intersections) return "crosses itself";
  if (failure == bg::failure_invalid_coordinate) return "has invalid coordinates";
  if (std::abs(bg::area(ring)) <= 1e-12 || failure == bg::failure_few_points ||
      failure == bg::failure_wrong_topological_dimension) {
    return "has no area";
  }
  if (failure == bg::failure_spikes) {  // the outline runs out and back along itself
    return format("has a sliver %.1f mm thin (minimum %g mm)", 0.0, min_feature_mm);
  }
  return "crosses itself";  // orientation and closure were corrected above
}

// Largest distance from `mask` pixels to the outside, in px, as an inscribed radius: the
// distance transform measures to the nearest outside pixel centre, half a pixel beyond the
// boundary.
double inscribed_radius_px(const cv::Mat& dist, const cv::Mat& where) {
  double hi = 0;
  cv::minMaxLoc(dist, nullptr, &hi, nullptr, nullptr, where);
  return std::max(0.0, hi - 0.5);
}

}  // namespace

std::optional<std::string> fabricability_problem(const std::vector<cv::Point2d>& polygon_mm,
                                                 double min_patch_mm, double min_feature_mm) {
  if (!(min_patch_mm >= 0) || !(min_feature_mm >= 0)) {
    throw std::invalid_argument("fabricability: the minimum sizes must not be negative");
  }
  if (auto problem = outline_problem(polygon_mm, min_feature_mm)) return problem;

  const double ppm = kFabricabilityPxPerMm;
  double lo_x = std::numeric_limits<double>::max(), lo_y = lo_x, hi_x = -lo_x, hi_y = -lo_x;
  for (const cv::Point2d& p : polygon_mm) {
    lo_x = std::min(lo_x, p.x), lo_y = std::min(lo_y, p.y);
    hi_x = std::max(hi_x, p.x), hi_y = std::max(hi_y, p.y);
  }
  if (hi_x - lo_x > 1000 || hi_y - lo_y > 1000) {
    throw std::invalid_argument("fabricability: pieces over 1 m across are not checked");
  }
  const int disc = std::max(1, static_cast<int>(std::lround(min_feature_mm * ppm)) | 1);
  const int margin = disc / 2 + 3;  // the opening and the distance transform see background
  const cv::Size size(static_cast<int>(std::ceil((hi_x - lo_x) * ppm)) + 2 * margin,
                      static_cast<int>(std::ceil((hi_y - lo_y) * ppm)) + 2 * margin);

  try {
    // fillPoly's integer coordinates are pixel centres: -0.5 makes pixel (i, j) the square
    // [i, i+1) x [j, j+1) of the raster. 8 fractional bits keep the outline sub-pixel exact.
    constexpr int kShift = 8;
    std::vector<cv::Point> pts;
    pts.reserve(polygon_mm.size());
    for (const cv::Point2d& p : polygon_mm) {
      pts.emplace_back(static_cast<int>(std::lround(((p.x - lo_x) * ppm + margin - 0.5) * (1 << kShift))),
                       static_cast<int>(std::lround(((p.y - lo_y) * ppm + margin - 0.5) * (1 << kShift))));
    }
    cv::Mat raster = cv::Mat::zeros(size, CV_8UC1);
    cv::fillPoly(raster, std::vector<std::vector<cv::Point>>{pts}, cv::Scalar(255), cv::LINE_8, kShift);

    cv::Mat labels;
    const int parts = cv::connectedComponents(raster, labels, 4, CV_32S) - 1;
    if (parts == 0) return "has no area";
    if (parts > 1) return "falls apart into " + std::to_string(parts) + " parts";

    cv::Mat dist;
    cv::distanceTransform(raster, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
    const double across_mm = 2 * inscribed_radius_px(dist, raster) / ppm;
    if (across_mm < min_patch_mm) {
      return format("is %.1f mm across, below the %g mm minimum", across_mm, min_patch_mm);
    }

    if (min_feature_mm * ppm < 1) return std::nullopt;  // no feature is below one raster pixel
    cv::Mat opened, removed, stats, centroids;
    // Opening by a Euclidean disc through two distance transforms (linear time, where a
    // morphological opening with a 40 px elliptic kernel costs ~kernel width per pixel):
    // erode = centres at least r inside, then everything within r of them.
    const double r = disc / 2.0;
    const cv::Mat outside_eroded = dist < r;
    cv::Mat to_eroded;
    cv::distanceTransform(outside_eroded, to_eroded, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
    opened = (to_eroded <= r) & raster;
    const double limit_px = min_feature_mm * min_feature_mm / 2 * ppm * ppm;
    // Parts that only hang together through something thinner than the minimum feature
    // (a neck the disc cannot pass) come apart in the cutting or the sanding.
    const int opened_n = cv::connectedComponentsWithStats(opened, labels, stats, centroids, 4, CV_32S);
    int big_parts = 0;
    for (int i = 1; i < opened_n; ++i) big_parts += stats.at<int>(i, cv::CC_STAT_AREA) > limit_px;
    if (big_parts > 1) {
      return format("falls apart into %g parts joined by a neck thinner than %g mm", big_parts, min_feature_mm);
    }
    cv::subtract(raster, opened, removed);
    const int n = cv::connectedComponentsWithStats(removed, labels, stats, centroids, 8, CV_32S);
    double thinnest_mm = -1;
    for (int i = 1; i < n; ++i) {
      if (stats.at<int>(i, cv::CC_STAT_AREA) <= limit_px) continue;
      const double thickness_mm = 2 * inscribed_radius_px(dist, labels == i) / ppm;
      if (thinnest_mm < 0 || thickness_mm < thinnest_mm) thinnest_mm = thickness_mm;
    }
    if (thinnest_mm >= 0) {
      return format("has a sliver %.1f mm thin (minimum %g mm)", thinnest_mm, min_feature_mm);
    }
    return std::nullopt;
  } catch (const cv::Exception& e) {
    throw std::runtime_error(std::string("fabricability check failed: ") + e.what());
  }
}

}  // namespace atelier::parquetry

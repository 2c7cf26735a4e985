#include "algorithms/pencil/path.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace atelier::pencil {

double time_step(double length_px) {
  if (length_px <= 200) return 0.5;
  if (length_px <= 400) return 0.3;
  return 0.2;
}

cv::Point2d min_jerk(cv::Point2d from, cv::Point2d to, double t) {
  const double tau = t / kFinalTime;
  const double tau3 = tau * tau * tau;
  const double shape = 15 * tau3 * tau - 6 * tau3 * tau * tau - 10 * tau3;  // 0 at tau 0, -1 at 1
  return from + (from - to) * shape;
}

std::vector<cv::Point2d> control_points(cv::Point2d from, cv::Point2d to, double squiggle,
                                        std::mt19937_64& rng) {
  const cv::Point2d d = to - from;
  const double length = std::hypot(d.x, d.y);
  if (length == 0) return {from};
  const cv::Point2d normal(-d.y / length, d.x / length);
  std::uniform_real_distribution<double> displacement(-squiggle, squiggle);
  const double dt = time_step(length);
  std::vector<cv::Point2d> points{from};
  // Interior times k * dt below t_final (dt need not divide it: 0.3), then the end itself.
  for (int k = 1; k * dt < kFinalTime - 1e-9; ++k)
    points.push_back(min_jerk(from, to, k * dt) + normal * displacement(rng));
  points.push_back(to);
  return points;
}

std::vector<cv::Point2d> catmull_rom(const std::vector<cv::Point2d>& points, double spacing_px) {
  if (points.size() < 2) return points;
  std::vector<cv::Point2d> out{points.front()};
  const std::size_t n = points.size();
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const cv::Point2d& p0 = points[i == 0 ? 0 : i - 1];
    const cv::Point2d& p1 = points[i];
    const cv::Point2d& p2 = points[i + 1];
    const cv::Point2d& p3 = points[i + 2 < n ? i + 2 : n - 1];
    // As a cubic Bezier the segment has control points p1, b1, b2, p2; its speed is at most
    // 3 x the longest leg of that polygon (the derivative's hull), which bounds each step.
    const cv::Point2d b1 = p1 + (p2 - p0) / 6.0, b2 = p2 - (p3 - p1) / 6.0;
    const double leg = std::max({cv::norm(b1 - p1), cv::norm(b2 - b1), cv::norm(p2 - b2)});
    const int steps = std::max(1, static_cast<int>(std::ceil(3 * leg / spacing_px)));
    for (int k = 1; k <= steps; ++k) {
      const double s = static_cast<double>(k) / steps, s2 = s * s, s3 = s2 * s;
      out.push_back(0.5 * (2.0 * p1 + (p2 - p0) * s + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * s2 +
                           (3.0 * p1 - p0 - 3.0 * p2 + p3) * s3));
    }
    out.back() = p2;  // exactly the control point, not a rounding of it
  }
  return out;
}

HumanPath human_path(cv::Point2d from, cv::Point2d to, const PathParams& params, std::uint64_t seed) {
  if (!std::isfinite(params.squiggle) || params.squiggle < 0)
    throw std::invalid_argument("squiggle must be a distance of 0 px or more");
  if (!std::isfinite(params.spacing_px) || params.spacing_px <= 0)
    throw std::invalid_argument("spacing_px must be more than 0");
  if (!std::isfinite(from.x) || !std::isfinite(from.y) || !std::isfinite(to.x) || !std::isfinite(to.y))
    throw std::invalid_argument("the end points must be finite");
  std::mt19937_64 rng(seed);
  HumanPath out;
  out.control = control_points(from, to, params.squiggle, rng);
  out.path = catmull_rom(out.control, params.spacing_px);
  return out;
}

}  // namespace atelier::pencil

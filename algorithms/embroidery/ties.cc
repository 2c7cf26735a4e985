// Tiny-stitch filter and tie stitches along a run's own path.
#include "algorithms/embroidery/ties.h"

#include <algorithm>
#include <cmath>

namespace atelier::embroidery {

bool stitch_longer_than(cv::Point2d a, cv::Point2d b, double min_mm) {
  if (!(cv::norm(b - a) > min_mm)) return false;
  // The files hold positions rounded to 0.1 mm (stitch_plan.h): a 0.14 mm stitch can be
  // written as 0.1 mm.
  const cv::Point2d ra(std::round(a.x * 10) / 10, std::round(a.y * 10) / 10);
  const cv::Point2d rb(std::round(b.x * 10) / 10, std::round(b.y * 10) / 10);
  return cv::norm(rb - ra) > min_mm + 1e-9;
}

namespace {

// The point `at` mm along the polyline pts[0], pts[1], ... (clamped to its end).
template <class It>
cv::Point2d along(It first, It last, double at) {
  cv::Point2d here = *first;
  for (It it = std::next(first); it != last; ++it) {
    const cv::Point2d next = *it;
    const double d = cv::norm(next - here);
    if (d >= at && d > 0) return here + (next - here) * (at / d);
    at -= d;
    here = next;
  }
  return here;
}

template <class It>
double length(It first, It last) {
  double len = 0;
  for (It it = first; it != last && std::next(it) != last; ++it) len += cv::norm(*std::next(it) - *it);
  return len;
}

template <class It>
std::vector<cv::Point2d> tie(It first, It last, double min_mm) {
  const cv::Point2d home = *first;
  const double reach = std::min(length(first, last), 2 * kTieStitchMm);
  if (reach / 2 > min_mm) {
    const double s = reach / 2;
    const cv::Point2d half = along(first, last, s), whole = along(first, last, 2 * s);
    // A path that doubles back (a satin tip's short spans) can bring these back near home.
    if (stitch_longer_than(home, half, min_mm) && stitch_longer_than(half, whole, min_mm))
      return {half, whole, half, home};
  }
  // Short or folded: back and forth on the way to the first point clear of home.
  for (It it = std::next(first); it != last; ++it) {
    const double d = cv::norm(*it - home);
    const cv::Point2d t = d > 0 ? home + (*it - home) * (std::min(d, kTieStitchMm) / d) : home;
    if (stitch_longer_than(home, t, min_mm)) return {t, home, t, home};
  }
  return {};  // the whole run lies within min_mm of its start
}

}  // namespace

int drop_tiny_stitches(std::vector<cv::Point2d>& run, double min_mm) {
  if (run.size() < 2) return 0;
  size_t kept = 1;
  for (size_t i = 1; i < run.size(); ++i)
    if (stitch_longer_than(run[kept - 1], run[i], min_mm)) run[kept++] = run[i];
  const int dropped = static_cast<int>(run.size() - kept);
  run.resize(kept);
  return dropped;
}

double run_length(const std::vector<cv::Point2d>& run) { return length(run.begin(), run.end()); }

std::vector<cv::Point2d> tie_in(const std::vector<cv::Point2d>& run, double min_mm) {
  if (run.empty()) return {};
  return tie(run.begin(), run.end(), min_mm);
}

std::vector<cv::Point2d> tie_off(const std::vector<cv::Point2d>& run, double min_mm) {
  if (run.empty()) return {};
  return tie(run.rbegin(), run.rend(), min_mm);
}

}  // namespace atelier::embroidery

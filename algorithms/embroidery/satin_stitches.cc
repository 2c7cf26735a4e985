// Satin columns along skeleton branches.
#include "algorithms/embroidery/satin_stitches.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "algorithms/embroidery/fill_stitches.h"

namespace atelier::embroidery {
namespace {

struct Cut {
  cv::Point2f centre, normal;
  double minus, plus;  // distances to the mask's edge on either side along the normal
};

bool inside(const cv::Mat1b& mask, cv::Point2f p) {
  const int x = cvRound(p.x), y = cvRound(p.y);
  return x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && mask(y, x) != 0;
}

// How far the ray from p along dir stays on the mask (0.5 px steps).
double reach(const cv::Mat1b& mask, cv::Point2f p, cv::Point2f dir, double limit) {
  double d = 0;
  while (d < limit && inside(mask, p + dir * static_cast<float>(d + 0.5))) d += 0.5;
  return d;
}

}  // namespace

bool satin_column(const cv::Mat1b& mask, const SampledCurve& curve, const ColumnParams& p, StitchSink& sink) {
  const double limit = std::hypot(mask.cols, mask.rows);
  std::vector<Cut> cuts;
  cuts.reserve(curve.points.size());
  for (size_t i = 0; i < curve.points.size(); ++i) {
    const cv::Point2f q = curve.points[i];
    if (!inside(mask, q)) continue;
    const cv::Point2f n(-curve.tangents[i].y, curve.tangents[i].x);
    cuts.push_back({q, n, reach(mask, q, -n, limit), reach(mask, q, n, limit)});
  }
  if (cuts.empty()) return false;
  int k = 1;  // sub-columns: each at most max_span wide before pull compensation
  if (p.max_span_px > 0)
    for (const Cut& c : cuts)
      k = std::max(k, static_cast<int>(std::ceil((c.minus + c.plus) / p.max_span_px - 1e-9)));

  bool forward = true;
  if (p.underlay) {  // centre walk: running stitches along the curve, then satin back over it
    const int every = std::max(1, static_cast<int>(std::floor(p.run_px / (p.spacing_px / 2))));
    std::vector<cv::Point2f> walk;
    for (size_t i = 0; i < cuts.size(); i += every) walk.push_back(cuts[i].centre);
    if (walk.back() != cuts.back().centre) walk.push_back(cuts.back().centre);
    sink.travel_to(walk.front());
    sink.run_along(walk);
    forward = false;
  }
  const int n = static_cast<int>(cuts.size());
  const double span_limit = p.max_span_px > 0 ? std::hypot(p.max_span_px + 2 * p.pull_px, p.spacing_px) : 0.0;
  for (int col = 0; col < k; ++col, forward = !forward) {
    for (int t = 0; t < n; ++t) {
      const Cut& c = cuts[forward ? t : n - 1 - t];
      const double w = c.minus + c.plus;
      const double e = (t % 2 == 0) ? -c.minus + w * col / k - p.pull_px : -c.minus + w * (col + 1) / k + p.pull_px;
      const cv::Point2f pt = c.centre + c.normal * static_cast<float>(e);
      // Get there inside the region: to the cut's own point nearest the first needle point.
      if (t == 0 && col == 0) sink.travel_to(c.centre + c.normal * static_cast<float>(std::clamp(e, -c.minus, c.plus)));
      // A span longer than a sub-column (the width jumps between neighbouring cuts, or the
      // cuts fan out on a tight bend) is split like a running stitch: no stitch may snag.
      if (span_limit > 0 && !sink.empty() && cv::norm(pt - sink.last()) > span_limit) sink.run(pt);
      else sink.stitch(pt);
    }
  }
  return true;
}

std::vector<StitchPoint> satin_region(const cv::Mat1b& mask, cv::Point2f offset_px, double fallback_angle,
                                      const StitchParams& params) {
  const double ppm = params.px_per_mm;
  const double run_px = params.running_stitch_mm * ppm, spacing_px = params.satin_spacing_mm * ppm;
  InsideTravel travel(mask, std::max(2.0, 0.5 * ppm));
  StitchSink sink(&travel, run_px, params.trim_jump_mm * ppm);
  std::vector<SkeletonBranch> branches = skeleton_branches(mask, std::max(3.0, 1.5 * ppm));
  cv::Mat1f dist;
  if (!branches.empty()) cv::distanceTransform(mask, dist, cv::DIST_L2, 3);
  const ColumnParams cp{spacing_px, params.satin_pull_comp_mm * ppm, params.satin_max_mm * ppm,
                        params.satin_underlay, run_px};
  std::vector<bool> done(branches.size(), false);
  bool sewn = false;
  for (size_t k = 0; k < branches.size(); ++k) {
    cv::Point2f needle;
    if (!sink.empty()) needle = sink.last();
    SkeletonBranch b = next_branch(branches, done, sink.empty() ? nullptr : &needle);
    // Extend by the stroke's half width at the ends: thinning stops that far short of a tip.
    const cv::Point2f e0 = b.pixels.front(), e1 = b.pixels.back();
    const double extend = std::max(dist(cvRound(e0.y), cvRound(e0.x)), dist(cvRound(e1.y), cvRound(e1.x)));
    sewn |= satin_column(mask, fit_bspline(b, spacing_px / 2, extend), cp, sink);
  }
  if (!sewn) fill_into(mask, fallback_angle, params, sink);
  return sink.to_mm(offset_px, ppm);
}

}  // namespace atelier::embroidery

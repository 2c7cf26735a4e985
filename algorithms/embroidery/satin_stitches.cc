// Satin columns along skeleton branches.
#include "algorithms/embroidery/satin_stitches.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "algorithms/embroidery/coverage.h"
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

// True when every pixel of the 8-connected line a-b is set in m.
bool line_on(const cv::Mat1b& m, cv::Point2f a, cv::Point2f b) {
  const cv::Point pa(cvRound(a.x), cvRound(a.y)), pb(cvRound(b.x), cvRound(b.y));
  const cv::Rect r(0, 0, m.cols, m.rows);
  if (!r.contains(pa) || !r.contains(pb)) return false;
  cv::LineIterator it(m, pa, pb, 8);
  for (int i = 0; i < it.count; ++i, ++it)
    if (**it == 0) return false;
  return true;
}

}  // namespace

bool satin_column(const cv::Mat1b& mask, const SampledCurve& curve, const ColumnParams& p, StitchSink& sink) {
  const double limit = std::hypot(mask.cols, mask.rows);
  // Cut directions from the tangent averaged over +-8 px of arc (the spline's control
  // spacing): the thinned skeleton's staircase would otherwise swing the cuts into fans.
  const size_t m = curve.points.size();
  std::vector<cv::Point2d> sum(m + 1, cv::Point2d(0, 0));
  std::vector<double> arc(m, 0.0);
  for (size_t i = 0; i < m; ++i) {
    sum[i + 1] = sum[i] + cv::Point2d(curve.tangents[i]);
    if (i > 0) arc[i] = arc[i - 1] + cv::norm(curve.points[i] - curve.points[i - 1]);
  }
  // Candidate cuts: the samples inside the mask, with the averaged normal; the edges (the
  // costly part, a walk along the normal) are found only for the cuts taken.
  struct Sample {
    cv::Point2f centre, normal;
  };
  std::vector<Sample> fine;
  fine.reserve(m);
  size_t lo = 0, hi = 0;
  for (size_t i = 0; i < m; ++i) {  // bounded: lo and hi only move forward
    const cv::Point2f q = curve.points[i];
    while (arc[i] - arc[lo] > 8.0) ++lo;
    while (hi + 1 < m && arc[hi + 1] - arc[i] <= 8.0) ++hi;
    if (!inside(mask, q)) continue;
    cv::Point2d t = sum[hi + 1] - sum[lo];
    const double tl = cv::norm(t);
    t = tl > 1e-9 ? t * (1.0 / tl) : cv::Point2d(curve.tangents[i]);
    fine.push_back({q, cv::Point2f(static_cast<float>(-t.y), static_cast<float>(t.x))});
  }
  if (fine.empty()) return false;
  // The needle's cuts: consecutive ones at most half the spacing apart on the centre line and
  // on both edges (on a bend the outer edge moves farther than the centre; spaced by the
  // centre alone the thread leaves gaps there). A little under half: the metric's thread is
  // exactly as wide as the spacing.
  const double advance = 0.475 * p.spacing_px;
  auto cut_at = [&](const Sample& f) {
    return Cut{f.centre, f.normal, reach(mask, f.centre, -f.normal, limit), reach(mask, f.centre, f.normal, limit)};
  };
  // How far the thread moves along the column from cut a to sample b: the centre's advance
  // plus what the turn of the cut adds at a's far ends (edges themselves are pixel-jagged).
  auto moved = [](const Cut& a, const Sample& b) {
    const double turn = std::acos(std::clamp(static_cast<double>(a.normal.dot(b.normal)), -1.0, 1.0));
    return cv::norm(a.centre - b.centre) + turn * std::max(a.minus, a.plus);
  };
  std::vector<Cut> cuts{cut_at(fine.front())};
  size_t last = 0;
  for (size_t i = 1; i < fine.size(); ++i) {  // bounded: one pass over the samples
    if (moved(cuts.back(), fine[i]) <= advance) continue;
    if (i - 1 > last) {
      cuts.push_back(cut_at(fine[i - 1]));
      last = i - 1;
      if (moved(cuts.back(), fine[i]) <= advance) continue;
    }
    cuts.push_back(cut_at(fine[i]));
    last = i;
  }
  if (last + 1 < fine.size()) cuts.push_back(cut_at(fine.back()));
  // Sub-columns: each one's stitch (its width, twice the pull compensation and the half
  // spacing it advances) within max_span, so no stitch of a straight column is longer.
  int k = 1;
  if (p.max_span_px > 0) {
    const double half_step = 0.5 * p.spacing_px;
    const double room = std::max(0.25 * p.max_span_px,
                                 std::sqrt(std::max(0.0, p.max_span_px * p.max_span_px - half_step * half_step)) -
                                     2 * p.pull_px - 0.05 * p.spacing_px);
    for (const Cut& c : cuts)
      k = std::max(k, static_cast<int>(std::ceil((c.minus + c.plus) / room - 1e-9)));
  }

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
  // Needle-to-needle checks against the mask grown by the pull compensation (plus a pixel of
  // rounding): a stitch that crosses bare fabric there (a tight bend, a fan of cuts in a
  // concave part) is a spike; the needle gets to its point inside the region instead.
  const int grow = cvCeil(p.pull_px + 0.75);  // a needle point's pull and its pixel's half diagonal
  const int pad = grow + 1;                     // pull-compensated points may lie past the box
  cv::Mat1b grown;
  cv::copyMakeBorder(mask, grown, pad, pad, pad, pad, cv::BORDER_CONSTANT, 0);
  cv::dilate(grown, grown, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * grow + 1, 2 * grow + 1)));
  const cv::Point2f shift(static_cast<float>(pad), static_cast<float>(pad));
  const int n = static_cast<int>(cuts.size());
  cv::Point2f prev_on_cut;
  bool have_prev = false;
  for (int col = 0; col < k; ++col, forward = !forward) {
    for (int t = 0; t < n; ++t) {  // bounded: one needle point per cut and sub-column
      const Cut& c = cuts[forward ? t : n - 1 - t];
      const double w = c.minus + c.plus;
      const double e = (t % 2 == 0) ? -c.minus + w * col / k - p.pull_px : -c.minus + w * (col + 1) / k + p.pull_px;
      const cv::Point2f pt = c.centre + c.normal * static_cast<float>(e);
      const cv::Point2f on_cut = c.centre + c.normal * static_cast<float>(std::clamp(e, -c.minus, c.plus));
      // Get there inside the region: to the cut's own point nearest the first needle point.
      if (t == 0 && col == 0) sink.travel_to(on_cut);
      if (sink.empty()) {
        sink.stitch(pt);
        prev_on_cut = on_cut, have_prev = true;
        continue;
      }
      if (!line_on(grown, sink.last() + shift, pt + shift)) {  // a spike: back onto the region, round inside, stitch
        if (have_prev) sink.run(prev_on_cut);
        sink.travel_to(on_cut);
        sink.stitch(pt);
        prev_on_cut = on_cut, have_prev = true;
        continue;
      }
      prev_on_cut = on_cut, have_prev = true;
      // A stitch longer than max_span (the width jumps between neighbouring cuts, or the
      // cuts fan out on a bend) is split in equal stitches, as a split satin: none may snag.
      const double d = cv::norm(pt - sink.last());
      if (p.max_span_px > 0 && d > p.max_span_px) {
        const cv::Point2f a = sink.last();
        const int parts = static_cast<int>(std::ceil(d / p.max_span_px - 1e-9));
        for (int i = 1; i <= parts; ++i) sink.stitch(a + (pt - a) * (static_cast<float>(i) / parts));
      } else {
        sink.stitch(pt);
      }
    }
  }
  return true;
}

double sink_coverage(const cv::Mat1b& mask, const StitchSink& sink, double px_per_mm) {
  if (sink.empty()) return cv::countNonZero(mask) == 0 ? 1.0 : 0.0;
  // Sink points are mask pixels: measured at 1 "px per mm", the radius given in pixels.
  return region_coverage(mask, sink.to_mm({0, 0}, 1.0), {0, 0}, 1.0, kThreadRadiusMm * px_per_mm);
}

std::vector<StitchPoint> on_region_mm(const cv::Mat1b& mask, const StitchSink& sink, cv::Point2f offset_px,
                                      double px_per_mm, double limit_px) {
  std::vector<StitchPoint> pts = sink.to_mm({0, 0}, 1.0);  // mask pixels
  const int pad = cvCeil(limit_px) + 2;
  bool far = false;
  cv::Mat1b padded;
  cv::copyMakeBorder(mask, padded, pad, pad, pad, pad, cv::BORDER_CONSTANT, 0);
  cv::Mat1f dist;
  cv::Mat1i label;
  if (cv::countNonZero(mask) > 0) {
    cv::distanceTransform(~padded, dist, cv::DIST_L2, cv::DIST_MASK_5);
    for (const StitchPoint& p : pts) {
      const int x = cvRound(p.x_mm) + pad, y = cvRound(p.y_mm) + pad;
      far |= p.kind == StitchKind::stitch &&
             (x < 0 || y < 0 || x >= dist.cols || y >= dist.rows || dist(y, x) > limit_px);
    }
  }
  if (far) {
    cv::distanceTransform(~padded, dist, label, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
    // DIST_LABEL_PIXEL numbers the zero pixels (here: the mask's) from 1 in raster order.
    std::vector<cv::Point> at(1);
    for (int y = 0; y < padded.rows; ++y)
      for (int x = 0; x < padded.cols; ++x)
        if (padded(y, x)) at.emplace_back(x, y);
    for (StitchPoint& p : pts) {
      if (p.kind != StitchKind::stitch) continue;
      const int x = std::clamp(cvRound(p.x_mm) + pad, 0, dist.cols - 1), y = std::clamp(cvRound(p.y_mm) + pad, 0, dist.rows - 1);
      const bool outside_box = cvRound(p.x_mm) + pad != x || cvRound(p.y_mm) + pad != y;
      if (!outside_box && dist(y, x) <= limit_px) continue;
      const int l = label(y, x);
      if (l <= 0 || l >= static_cast<int>(at.size())) continue;
      p.x_mm = at[l].x - pad, p.y_mm = at[l].y - pad;
    }
  }
  for (StitchPoint& p : pts) {
    p.x_mm = (p.x_mm + offset_px.x) / px_per_mm;
    p.y_mm = (p.y_mm + offset_px.y) / px_per_mm;
  }
  return pts;
}

double cover_bare(const cv::Mat1b& mask, double angle, const StitchParams& params, StitchSink& sink) {
  const double ppm = params.px_per_mm, radius_px = kThreadRadiusMm * ppm;
  const int area = cv::countNonZero(mask);
  if (area == 0) return 1.0;
  auto bare_of = [&] {
    // Sink points are mask pixels: measured at 1 "px per mm", radius given in pixels.
    const cv::Mat1b sewn = sink.empty() ? cv::Mat1b(mask.size(), uchar(0))
                                        : thread_pixels(mask.size(), sink.to_mm({0, 0}, 1.0), {0, 0}, 1.0, radius_px);
    return cv::Mat1b(mask & ~sewn);
  };
  cv::Mat1b bare = bare_of();
  // Topped up below 99 %: a margin over the target for what moving stray travel points
  // (on_region_mm) may take away.
  if (1.0 - static_cast<double>(cv::countNonZero(bare)) / area >= 0.99) {
    return 1.0 - static_cast<double>(cv::countNonZero(bare)) / area;
  }
  cv::Mat1i labels, stats;
  cv::Mat1d centroids;
  const int n = cv::connectedComponentsWithStats(bare, labels, stats, centroids, 8, CV_32S);
  const int min_px = std::max(4, static_cast<int>(std::lround(0.25 * ppm * ppm)));
  const cv::Mat grow = cv::getStructuringElement(cv::MORPH_RECT, {3, 3});
  bool filled = false;
  for (int c = 1; c < n; ++c) {  // bounded: one fill per bare part
    if (stats(c, cv::CC_STAT_AREA) < min_px) continue;
    filled = true;
    const cv::Rect box = cv::Rect(stats(c, cv::CC_STAT_LEFT) - 1, stats(c, cv::CC_STAT_TOP) - 1,
                                  stats(c, cv::CC_STAT_WIDTH) + 2, stats(c, cv::CC_STAT_HEIGHT) + 2) &
                         cv::Rect(0, 0, mask.cols, mask.rows);
    cv::Mat1b part(mask.size(), uchar(0));
    part(box).setTo(255, labels(box) == c);
    cv::dilate(part(box), part(box), grow);
    part(box) &= mask(box);
    fill_into(part, angle, params, sink);
  }
  if (filled) bare = bare_of();
  // Still under the margin: what is left are specks too small to fill (a fill row needs room),
  // e.g. along a thin stroke's ragged border. Visit each, nearest first, with travel inside the
  // region: its running stitch lays thread over the speck. Bounded: at most kMaxSpecks visits.
  if (1.0 - static_cast<double>(cv::countNonZero(bare)) / area < 0.99) {
    const int m = cv::connectedComponentsWithStats(bare, labels, stats, centroids, 8, CV_32S);
    constexpr int kMaxSpecks = 400;
    std::vector<cv::Point2f> specks;
    for (int c = 1; c < m && static_cast<int>(specks.size()) < kMaxSpecks; ++c) {
      // The speck's pixel nearest its centroid (a ring's centroid may lie outside it).
      const cv::Point2f centre(static_cast<float>(centroids(c, 0)), static_cast<float>(centroids(c, 1)));
      cv::Point2f best(-1, -1);
      double best_d = 1e18;
      const int x0 = stats(c, cv::CC_STAT_LEFT), y0 = stats(c, cv::CC_STAT_TOP);
      for (int y = y0; y < y0 + stats(c, cv::CC_STAT_HEIGHT); ++y)
        for (int x = x0; x < x0 + stats(c, cv::CC_STAT_WIDTH); ++x) {
          if (labels(y, x) != c) continue;
          const double d = (x - centre.x) * (x - centre.x) + (y - centre.y) * (y - centre.y);
          if (d < best_d) best_d = d, best = cv::Point2f(static_cast<float>(x), static_cast<float>(y));
        }
      specks.push_back(best);
    }
    cv::Point2f at = sink.empty() ? (specks.empty() ? cv::Point2f() : specks.front()) : sink.last();
    std::vector<bool> visited(specks.size(), false);
    for (size_t k = 0; k < specks.size(); ++k) {  // greedy nearest-first: O(specks^2), <= 160k
      size_t next = 0;
      double next_d = 1e18;
      for (size_t i = 0; i < specks.size(); ++i) {
        if (visited[i]) continue;
        const double d = cv::norm(specks[i] - at);
        if (d < next_d) next_d = d, next = i;
      }
      visited[next] = true;
      sink.travel_to(specks[next]);
      at = specks[next];
    }
    if (!specks.empty()) bare = bare_of();
  }
  return 1.0 - static_cast<double>(cv::countNonZero(bare)) / area;
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
    sewn |= satin_column(mask, fit_bspline(b, spacing_px / 8, extend), cp, sink);
  }
  const double satin_cover = sewn ? cover_bare(mask, fallback_angle, params, sink) : 0.0;
  const double limit_px = cp.pull_px + 0.75;
  if (satin_cover >= kCoverTarget) return on_region_mm(mask, sink, offset_px, ppm, limit_px);
  // Satin cannot cover this region: tatami over all of it, unless that covers even less.
  StitchSink fill(&travel, run_px, params.trim_jump_mm * ppm);
  fill_into(mask, fallback_angle, params, fill);
  return on_region_mm(mask, sewn && satin_cover > sink_coverage(mask, fill, ppm) ? sink : fill, offset_px, ppm,
                      limit_px);
}

}  // namespace atelier::embroidery

// Running stitches, travel inside a region, edge strokes.
#include "algorithms/embroidery/running_stitches.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "algorithms/embroidery/coverage.h"
#include "algorithms/embroidery/fill_stitches.h"
#include "algorithms/embroidery/satin_stitches.h"
#include "algorithms/embroidery/skeleton.h"
#include "algorithms/embroidery/stitch_planner.h"

namespace atelier::embroidery {

// ---- InsideTravel -----------------------------------------------------------------------
InsideTravel::InsideTravel(const cv::Mat1b& mask, double cell_px)
    : mask_(mask), cell_(std::max(2, static_cast<int>(std::lround(cell_px)))) {
  const int cw = (mask.cols + cell_ - 1) / cell_, ch = (mask.rows + cell_ - 1) / cell_;
  cv::Mat1b padded(ch * cell_, cw * cell_, uchar(0));
  mask.copyTo(padded(cv::Rect(0, 0, mask.cols, mask.rows)));
  // A cell is usable when its minimum is 255: erode by the cell, then sample its centres.
  cv::Mat1b eroded;
  cv::erode(padded, eroded, cv::getStructuringElement(cv::MORPH_RECT, {cell_, cell_}, {0, 0}));
  inside_.create(ch, cw);
  for (int y = 0; y < ch; ++y)
    for (int x = 0; x < cw; ++x) inside_(y, x) = eroded(y * cell_, x * cell_);
}

bool InsideTravel::line_inside(cv::Point2f a, cv::Point2f b) const {
  const cv::Point pa(cvRound(a.x), cvRound(a.y)), pb(cvRound(b.x), cvRound(b.y));
  const cv::Rect r(0, 0, mask_.cols, mask_.rows);
  if (!r.contains(pa) || !r.contains(pb)) return false;
  cv::LineIterator it(mask_, pa, pb, 8);
  for (int i = 0; i < it.count; ++i, ++it)
    if (**it == 0) return false;
  return true;
}

bool InsideTravel::nearest_cell(cv::Point2f p, cv::Point& cell) const {
  const int cx = static_cast<int>(p.x) / cell_, cy = static_cast<int>(p.y) / cell_;
  double best = 1e18;
  for (int r = 0; r <= 2; ++r) {
    for (int y = cy - r; y <= cy + r; ++y)
      for (int x = cx - r; x <= cx + r; ++x) {
        if (std::max(std::abs(x - cx), std::abs(y - cy)) != r) continue;
        if (x < 0 || y < 0 || x >= inside_.cols || y >= inside_.rows || !inside_(y, x)) continue;
        const cv::Point2f c((x + 0.5f) * cell_ - 0.5f, (y + 0.5f) * cell_ - 0.5f);
        const double d = cv::norm(c - p);
        if (d < best && line_inside(p, c)) {
          best = d;
          cell = {x, y};
        }
      }
    if (best < 1e18) return true;
  }
  return false;
}

bool InsideTravel::path(cv::Point2f a, cv::Point2f b, std::vector<cv::Point2f>& out, int margin_cells) const {
  out.clear();
  if (line_inside(a, b)) {
    out = {a, b};
    return true;
  }
  cv::Point ca, cb;
  if (!nearest_cell(a, ca) || !nearest_cell(b, cb)) return false;
  // Breadth-first search over inside cells, diagonal steps only past two inside cells.
  const int cols = inside_.cols;
  if (stamp_.empty()) {
    stamp_.assign(inside_.total(), 0);
    parent_.assign(inside_.total(), 0);
  }
  const unsigned stamp = ++search_;
  auto seen = [&](cv::Point c) { return stamp_[c.y * cols + c.x] == stamp; };
  auto set_from = [&](cv::Point c, cv::Point f) {
    stamp_[c.y * cols + c.x] = stamp;
    parent_[c.y * cols + c.x] = f.y * cols + f.x;
  };
  auto from = [&](cv::Point c) { return parent_[c.y * cols + c.x]; };
  cv::Rect window(0, 0, inside_.cols, inside_.rows);
  if (margin_cells >= 0)
    window &= cv::Rect(cv::Point(std::min(ca.x, cb.x) - margin_cells, std::min(ca.y, cb.y) - margin_cells),
                       cv::Point(std::max(ca.x, cb.x) + margin_cells + 1, std::max(ca.y, cb.y) + margin_cells + 1));
  std::vector<cv::Point> queue{ca};
  set_from(ca, ca);
  bool found = ca == cb;
  for (size_t q = 0; q < queue.size() && !found; ++q) {
    const cv::Point c = queue[q];
    for (int dy = -1; dy <= 1 && !found; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const cv::Point n(c.x + dx, c.y + dy);
        if ((dx == 0 && dy == 0) || !window.contains(n)) continue;
        if (!inside_(n) || seen(n)) continue;
        if (dx != 0 && dy != 0 && (!inside_(c.y, n.x) || !inside_(n.y, c.x))) continue;
        set_from(n, c);
        if (n == cb) {
          found = true;
          break;
        }
        queue.push_back(n);
      }
  }
  if (!found) return false;
  std::vector<cv::Point2f> cells;
  for (cv::Point c = cb;;) {
    cells.emplace_back((c.x + 0.5f) * cell_ - 0.5f, (c.y + 0.5f) * cell_ - 0.5f);
    if (c == ca) break;
    const int f = from(c);
    c = {f % inside_.cols, f / inside_.cols};
  }
  std::reverse(cells.begin(), cells.end());
  std::vector<cv::Point2f> full;
  full.reserve(cells.size() + 2);
  full.push_back(a);
  full.insert(full.end(), cells.begin(), cells.end());
  full.push_back(b);
  // Line of sight shortening: from each kept point, jump to the farthest point still visible
  // along the path (checked forward until the first blocked one).
  out.push_back(a);
  size_t i = 0;
  while (i + 1 < full.size()) {
    size_t j = i + 1;
    while (j + 1 < full.size() && line_inside(full[i], full[j + 1])) ++j;
    out.push_back(full[j]);
    i = j;
  }
  return true;
}

// ---- StitchSink -------------------------------------------------------------------------
void StitchSink::stitch(cv::Point2f p) { pts_.push_back({p, StitchKind::stitch}); }

void StitchSink::run(cv::Point2f p) {
  if (pts_.empty()) {
    stitch(p);
    return;
  }
  const cv::Point2f a = last();
  const double d = cv::norm(p - a);
  if (d < 1e-4) return;  // already there: no stitch in place
  // Points arrive as float32: a stitch meant to be exactly max_px long measures a few 1e-6
  // relative over it, and ceil(d / max - 1e-9) then sewed it as two halves (issue 21 point 5).
  // 1e-4 of a stitch (0.3 um at 3 mm) is far beyond float32's error and far below the files'
  // 0.1 mm unit.
  const int n = std::max(1, static_cast<int>(std::ceil(d / max_px_ - kLengthTolerance)));
  for (int i = 1; i <= n; ++i) stitch(a + (p - a) * (static_cast<float>(i) / n));
}

void StitchSink::run_along(const std::vector<cv::Point2f>& polyline) {
  for (const cv::Point2f& p : polyline) run(p);
}

void StitchSink::travel_to(cv::Point2f p) {
  if (pts_.empty()) {
    stitch(p);
    return;
  }
  const cv::Point2f a = last();
  if (cv::norm(p - a) < 1e-3) return;
  std::vector<cv::Point2f> path;
  if (travel_ && travel_->path(a, p, path)) {
    run_along(path);
  } else if (cv::norm(p - a) <= trim_jump_px_) {
    run(p);
  } else {
    pts_.push_back({a, StitchKind::trim});
    pts_.push_back({p, StitchKind::jump});
    stitch(p);  // anchors the thread where sewing resumes
  }
}

std::vector<StitchPoint> StitchSink::to_mm(cv::Point2f offset_px, double px_per_mm) const {
  std::vector<StitchPoint> out;
  out.reserve(pts_.size());
  for (const Pt& p : pts_)
    out.push_back({(p.p.x + offset_px.x) / px_per_mm, (p.p.y + offset_px.y) / px_per_mm, p.kind});
  return out;
}

// ---- running stitch along pixels ----------------------------------------------------------
std::vector<cv::Point2f> resample_on_pixels(const std::vector<cv::Point2f>& pixels, double step_px) {
  std::vector<cv::Point2f> out;
  if (pixels.empty()) return out;
  out.push_back(pixels.front());
  for (size_t i = 1; i < pixels.size(); ++i) {
    // Keep the last pixel still within reach of the previous needle point.
    if (cv::norm(pixels[i] - out.back()) > step_px && cv::norm(pixels[i - 1] - out.back()) > 0)
      out.push_back(pixels[i - 1]);
  }
  if (cv::norm(pixels.back() - out.back()) > 0) out.push_back(pixels.back());
  return out;
}

// ---- edge strokes -----------------------------------------------------------------------
std::vector<StitchPoint> edge_region(const cv::Mat1b& mask, cv::Point2f offset_px, double fallback_angle,
                                     const StitchParams& params) {
  const double ppm = params.px_per_mm;
  const double run_px = params.running_stitch_mm * ppm;
  InsideTravel travel(mask, std::max(2.0, 0.5 * ppm));
  std::vector<SkeletonBranch> branches = skeleton_branches(mask, std::max(2.0, 0.5 * ppm));
  if (branches.empty()) {
    StitchSink sink(&travel, run_px, params.trim_jump_mm * ppm);
    fill_into(mask, fallback_angle, params, sink);
    return sink.to_mm(offset_px, ppm);
  }
  cv::Mat1f dist;
  cv::distanceTransform(mask, dist, cv::DIST_L2, 3);
  // Sews every branch: a narrow satin where the stroke is at least satin_min_px wide, else a
  // running stitch. Bounded: one column or run per branch.
  // Stroke width per branch: twice the mean distance to the background along the centre line
  // (the distance at a centre pixel is half the width plus about half a pixel).
  std::vector<double> width_px(branches.size());
  for (size_t k = 0; k < branches.size(); ++k) {
    double sum = 0;
    for (const cv::Point2f& p : branches[k].pixels) sum += dist(cvRound(p.y), cvRound(p.x));
    width_px[k] = std::max(1.0, 2.0 * sum / branches[k].pixels.size() - 1.0);
  }
  auto sew = [&](double satin_min_px) {
    StitchSink sink(&travel, run_px, params.trim_jump_mm * ppm);
    std::vector<bool> done(branches.size(), false);
    for (size_t k = 0; k < branches.size(); ++k) {
      cv::Point2f needle;
      if (!sink.empty()) needle = sink.last();
      const std::vector<bool> before = done;
      const SkeletonBranch b = next_branch(branches, done, sink.empty() ? nullptr : &needle);
      size_t id = 0;
      while (id + 1 < done.size() && !(done[id] && !before[id])) ++id;  // the one just taken
      const double w = width_px[id];
      if (w >= satin_min_px && b.pixels.size() >= 3) {
        const double spacing_px = params.satin_spacing_mm * ppm;
        const SampledCurve c = fit_bspline(b, spacing_px / 8, w / 2);
        const ColumnParams cp{spacing_px, params.satin_pull_comp_mm * ppm, params.satin_max_mm * ppm, false, run_px};
        if (satin_column(mask, c, cp, sink)) continue;
      }
      const std::vector<cv::Point2f> pts = resample_on_pixels(b.pixels, run_px);
      sink.travel_to(pts.front());
      sink.run_along(pts);
    }
    return sink;
  };
  // Issue 21: a running stitch (0.4 mm of thread) cannot cover a wider stroke. As configured
  // first; below kCoverTarget a narrow satin wherever the stroke is wider than the thread,
  // bare parts filled; still below, a tatami fill; the best of these.
  const double limit_px = params.satin_pull_comp_mm * ppm + 0.75;  // see on_region_mm
  // A running stitch on a stroke over a pixel wider than the thread cannot reach the target:
  // straight to the narrow satin then.
  const double thread_px = 2 * kThreadRadiusMm * ppm, satin_min_px = params.edge_satin_min_mm * ppm;
  const bool may_cover = std::all_of(width_px.begin(), width_px.end(),
                                     [&](double w) { return w >= satin_min_px || w <= thread_px + 1.0; });
  if (may_cover) {
    StitchSink sink = sew(satin_min_px);
    if (sink_coverage(mask, sink, ppm) >= kCoverTarget) return on_region_mm(mask, sink, offset_px, ppm, limit_px);
  }
  StitchSink narrow = sew(thread_px);
  const double narrow_cover = cover_bare(mask, fallback_angle, params, narrow);
  if (narrow_cover >= kCoverTarget) return on_region_mm(mask, narrow, offset_px, ppm, limit_px);
  StitchSink fill(&travel, run_px, params.trim_jump_mm * ppm);
  fill_into(mask, fallback_angle, params, fill);
  return on_region_mm(mask, narrow_cover > sink_coverage(mask, fill, ppm) ? narrow : fill, offset_px, ppm, limit_px);
}

}  // namespace atelier::embroidery

// Tatami fill: rows on the region rotated to the stitch direction.
#include "algorithms/embroidery/fill_stitches.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

namespace atelier::embroidery {
namespace {

struct Run {
  int x0, x1;  // inclusive pixel range in the rotated row
  int row;     // row number (its index k, spacing apart)
};

}  // namespace

std::vector<std::vector<cv::Point2f>> fill_sections(const cv::Mat1b& mask, double angle, double spacing_px,
                                                    double max_px, int stagger) {
  std::vector<std::vector<cv::Point2f>> out;
  if (mask.empty() || spacing_px <= 0 || max_px <= 0) return out;
  stagger = std::max(1, stagger);
  // Rotated frame: x along the stitches, y across; y scaled so rows fall exactly `m` rotated
  // pixel rows apart (even spacing with no per-row rounding).
  const double c = std::cos(angle), s = std::sin(angle);
  const int m = std::max(1, static_cast<int>(std::lround(spacing_px)));
  const double sy = m / spacing_px;
  double min_x = 1e18, max_x = -1e18, min_y = 1e18, max_y = -1e18;
  for (const cv::Point2d p : {cv::Point2d(0, 0), cv::Point2d(mask.cols - 1, 0), cv::Point2d(0, mask.rows - 1),
                              cv::Point2d(mask.cols - 1, mask.rows - 1)}) {
    const double x = c * p.x + s * p.y, y = (-s * p.x + c * p.y) * sy;
    min_x = std::min(min_x, x), max_x = std::max(max_x, x);
    min_y = std::min(min_y, y), max_y = std::max(max_y, y);
  }
  const double tx = 1 - std::floor(min_x), ty = 1 - std::floor(min_y);
  const cv::Size size(static_cast<int>(std::ceil(max_x + tx)) + 2, static_cast<int>(std::ceil(max_y + ty)) + 2);
  const cv::Matx23d M(c, s, tx, -s * sy, c * sy, ty);
  cv::Mat1b rot;
  cv::warpAffine(mask, rot, M, size, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  auto back = [&](double qx, double qy) {
    const double a = qx - tx, b = (qy - ty) / sy;
    return cv::Point2f(static_cast<float>(c * a - s * b), static_cast<float>(s * a + c * b));
  };

  // Runs per row; rows every m rotated pixel rows.
  std::vector<std::vector<Run>> rows;
  for (int y = 0, k = 0; y < rot.rows; y += m, ++k) {
    std::vector<Run> runs;
    const uchar* r = rot.ptr<uchar>(y);
    for (int x = 0; x < rot.cols;) {
      if (!r[x]) {
        ++x;
        continue;
      }
      const int x0 = x;
      while (x < rot.cols && r[x]) ++x;
      runs.push_back({x0, x - 1, k});
    }
    rows.push_back(std::move(runs));
  }

  // Sections: runs chained row to row while they overlap one to one.
  auto overlap = [](const Run& a, const Run& b) { return a.x0 <= b.x1 && b.x0 <= a.x1; };
  std::vector<std::vector<Run>> sections;
  std::vector<int> open;  // per run of the previous row: its section, or -1
  for (size_t k = 0; k < rows.size(); ++k) {
    const std::vector<Run>& cur = rows[k];
    std::vector<int> now(cur.size(), -1);
    const std::vector<Run>* prev = k > 0 ? &rows[k - 1] : nullptr;
    for (size_t j = 0; j < cur.size(); ++j) {
      int hit = -1, hits = 0;
      if (prev)
        for (size_t i = 0; i < prev->size(); ++i)
          if (overlap((*prev)[i], cur[j])) hit = static_cast<int>(i), ++hits;
      bool extend = hits == 1 && open[hit] >= 0;
      if (extend) {
        int back_hits = 0;
        for (const Run& r : cur) back_hits += overlap((*prev)[hit], r);
        extend = back_hits == 1;
      }
      if (extend) {
        now[j] = open[hit];
      } else {
        now[j] = static_cast<int>(sections.size());
        sections.emplace_back();
      }
      sections[now[j]].push_back(cur[j]);
    }
    open = std::move(now);
  }

  // Needle points: a grid along x shifted per row; no point nearer than a fifth of a stitch
  // to a row end (no tiny stitches). The grid is a hair (kLengthTolerance) under max_px so
  // that float32 rounding never makes a grid stitch longer than max_px.
  const double min_gap = 0.2 * max_px;
  max_px *= 1 - kLengthTolerance;
  for (const std::vector<Run>& sec : sections) {
    std::vector<cv::Point2f> poly;
    auto add = [&](double x, double y) { poly.push_back(back(x, y)); };
    for (size_t i = 0; i < sec.size(); ++i) {
      const Run& r = sec[i];
      const double y = static_cast<double>(r.row) * m;
      const bool forward = i % 2 == 0;
      const double start = forward ? r.x0 : r.x1, end = forward ? r.x1 : r.x0;
      if (i > 0) {  // connect from the previous row's end, staying on overlapping runs
        const Run& p = sec[i - 1];
        const double py = static_cast<double>(p.row) * m;
        const double pend = forward ? p.x0 : p.x1;  // where the previous row ended
        const bool further = forward ? start <= pend : start >= pend;
        if (further) {
          add(pend, y);  // straight across, then along this row to its start
        } else {
          add(start, py);  // back along the previous row, then across
        }
      }
      add(start, y);
      const double off = static_cast<double>(r.row % stagger) / stagger * max_px;
      if (std::abs(end - start) <= max_px / (1 - kLengthTolerance)) {
        // A row no longer than one stitch is one stitch (a grid point would halve it).
      } else if (forward) {
        for (double g = std::ceil((start - off) / max_px) * max_px + off; g < end; g += max_px)
          if (g - start >= min_gap && end - g >= min_gap) add(g, y);
      } else {
        for (double g = std::floor((start - off) / max_px) * max_px + off; g > end; g -= max_px)
          if (start - g >= min_gap && g - end >= min_gap) add(g, y);
      }
      if (end != start) add(end, y);
    }
    out.push_back(std::move(poly));
  }
  return out;
}

namespace {

// Sews sections nearest first (either direction) with travel inside the region. A region
// with many holes has thousands of sections: their ends sit in a bucket grid searched ring
// by ring outwards from the needle.
void sew_sections(std::vector<std::vector<cv::Point2f>> sections, StitchSink& sink) {
  std::vector<cv::Point2f> ends;  // 2 i: front of section i, 2 i + 1: its back
  for (const auto& sec : sections) {
    ends.push_back(sec.empty() ? cv::Point2f(0, 0) : sec.front());
    ends.push_back(sec.empty() ? cv::Point2f(0, 0) : sec.back());
  }
  std::vector<bool> done(sections.size(), false);
  size_t left = 0;
  for (size_t i = 0; i < sections.size(); ++i) (sections[i].empty() ? done[i] = true : ++left);
  if (left == 0) return;
  const cv::Rect2f box = cv::boundingRect(ends);
  const float cell = std::max(8.0f, std::sqrt(std::max(1.0f, box.area()) / static_cast<float>(left)));
  const int gw = static_cast<int>(box.width / cell) + 1, gh = static_cast<int>(box.height / cell) + 1;
  std::vector<std::vector<int>> grid(static_cast<size_t>(gw) * gh);
  auto cell_of = [&](cv::Point2f p) {
    return cv::Point(std::clamp(static_cast<int>((p.x - box.x) / cell), 0, gw - 1),
                     std::clamp(static_cast<int>((p.y - box.y) / cell), 0, gh - 1));
  };
  for (size_t e = 0; e < ends.size(); ++e)
    if (!done[e / 2]) {
      const cv::Point c = cell_of(ends[e]);
      grid[static_cast<size_t>(c.y) * gw + c.x].push_back(static_cast<int>(e));
    }
  for (; left > 0; --left) {
    int best = -1;
    if (sink.empty()) {
      for (size_t i = 0; i < sections.size() && best < 0; ++i)
        if (!done[i]) best = static_cast<int>(2 * i);
    } else {
      const cv::Point2f here = sink.last();
      const cv::Point c = cell_of(here);
      float best_d = std::numeric_limits<float>::max();
      for (int r = 0; r <= std::max(gw, gh); ++r) {
        const float reach = (r - 1) * cell;  // every end in ring r is at least this far
        if (best >= 0 && reach > 0 && best_d <= reach * reach) break;
        for (int y = c.y - r; y <= c.y + r; ++y) {
          if (y < 0 || y >= gh) continue;
          const bool edge_row = y == c.y - r || y == c.y + r;
          for (int x = c.x - r; x <= c.x + r; x += (edge_row || r == 0) ? 1 : 2 * r) {
            if (x < 0 || x >= gw) continue;
            std::vector<int>& bucket = grid[static_cast<size_t>(y) * gw + x];
            for (size_t k = 0; k < bucket.size();) {
              const int e = bucket[k];
              if (done[e / 2]) {  // drop ends of sewn sections lazily
                bucket[k] = bucket.back();
                bucket.pop_back();
                continue;
              }
              const cv::Point2f d = ends[e] - here;
              const float dd = d.dot(d);
              if (dd < best_d) best_d = dd, best = e;
              ++k;
            }
          }
        }
      }
    }
    std::vector<cv::Point2f>& sec = sections[best / 2];
    done[best / 2] = true;
    if (best % 2 == 1) std::reverse(sec.begin(), sec.end());
    sink.travel_to(sec.front());
    sink.run_along(sec);
  }
}

}  // namespace

void fill_into(const cv::Mat1b& mask, double angle, const StitchParams& params, StitchSink& sink) {
  const double ppm = params.px_per_mm;
  const double spacing = params.fill_row_spacing_mm * ppm, max_px = params.fill_max_stitch_mm * ppm;
  if (params.fill_underlay) {
    const int inset = static_cast<int>(std::lround(0.5 * ppm));
    cv::Mat1b inner;
    if (inset > 0)
      cv::erode(mask, inner, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * inset + 1, 2 * inset + 1}),
                {-1, -1}, 1, cv::BORDER_CONSTANT, 0);
    else
      inner = mask;
    sew_sections(fill_sections(inner, angle + CV_PI / 2, 3 * spacing, max_px, 1), sink);
  }
  sew_sections(fill_sections(mask, angle, spacing, max_px, params.fill_stagger), sink);
}

std::vector<StitchPoint> fill_region(const cv::Mat1b& mask, cv::Point2f offset_px, double angle,
                                     const StitchParams& params) {
  const double ppm = params.px_per_mm;
  InsideTravel travel(mask, std::max(2.0, 0.5 * ppm));
  StitchSink sink(&travel, params.fill_max_stitch_mm * ppm, params.trim_jump_mm * ppm);
  fill_into(mask, angle, params, sink);
  return sink.to_mm(offset_px, ppm);
}

}  // namespace atelier::embroidery

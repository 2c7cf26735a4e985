// Thread coverage: capsules rasterised row by row, counted on the region's mask.
#include "algorithms/embroidery/coverage.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core/utility.hpp>

#include "algorithms/embroidery/fill_stitches.h"
#include "algorithms/embroidery/running_stitches.h"
#include "algorithms/embroidery/satin_stitches.h"

namespace atelier::embroidery {

void draw_thread(cv::Mat1b& canvas, cv::Point2f a, cv::Point2f b, double r) {
  if (canvas.empty() || !(r > 0)) return;
  const double ax = a.x, ay = a.y, bx = b.x, by = b.y;
  if (!std::isfinite(ax) || !std::isfinite(ay) || !std::isfinite(bx) || !std::isfinite(by)) return;
  const double dx = bx - ax, dy = by - ay, len = std::hypot(dx, dy);
  // The capsule's rectangle: corners a +- r n, b +- r n (none when the segment is a point).
  double cx[4], cy[4];
  const bool rect = len > 1e-9;
  if (rect) {
    const double nx = -dy / len * r, ny = dx / len * r;
    cx[0] = ax + nx, cy[0] = ay + ny;
    cx[1] = bx + nx, cy[1] = by + ny;
    cx[2] = bx - nx, cy[2] = by - ny;
    cx[3] = ax - nx, cy[3] = ay - ny;
  }
  const int y0 = std::max(0, static_cast<int>(std::ceil(std::min(ay, by) - r)));
  const int y1 = std::min(canvas.rows - 1, static_cast<int>(std::floor(std::max(ay, by) + r)));
  for (int y = y0; y <= y1; ++y) {  // bounded by the canvas's rows
    double lo = 1e300, hi = -1e300;
    for (const auto& [px, py] : {std::pair{ax, ay}, std::pair{bx, by}}) {  // end discs
      const double h2 = r * r - (y - py) * (y - py);
      if (h2 < 0) continue;
      const double h = std::sqrt(h2);
      lo = std::min(lo, px - h), hi = std::max(hi, px + h);
    }
    if (rect)  // the row against the rectangle's four edges
      for (int e = 0; e < 4; ++e) {
        const double x0 = cx[e], yy0 = cy[e], x1 = cx[(e + 1) % 4], yy1 = cy[(e + 1) % 4];
        if ((y < std::min(yy0, yy1)) || (y > std::max(yy0, yy1))) continue;
        const double x = std::abs(yy1 - yy0) < 1e-12 ? x0 : x0 + (x1 - x0) * (y - yy0) / (yy1 - yy0);
        lo = std::min(lo, std::abs(yy1 - yy0) < 1e-12 ? std::min(x0, x1) : x);
        hi = std::max(hi, std::abs(yy1 - yy0) < 1e-12 ? std::max(x0, x1) : x);
      }
    if (lo > hi) continue;
    const int x0 = std::max(0, static_cast<int>(std::ceil(lo - 1e-9)));
    const int x1 = std::min(canvas.cols - 1, static_cast<int>(std::floor(hi + 1e-9)));
    if (x0 <= x1) std::fill(canvas.ptr<uchar>(y) + x0, canvas.ptr<uchar>(y) + x1 + 1, uchar(255));
  }
}

cv::Mat1b thread_pixels(cv::Size size, const std::vector<StitchPoint>& pts, cv::Point2f offset_px, double px_per_mm,
                        double radius_mm) {
  cv::Mat1b canvas(size, uchar(0));
  auto px = [&](const StitchPoint& p) {
    return cv::Point2f(static_cast<float>(p.x_mm * px_per_mm - offset_px.x),
                       static_cast<float>(p.y_mm * px_per_mm - offset_px.y));
  };
  for (size_t i = 1; i < pts.size(); ++i)
    if (pts[i].kind == StitchKind::stitch && pts[i - 1].kind == StitchKind::stitch)
      draw_thread(canvas, px(pts[i - 1]), px(pts[i]), radius_mm * px_per_mm);
  return canvas;
}

double region_coverage(const cv::Mat1b& mask, const std::vector<StitchPoint>& pts, cv::Point2f offset_px,
                       double px_per_mm, double radius_mm) {
  const int area = cv::countNonZero(mask);
  if (area == 0) return 1.0;
  const cv::Mat1b sewn = thread_pixels(mask.size(), pts, offset_px, px_per_mm, radius_mm);
  return static_cast<double>(cv::countNonZero(sewn & mask)) / area;
}

std::vector<StitchPoint> region_stitches(const Region& reg, double direction, const StitchParams& params) {
  if (reg.mask.empty() || cv::countNonZero(reg.mask) == 0) return {};
  switch (reg.style) {
    case Style::long_short: return fill_region(reg.mask, {0, 0}, direction, params);
    case Style::satin: return satin_region(reg.mask, {0, 0}, direction, params);
    case Style::edge: return edge_region(reg.mask, {0, 0}, direction, params);
  }
  return {};
}

std::vector<RegionCoverage> regions_coverage(const Segmentation& seg,
                                             const std::vector<std::vector<StitchPoint>>& stitches,
                                             const std::vector<cv::Point2f>& offset_px, double px_per_mm) {
  const size_t n = std::min(seg.regions.size(), stitches.size());
  std::vector<RegionCoverage> out(n);
  cv::parallel_for_(cv::Range(0, static_cast<int>(n)), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      const Region& reg = seg.regions[i];
      const cv::Point2f off = offset_px.empty() ? cv::Point2f(0, 0) : offset_px[i];
      out[i] = {i, reg.style, cv::countNonZero(reg.mask) / (px_per_mm * px_per_mm),
                region_coverage(reg.mask, stitches[i], off, px_per_mm)};
    }
  });
  return out;
}

std::vector<RegionCoverage> design_coverage(const Segmentation& seg, const std::vector<double>& directions,
                                            const StitchParams& params) {
  std::vector<std::vector<StitchPoint>> stitches(seg.regions.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(seg.regions.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i)
      stitches[i] = region_stitches(seg.regions[i], i < static_cast<int>(directions.size()) ? directions[i] : 0.0,
                                    params);
  });
  return regions_coverage(seg, stitches, {}, params.px_per_mm);
}

std::array<StyleCoverage, kStyleCount> coverage_by_style(const std::vector<RegionCoverage>& regions,
                                                         double min_area_mm2, double threshold) {
  std::array<StyleCoverage, kStyleCount> out{};
  std::array<double, kStyleCount> sum{};
  for (const RegionCoverage& r : regions) {
    if (r.area_mm2 <= min_area_mm2) continue;
    StyleCoverage& s = out[static_cast<int>(r.style)];
    s.min = s.regions == 0 ? r.coverage : std::min(s.min, r.coverage);
    ++s.regions;
    sum[static_cast<int>(r.style)] += r.coverage;
    s.below += r.coverage < threshold;
  }
  for (int k = 0; k < kStyleCount; ++k)
    if (out[k].regions > 0) out[k].mean = sum[k] / out[k].regions;
  return out;
}

}  // namespace atelier::embroidery

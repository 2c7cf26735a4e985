// Helpers shared by the stitch tests (fill, satin, running stitches, planner): test images at
// 8 px per mm, stitch points back in pixels, the thread drawn, coverage, lengths and trims.
#pragma once

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <vector>

#include "algorithms/embroidery/stitch_planner.h"

namespace atelier::embroidery::test {

inline constexpr double kPpm = 8;  // test images: 8 px per mm

inline StitchParams params8() {
  StitchParams p;
  p.px_per_mm = kPpm;
  p.hoop_width_mm = p.hoop_height_mm = 200;
  return p;
}

// Stitch points back in mask pixels (region-level functions get offset 0).
inline std::vector<cv::Point2f> to_px(const std::vector<StitchPoint>& pts, StitchKind kind = StitchKind::stitch) {
  std::vector<cv::Point2f> out;
  for (const StitchPoint& p : pts)
    if (p.kind == kind) out.emplace_back(static_cast<float>(p.x_mm * kPpm), static_cast<float>(p.y_mm * kPpm));
  return out;
}

// The thread laid between consecutive needle penetrations, drawn `thickness` px wide.
inline cv::Mat1b rasterise(const std::vector<StitchPoint>& pts, cv::Size size, int thickness) {
  cv::Mat1b canvas(size, uchar(0));
  const int shift = 4;
  auto fx = [&](double mm) { return static_cast<int>(std::lround(mm * kPpm * (1 << shift))); };
  for (size_t i = 1; i < pts.size(); ++i) {
    if (pts[i].kind != StitchKind::stitch || !is_positioned(pts[i - 1].kind)) continue;
    cv::line(canvas, {fx(pts[i - 1].x_mm), fx(pts[i - 1].y_mm)}, {fx(pts[i].x_mm), fx(pts[i].y_mm)}, 255, thickness,
             cv::LINE_8, shift);
  }
  return canvas;
}

inline double coverage(const cv::Mat1b& mask, const cv::Mat1b& sewn) {
  return static_cast<double>(cv::countNonZero(mask & sewn)) / cv::countNonZero(mask);
}

// Largest distance (px) from a needle point to the nearest mask pixel centre (1e9 when none
// is within 8 px).
inline double worst_outside(const cv::Mat1b& mask, const std::vector<StitchPoint>& pts) {
  double worst = 0;
  for (const cv::Point2f& p : to_px(pts)) {
    double nearest = 1e9;
    for (int y = cvFloor(p.y) - 8; y <= cvCeil(p.y) + 8; ++y)
      for (int x = cvFloor(p.x) - 8; x <= cvCeil(p.x) + 8; ++x)
        if (x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && mask(y, x))
          nearest = std::min(nearest, cv::norm(p - cv::Point2f(x, y)));
    worst = std::max(worst, nearest);
  }
  return worst;
}

// Length (mm) of each stitch: consecutive positioned points where the second is a stitch.
inline std::vector<double> stitch_lengths(const std::vector<StitchPoint>& pts) {
  std::vector<double> out;
  const StitchPoint* prev = nullptr;
  for (const StitchPoint& p : pts) {
    if (!is_positioned(p.kind)) continue;
    if (prev && p.kind == StitchKind::stitch) out.push_back(std::hypot(p.x_mm - prev->x_mm, p.y_mm - prev->y_mm));
    prev = &p;
  }
  return out;
}

// Every run of jumps longer than trim_jump_mm in total starts right after a trim (or after a
// colour change that follows a trim); the very first move from the machine's start is exempt.
inline void expect_long_jumps_trimmed(const std::vector<StitchPoint>& pts, double trim_jump_mm) {
  const StitchPoint* last_pos = nullptr;
  bool started = false;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (pts[i].kind != StitchKind::jump) {
      if (pts[i].kind == StitchKind::stitch) started = true;
      if (is_positioned(pts[i].kind)) last_pos = &pts[i];
      continue;
    }
    size_t j = i;
    double len = 0;
    const StitchPoint* from = last_pos;
    while (j < pts.size() && pts[j].kind == StitchKind::jump) {
      if (from) len += std::hypot(pts[j].x_mm - from->x_mm, pts[j].y_mm - from->y_mm);
      from = &pts[j];
      ++j;
    }
    if (started && len > trim_jump_mm) {
      ASSERT_GT(i, 0u);
      const StitchKind before = pts[i - 1].kind;
      const bool trimmed = before == StitchKind::trim ||
                           (before == StitchKind::color_change && i >= 2 && pts[i - 2].kind == StitchKind::trim);
      EXPECT_TRUE(trimmed) << "untrimmed jump of " << len << " mm at point " << i;
    }
    last_pos = from;
    i = j - 1;
  }
}

}  // namespace atelier::embroidery::test

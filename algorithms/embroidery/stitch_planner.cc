// All regions -> one StitchPlan: per-region stitches in parallel, then colour blocks, layers,
// nearest-first order, trims and jumps, hoop check.
#include "algorithms/embroidery/stitch_planner.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core/utility.hpp>

#include "algorithms/embroidery/fill_stitches.h"
#include "algorithms/embroidery/running_stitches.h"
#include "algorithms/embroidery/satin_stitches.h"

namespace atelier::embroidery {
namespace {

void check_params(const Segmentation& seg, const std::vector<double>& directions, const StitchParams& p) {
  auto positive = [](double v, const char* name) {
    if (!(v > 0) || !std::isfinite(v)) throw std::invalid_argument(std::string("stitch params: ") + name + " must be > 0");
  };
  positive(p.px_per_mm, "px_per_mm");
  positive(p.fill_row_spacing_mm, "fill_row_spacing_mm");
  positive(p.fill_max_stitch_mm, "fill_max_stitch_mm");
  positive(p.satin_spacing_mm, "satin_spacing_mm");
  positive(p.satin_max_mm, "satin_max_mm");
  positive(p.running_stitch_mm, "running_stitch_mm");
  positive(p.hoop_width_mm, "hoop_width_mm");
  positive(p.hoop_height_mm, "hoop_height_mm");
  if (p.fill_max_stitch_mm > 12.1 || p.running_stitch_mm > 12.1)
    throw std::invalid_argument("stitch params: stitches longer than 12.1 mm cannot be written (DST)");
  if (directions.size() != seg.regions.size())
    throw std::invalid_argument("plan_stitches: one direction per region expected");
}

int layer(Style s) { return static_cast<int>(s); }  // long_short 0, satin 1, edge 2

std::uint32_t rgb(const cv::Vec3b& bgr) {
  return (static_cast<std::uint32_t>(bgr[2]) << 16) | (static_cast<std::uint32_t>(bgr[1]) << 8) | bgr[0];
}

// Lock stitches (as digitizers add them): thread that starts after a jump or ends at a trim,
// colour change or the end would pull out. A tie goes back along the last (or ahead along the
// next) stitch by up to kTieMm and returns, so it stays on thread already in the region.
constexpr double kTieMm = 0.5;

StitchPoint toward(const StitchPoint& from, const StitchPoint& to) {
  const double len = std::hypot(to.x_mm - from.x_mm, to.y_mm - from.y_mm);
  const double t = len > kTieMm ? kTieMm / len : 1.0;
  return {from.x_mm + (to.x_mm - from.x_mm) * t, from.y_mm + (to.y_mm - from.y_mm) * t, StitchKind::stitch};
}

std::vector<StitchPoint> with_ties(const std::vector<StitchPoint>& in) {
  std::vector<StitchPoint> out;
  out.reserve(in.size() + in.size() / 8);
  for (size_t i = 0; i < in.size(); ++i) {
    const StitchPoint& p = in[i];
    const bool ends_thread = p.kind == StitchKind::trim || p.kind == StitchKind::color_change || p.kind == StitchKind::end;
    if (ends_thread && out.size() >= 2 && out.back().kind == StitchKind::stitch &&
        out[out.size() - 2].kind == StitchKind::stitch) {
      const StitchPoint last = out.back(), before = out[out.size() - 2];
      if (std::hypot(last.x_mm - before.x_mm, last.y_mm - before.y_mm) > 1e-6) {
        out.push_back(toward(last, before));
        out.push_back(last);
      }
    }
    out.push_back(p);
    // The first stitch after a jump: tie in towards the next stitch.
    if (p.kind == StitchKind::stitch && i > 0 && in[i - 1].kind == StitchKind::jump && i + 1 < in.size() &&
        in[i + 1].kind == StitchKind::stitch &&
        std::hypot(in[i + 1].x_mm - p.x_mm, in[i + 1].y_mm - p.y_mm) > 1e-6) {
      out.push_back(toward(p, in[i + 1]));
      out.push_back(p);
    }
  }
  return out;
}

}  // namespace

StitchPlan plan_stitches(const Segmentation& seg, const std::vector<double>& directions, const StitchParams& params) {
  check_params(seg, directions, params);
  const size_t n = seg.regions.size();
  const cv::Point2f centre((seg.size.width - 1) / 2.0f, (seg.size.height - 1) / 2.0f);

  // Each region's stitches on its own (regions are independent; the order comes later).
  // Costliest first (box area; thinning makes satin and edge dearer per pixel) so a large
  // region does not start last on one thread while the other idles.
  std::vector<int> by_cost(n);
  std::vector<double> cost(n);
  for (size_t i = 0; i < n; ++i) {
    by_cost[i] = static_cast<int>(i);
    cost[i] = static_cast<double>(seg.regions[i].mask.total()) * (seg.regions[i].style == Style::long_short ? 1 : 4);
  }
  std::stable_sort(by_cost.begin(), by_cost.end(), [&](int a, int b) { return cost[a] > cost[b]; });
  std::vector<std::vector<StitchPoint>> stitches(n);
  cv::parallel_for_(cv::Range(0, static_cast<int>(n)), [&](const cv::Range& r) {
    for (int k = r.start; k < r.end; ++k) {
      const int i = by_cost[k];
      const Region& reg = seg.regions[i];
      if (reg.mask.empty() || cv::countNonZero(reg.mask) == 0) continue;
      const cv::Point2f offset = cv::Point2f(static_cast<float>(reg.bbox.x), static_cast<float>(reg.bbox.y)) - centre;
      switch (reg.style) {
        case Style::long_short: stitches[i] = fill_region(reg.mask, offset, directions[i], params); break;
        case Style::satin: stitches[i] = satin_region(reg.mask, offset, directions[i], params); break;
        case Style::edge: stitches[i] = edge_region(reg.mask, offset, directions[i], params); break;
      }
    }
  });

  // Colour blocks in order of first use, regions taken layer by layer.
  std::vector<int> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = static_cast<int>(i);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return layer(seg.regions[a].style) < layer(seg.regions[b].style); });
  std::vector<int> colours;
  for (int i : order)
    if (!stitches[i].empty() && std::find(colours.begin(), colours.end(), seg.regions[i].color) == colours.end())
      colours.push_back(seg.regions[i].color);

  StitchPlan plan;
  auto& out = plan.points;
  bool have_pos = false;
  StitchPoint cur{0, 0, StitchKind::jump};
  for (size_t b = 0; b < colours.size(); ++b) {
    const int colour = colours[b];
    const cv::Vec3b bgr = colour >= 0 && colour < static_cast<int>(seg.palette.bgr.size()) ? seg.palette.bgr[colour]
                                                                                          : cv::Vec3b(0, 0, 0);
    plan.colors_rgb.push_back(rgb(bgr));
    bool block_start = true;
    for (int l = 0; l < kStyleCount; ++l) {
      std::vector<int> remaining;
      for (int i : order)
        if (seg.regions[i].color == colour && layer(seg.regions[i].style) == l && !stitches[i].empty())
          remaining.push_back(i);
      while (!remaining.empty()) {
        // Nearest region start from the needle (squared distances: this scan is quadratic in
        // a colour's region count and runs on one thread).
        size_t best = 0;
        double best_d2 = 1e36;
        for (size_t t = 0; t < remaining.size(); ++t) {
          const StitchPoint& s = stitches[remaining[t]].front();
          const double dx = s.x_mm - cur.x_mm, dy = s.y_mm - cur.y_mm, d2 = dx * dx + dy * dy;
          if (d2 < best_d2) best_d2 = d2, best = t;
        }
        const double best_d = std::sqrt(best_d2);
        const std::vector<StitchPoint>& seq = stitches[remaining[best]];
        remaining.erase(remaining.begin() + static_cast<long>(best));
        const StitchPoint& first = seq.front();
        if (have_pos && block_start) {
          out.push_back({cur.x_mm, cur.y_mm, StitchKind::trim});
          out.push_back({cur.x_mm, cur.y_mm, StitchKind::color_change});
          out.push_back({first.x_mm, first.y_mm, StitchKind::jump});
        } else if (!have_pos) {
          out.push_back({first.x_mm, first.y_mm, StitchKind::jump});  // from the machine's start point
        } else if (best_d > params.trim_jump_mm) {
          out.push_back({cur.x_mm, cur.y_mm, StitchKind::trim});
          out.push_back({first.x_mm, first.y_mm, StitchKind::jump});
        }
        // A short move is the region's first stitch itself.
        block_start = false;
        out.insert(out.end(), seq.begin(), seq.end());
        for (auto it = seq.rbegin(); it != seq.rend(); ++it)
          if (is_positioned(it->kind)) {
            cur = *it;
            break;
          }
        have_pos = true;
      }
    }
  }
  out.push_back({0, 0, StitchKind::end});
  out = with_ties(out);

  const StitchStats st = stitch_stats(plan);
  const double w = st.max_x_mm - st.min_x_mm, h = st.max_y_mm - st.min_y_mm;
  if (w > params.hoop_width_mm || h > params.hoop_height_mm) {
    char msg[160];
    std::snprintf(msg, sizeof msg, "design is %.1f x %.1f mm, the hoop is %.1f x %.1f mm", w, h, params.hoop_width_mm,
                  params.hoop_height_mm);
    throw HoopTooSmall(msg);
  }
  return plan;
}

}  // namespace atelier::embroidery

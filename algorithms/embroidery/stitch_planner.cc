// All regions -> one StitchPlan: per-region stitches in parallel, then colour blocks, layers,
// nearest-first order, hidden travel or trims and jumps, runs cleaned and tied, hoop check.
#include "algorithms/embroidery/stitch_planner.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core/utility.hpp>

#include "algorithms/embroidery/fill_stitches.h"
#include "algorithms/embroidery/running_stitches.h"
#include "algorithms/embroidery/satin_stitches.h"
#include "algorithms/embroidery/ties.h"
#include "algorithms/embroidery/travel.h"

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
  if (!(p.min_stitch_mm >= 0) || p.min_stitch_mm >= std::min(p.fill_max_stitch_mm, p.running_stitch_mm))
    throw std::invalid_argument("stitch params: min_stitch_mm must be >= 0 and below every stitch length");
  if (p.fill_max_stitch_mm > 12.1 || p.running_stitch_mm > 12.1)
    throw std::invalid_argument("stitch params: stitches longer than 12.1 mm cannot be written (DST)");
  if (directions.size() != seg.regions.size())
    throw std::invalid_argument("plan_stitches: one direction per region expected");
}

int layer(Style s) { return static_cast<int>(s); }  // long_short 0, satin 1, edge 2

std::uint32_t rgb(const cv::Vec3b& bgr) {
  return (static_cast<std::uint32_t>(bgr[2]) << 16) | (static_cast<std::uint32_t>(bgr[1]) << 8) | bgr[0];
}

// A hidden travel longer than this is not worth it: about the machine time of a trim (a
// trim and its ties take some seconds, 100 mm of 1.5 mm running stitches as long).
constexpr double kMaxHiddenTravelMm = 100;
// Regions tried for a hidden way before the nearest is taken with a trim.
constexpr size_t kCandidates = 8;

// One continuous thread: needle points from its first (where a jump brings the needle) to
// its last (where the thread is cut, changed or ends).
struct Run {
  std::vector<cv::Point2d> pts;
  int block;
};

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

  std::vector<int> block_of(n, -1);
  for (size_t i = 0; i < n; ++i)
    if (!stitches[i].empty())
      block_of[i] = static_cast<int>(std::find(colours.begin(), colours.end(), seg.regions[i].color) - colours.begin());
  // Per design pixel: the block that sews it (regions tile the sewn pixels), -1 = fabric.
  // Fills and satins cover their pixels; an edge region's running stitch does not.
  cv::Mat1i block_px(seg.size, -1);
  cv::Mat1b covers(seg.size, uchar(0));
  for (size_t i = 0; i < n; ++i)
    if (block_of[i] >= 0) {
      const Region& reg = seg.regions[i];
      const cv::Rect r = reg.bbox & cv::Rect(0, 0, seg.size.width, seg.size.height);
      if (static_cast<size_t>(r.area()) != reg.mask.total()) continue;
      block_px(r).setTo(block_of[i], reg.mask);
      if (reg.style != Style::edge) covers(r).setTo(255, reg.mask);
    }
  HiddenTravel hidden(block_px, covers, params.px_per_mm, 0.5);

  // Colour blocks -> runs. Inside a block the needle moves hidden (under pixels this block or
  // a later one sews) where it can, else straight when the move is at most trim_jump_mm,
  // else a new run starts (a trim and a jump).
  std::vector<Run> runs;
  cv::Point2d needle(0, 0);  // the machine's start point, then the last needle point
  std::vector<cv::Point2d> path;
  for (size_t b = 0; b < colours.size(); ++b) {
    hidden.begin_block(static_cast<int>(b));
    bool open = false;  // runs.back() is this block's and may go on
    auto add = [&](cv::Point2d p) {
      runs.back().pts.push_back(p);
      needle = p;
    };
    auto move_to = [&](cv::Point2d p) {
      const double d = open ? cv::norm(p - needle) : 0;
      if (open && d < 1e-9) return;
      if (open && hidden.path(needle, p, path) && run_length(path) <= kMaxHiddenTravelMm) {
        const double run_mm = params.running_stitch_mm;
        for (size_t k = 1; k < path.size(); ++k) {
          const cv::Point2d a = needle, q = path[k];
          const int steps = std::max(1, static_cast<int>(std::ceil(cv::norm(q - a) / run_mm - kLengthTolerance)));
          for (int t = 1; t <= steps; ++t) add(a + (q - a) * (static_cast<double>(t) / steps));
        }
        return;
      }
      if (open && d <= params.trim_jump_mm) {
        add(p);  // one short stitch, shown: a trim would cost more than it hides
        return;
      }
      runs.push_back({{}, static_cast<int>(b)});
      open = true;
      add(p);
    };
    for (int l = 0; l < kStyleCount; ++l) {
      std::vector<int> remaining;
      for (int i : order)
        if (block_of[i] == static_cast<int>(b) && layer(seg.regions[i].style) == l) remaining.push_back(i);
      while (!remaining.empty()) {
        // The nearest region start from the needle that hidden travel reaches, among the
        // kCandidates nearest; else the nearest (a trim). Distances are a scan, quadratic in
        // a colour's region count on one thread (a few thousand regions: milliseconds); at
        // most kCandidates searches per region.
        std::vector<std::pair<double, size_t>> near;
        near.reserve(remaining.size());
        for (size_t t = 0; t < remaining.size(); ++t) {
          const StitchPoint& s = stitches[remaining[t]].front();
          const double dx = s.x_mm - needle.x, dy = s.y_mm - needle.y;
          near.emplace_back(dx * dx + dy * dy, t);
        }
        const size_t k = std::min(near.size(), kCandidates);
        std::partial_sort(near.begin(), near.begin() + static_cast<long>(k), near.end());
        size_t best = near[0].second;
        if (open && near[0].first > params.trim_jump_mm * params.trim_jump_mm)
          for (size_t c = 0; c < k; ++c) {
            const StitchPoint& s = stitches[remaining[near[c].second]].front();
            if (hidden.path(needle, {s.x_mm, s.y_mm}, path) && run_length(path) <= kMaxHiddenTravelMm) {
              best = near[c].second;
              break;
            }
          }
        const std::vector<StitchPoint>& seq = stitches[remaining[best]];
        remaining.erase(remaining.begin() + static_cast<long>(best));
        // The region's own trims become moves too: a jump inside a region may have a hidden
        // way round through its neighbours.
        bool moving = true;
        for (const StitchPoint& q : seq) {
          const cv::Point2d p(q.x_mm, q.y_mm);
          if (q.kind == StitchKind::jump) {
            move_to(p);
            moving = false;
          } else if (q.kind == StitchKind::stitch) {
            if (moving) move_to(p);
            else add(p);  // in place after a jump: dropped below as a tiny stitch
            moving = false;
          }
        }
      }
    }
  }

  // Runs -> points: tiny stitches dropped, ties at both ends, trims, colour changes, jumps.
  StitchPlan plan;
  auto& out = plan.points;
  int emitted_block = -1;
  for (Run& run : runs) {
    drop_tiny_stitches(run.pts, params.min_stitch_mm);
    const std::vector<cv::Point2d> in = tie_in(run.pts, params.min_stitch_mm);
    if (in.empty()) continue;  // all of it within min_stitch_mm of one point: nothing to sew
    const std::vector<cv::Point2d> off = tie_off(run.pts, params.min_stitch_mm);
    const cv::Point2d first = run.pts.front();
    if (run.block != emitted_block) {
      if (emitted_block >= 0) {
        out.push_back({needle.x, needle.y, StitchKind::trim});
        out.push_back({needle.x, needle.y, StitchKind::color_change});
      }
      const int colour = colours[run.block];
      const cv::Vec3b bgr = colour >= 0 && colour < static_cast<int>(seg.palette.bgr.size()) ? seg.palette.bgr[colour]
                                                                                            : cv::Vec3b(0, 0, 0);
      plan.colors_rgb.push_back(rgb(bgr));
      emitted_block = run.block;
    } else {
      out.push_back({needle.x, needle.y, StitchKind::trim});
    }
    out.push_back({first.x, first.y, StitchKind::jump});
    // The jump's end is the tie-in's home; the needle first goes down on its way out.
    for (const cv::Point2d& p : in) out.push_back({p.x, p.y, StitchKind::stitch});
    for (size_t k = 1; k < run.pts.size(); ++k) out.push_back({run.pts[k].x, run.pts[k].y, StitchKind::stitch});
    for (const cv::Point2d& p : off) out.push_back({p.x, p.y, StitchKind::stitch});
    needle = run.pts.back();
  }
  out.push_back({0, 0, StitchKind::end});

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

// A machine-independent stitch sequence, as the embroidery planner produces it and the
// stitch-file writers (dst_writer.h, exp_writer.h) consume it.
// Units: millimetres, absolute positions in the image frame (x right, y DOWN). The machine's
// start point (the hoop's needle position when sewing begins) is the plan's origin (0, 0): a
// planner that wants the design centred on the hoop puts the origin at the design's centre.
// Value types; pure functions, thread-safe.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace atelier::embroidery {

enum class StitchKind {
  stitch,        // needle goes down at (x_mm, y_mm)
  jump,          // frame moves to (x_mm, y_mm) without a needle penetration
  trim,          // cut the thread here; position ignored
  color_change,  // stop for the next thread; position ignored
  end            // end of design; position ignored; optional, and only as the last point
};

struct StitchPoint {
  double x_mm = 0, y_mm = 0;
  StitchKind kind = StitchKind::stitch;
};

struct StitchPlan {
  std::string name;                      // design label (DST keeps 16 ASCII characters)
  std::vector<StitchPoint> points;
  std::vector<std::uint32_t> colors_rgb;  // thread per colour block, 0xRRGGBB; informative
                                          // only: DST and EXP carry no colours
};

// Counts of plan points by kind, and the extents of the positioned points (stitch, jump) in mm,
// image frame. Extents are 0 when the plan has no positioned point.
struct StitchStats {
  int stitches = 0, jumps = 0, trims = 0, color_changes = 0;
  double min_x_mm = 0, max_x_mm = 0, min_y_mm = 0, max_y_mm = 0;
};

inline bool is_positioned(StitchKind k) { return k == StitchKind::stitch || k == StitchKind::jump; }

inline StitchStats stitch_stats(const StitchPlan& plan) {
  StitchStats s;
  bool any = false;
  for (const StitchPoint& p : plan.points) {
    switch (p.kind) {
      case StitchKind::stitch: ++s.stitches; break;
      case StitchKind::jump: ++s.jumps; break;
      case StitchKind::trim: ++s.trims; break;
      case StitchKind::color_change: ++s.color_changes; break;
      case StitchKind::end: break;
    }
    if (!is_positioned(p.kind)) continue;
    if (!any) {
      s.min_x_mm = s.max_x_mm = p.x_mm;
      s.min_y_mm = s.max_y_mm = p.y_mm;
      any = true;
    }
    s.min_x_mm = std::min(s.min_x_mm, p.x_mm);
    s.max_x_mm = std::max(s.max_x_mm, p.x_mm);
    s.min_y_mm = std::min(s.min_y_mm, p.y_mm);
    s.max_y_mm = std::max(s.max_y_mm, p.y_mm);
  }
  return s;
}

// Throws std::invalid_argument when a positioned point is not finite or lies farther than
// 10 m from the origin (no machine sews that; it would overflow the files' counters), or when
// an `end` point is followed by anything. Writers call this before writing a byte.
inline void validate_plan(const StitchPlan& plan) {
  constexpr double kMaxMm = 10000.0;
  for (size_t i = 0; i < plan.points.size(); ++i) {
    const StitchPoint& p = plan.points[i];
    if (p.kind == StitchKind::end && i + 1 != plan.points.size())
      throw std::invalid_argument("stitch plan: 'end' at point " + std::to_string(i) +
                                  " is not the last point");
    if (!is_positioned(p.kind)) continue;
    if (!std::isfinite(p.x_mm) || !std::isfinite(p.y_mm))
      throw std::invalid_argument("stitch plan: point " + std::to_string(i) +
                                  " has a non-finite coordinate");
    if (std::abs(p.x_mm) > kMaxMm || std::abs(p.y_mm) > kMaxMm)
      throw std::invalid_argument("stitch plan: point " + std::to_string(i) +
                                  " lies more than 10 m from the origin");
  }
}

// For the writers: file units are 0.1 mm with +y up (DST and EXP both flip the image's y).
// Positions are rounded, never moves, so the rounding never accumulates into drift.
struct FileUnits {
  long x = 0, y = 0;
};
inline FileUnits to_file_units(const StitchPoint& p) {
  return {std::lround(p.x_mm * 10.0), -std::lround(p.y_mm * 10.0)};
}

// Splits the move (dx, dy) into the fewest equal steps each within +-max_units on both axes;
// the steps sum exactly to (dx, dy). A zero move is one zero step (a stitch in place is a tie).
inline std::vector<FileUnits> split_move(long dx, long dy, long max_units) {
  const long longest = std::max(std::abs(dx), std::abs(dy));
  const long n = std::max(1L, (longest + max_units - 1) / max_units);
  std::vector<FileUnits> steps;
  steps.reserve(static_cast<size_t>(n));
  long px = 0, py = 0;
  for (long i = 1; i <= n; ++i) {
    // Truncated positions along the line: consecutive ones differ by at most
    // ceil(|d| / n) <= max_units, and the last is exactly (dx, dy).
    const long x = dx * i / n, y = dy * i / n;
    steps.push_back({x - px, y - py});
    px = x;
    py = y;
  }
  return steps;
}

}  // namespace atelier::embroidery

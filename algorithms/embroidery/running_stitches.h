// Running stitches and travel inside a region, and the building block every region's stitch
// generator appends to (StitchSink).
// Units: the region mask's pixel frame (x right, y down; a pixel's centre is its integer
// coordinate) until StitchSink::to_mm converts to the plan's millimetres.
// Value types; no shared state; thread-compatible (one sink per thread).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "algorithms/embroidery/stitch_plan.h"

namespace atelier::embroidery {

struct StitchParams;

// Shortest-ish paths that stay inside a region: straight when the segment stays on mask
// pixels, otherwise a breadth-first search on a grid of cells wholly inside the mask
// (cell_px wide), shortened by line of sight. The mask must outlive the object. Not
// thread-safe: path() reuses a scratch buffer (one object per region and thread).
class InsideTravel {
 public:
  InsideTravel(const cv::Mat1b& mask, double cell_px);
  // The path from a to b (both included), or false when none was found (a neck narrower
  // than a cell, or a or b out of sight of every nearby inside cell).
  // margin_cells >= 0 limits the search to the cells' box around a and b grown by that many
  // cells (the planner's design-wide searches stay near the move); -1: the whole grid.
  bool path(cv::Point2f a, cv::Point2f b, std::vector<cv::Point2f>& out, int margin_cells = -1) const;
  bool line_inside(cv::Point2f a, cv::Point2f b) const;

 private:
  const cv::Mat1b& mask_;
  int cell_;
  cv::Mat1b inside_;  // per cell: 255 when every pixel of the cell is inside the mask
  // Search scratch: a cell's parent is valid when its stamp is the current search's.
  mutable std::vector<int> parent_;
  mutable std::vector<unsigned> stamp_;
  mutable unsigned search_ = 0;
  bool nearest_cell(cv::Point2f p, cv::Point& cell) const;
};

// Relative slack when a run is cut into stitches of at most max_px: a run up to
// max_px * (1 + kLengthTolerance) is one stitch (float32 points cannot be exact).
inline constexpr double kLengthTolerance = 1e-4;

// One region's needle sequence, built in mask pixels.
class StitchSink {
 public:
  // max_px: longest running stitch (split longer runs); trim_jump_px: a travel with no inside
  // path that is longer than this becomes trim + jump, a shorter one runs straight.
  StitchSink(const InsideTravel* travel, double max_px, double trim_jump_px)
      : travel_(travel), max_px_(max_px), trim_jump_px_(trim_jump_px) {}
  bool empty() const { return pts_.empty(); }
  cv::Point2f last() const { return pts_.back().p; }
  // One needle penetration at p, however far (satin spans).
  void stitch(cv::Point2f p);
  // A straight run to p, split into equal stitches of at most max_px (nothing when already there).
  void run(cv::Point2f p);
  // Runs through the polyline (its first point is run to as well).
  void run_along(const std::vector<cv::Point2f>& polyline);
  // Gets the needle to p: inside the region when possible (running stitches, later sewn over),
  // otherwise straight stitches (short) or trim + jump (long). The first call just stitches p.
  void travel_to(cv::Point2f p);
  // Millimetres: (p + offset_px) / px_per_mm.
  std::vector<StitchPoint> to_mm(cv::Point2f offset_px, double px_per_mm) const;

 private:
  struct Pt {
    cv::Point2f p;
    StitchKind kind;
  };
  const InsideTravel* travel_;
  double max_px_, trim_jump_px_;
  std::vector<Pt> pts_;
};

// Positions along `pixels` (in order) at most step_px apart, taken from the pixels
// themselves (so they stay on them), first and last included.
std::vector<cv::Point2f> resample_on_pixels(const std::vector<cv::Point2f>& pixels, double step_px);

// An edge region (a thin stroke): along each skeleton branch a running stitch of
// running_stitch_mm, or a narrow satin (zig-zag across the stroke, pull compensation, no
// split) when the stroke is at least edge_satin_min_mm wide. Branches are sewn nearest
// first with travel inside the stroke. A region too small to have a branch gets a small
// tatami fill at fallback_angle (radians). Returns the region's stitches in mm;
// offset_px is added to mask pixel coordinates before scaling (the planner passes the
// bounding box's corner minus the design's centre).
std::vector<StitchPoint> edge_region(const cv::Mat1b& mask, cv::Point2f offset_px, double fallback_angle,
                                     const StitchParams& params);

}  // namespace atelier::embroidery

// The design's machine stitches (issue 6 part 2): every region of a segmentation sewn in its
// style (tatami fill, satin columns, edge running stitch / narrow satin), ordered by colour
// and layer, joined by travel, with trims, colour changes and a hoop check.
// Units: StitchParams in millimetres (px_per_mm converts image pixels); the plan in mm with
// the origin at the image's centre, y down (stitch_plan.h).
// Pure; regions are stitched in parallel (cv::parallel_for_); thread-safe.
#pragma once

#include <stdexcept>
#include <vector>

#include "algorithms/embroidery/design.h"
#include "algorithms/embroidery/stitch_plan.h"
#include "base/error.h"

namespace atelier::embroidery {

struct StitchParams {
  double px_per_mm = 4;  // image pixels per mm of the design
  // fill (long-short regions): Ink/Stitch tatami defaults
  double fill_row_spacing_mm = 0.25, fill_max_stitch_mm = 3.0;
  int fill_stagger = 4;  // rows repeat their needle offsets every N rows
  // Underlay rows at fill angle + 90 deg, 3x the row spacing apart (Ink/Stitch's default
  // underlay spacing), on the region inset by 0.5 mm.
  bool fill_underlay = true;
  // satin
  double satin_spacing_mm = 0.4;     // zig-zag peak to peak (same side) along the column
  double satin_pull_comp_mm = 0.2;   // each side widened by this
  double satin_max_mm = 8.0;         // wider columns are split into parallel sub-columns
  bool satin_underlay = true;        // centre-walk underlay
  // edge
  double running_stitch_mm = 1.5;
  double edge_satin_min_mm = 1.0;  // strokes at least this wide get a narrow satin, thinner a running stitch
  // travel
  double trim_jump_mm = 3.0;  // moves longer than this with no hidden way: jump with a trim
  // Stitches this short or shorter are dropped (Ink/Stitch's default minimum stitch length);
  // tie stitches are never this short either.
  double min_stitch_mm = 0.1;
  double hoop_width_mm = 100, hoop_height_mm = 100;
};

class HoopTooSmall : public BadInput {
 public:
  using BadInput::BadInput;
};

// The design's stitches: colour blocks in palette order of first use (regions taken in layer
// order: long-short, then satin, then edge); inside a block the layers in that order and,
// within a layer, regions nearest first from the needle. Moves between regions, and a
// region's own jumps, are running stitches (running_stitch_mm) through pixels that this
// block sews or a later one covers with fill or satin (hidden: travel.h) when there is such
// a way of at most 100 mm,
// else one stitch when at most trim_jump_mm, else the thread is cut: trim and jump. Each
// run of thread (between a jump and the next trim, colour change or the end) has its
// stitches of min_stitch_mm or less dropped, then a tie-in and a tie-off (ties.h: four
// stitches of at most 0.75 mm along the run's own path); a run that would be nothing but
// ties (all of it within min_stitch_mm of one point) is left out. A colour block starts
// with trim, color_change and a jump; the plan ends with `end`. colors_rgb: one 0xRRGGBB
// per block. directions: radians per region, indexed like seg.regions (fill angle of
// long-short regions; satin and edge regions use theirs only when they are too small for
// a skeleton and are filled instead). Regions with an empty mask are skipped.
// Throws HoopTooSmall("design is W x H mm, the hoop is w x h mm") when the extent of the
// positioned points (max - min on each axis) exceeds the hoop; std::invalid_argument for
// non-positive px_per_mm, spacings or lengths, min_stitch_mm negative or not below the fill
// and running stitch lengths, or directions of the wrong size.
StitchPlan plan_stitches(const Segmentation& seg, const std::vector<double>& directions,
                         const StitchParams& params);

}  // namespace atelier::embroidery

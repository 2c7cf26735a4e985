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
  double trim_jump_mm = 3.0;  // moves longer than this inside no region: jump with a trim
  double hoop_width_mm = 100, hoop_height_mm = 100;
};

class HoopTooSmall : public BadInput {
 public:
  using BadInput::BadInput;
};

// The design's stitches: colour blocks in palette order of first use (regions taken in layer
// order: long-short, then satin, then edge); inside a block the layers in that order and,
// within a layer, regions nearest first from the needle. A move to the next region longer
// than trim_jump_mm is trim + jump (a zero-length stitch then anchors the thread), a shorter
// one is a stitch; a colour block starts with trim, color_change and a jump. The plan ends
// with `end`. Lock stitches: before every trim, colour change and the end the needle goes back
// 0.5 mm along the last stitch and returns; after every jump it goes 0.5 mm ahead along the
// next stitch and returns. colors_rgb: one 0xRRGGBB per block. directions: radians per region, indexed like
// seg.regions (fill angle of long-short regions; satin and edge regions use theirs only when
// they are too small for a skeleton and are filled instead). Regions with an empty mask are
// skipped.
// Throws HoopTooSmall("design is W x H mm, the hoop is w x h mm") when the extent of the
// positioned points (max - min on each axis) exceeds the hoop; std::invalid_argument for
// non-positive px_per_mm, spacings or lengths, or directions of the wrong size.
StitchPlan plan_stitches(const Segmentation& seg, const std::vector<double>& directions,
                         const StitchParams& params);

}  // namespace atelier::embroidery

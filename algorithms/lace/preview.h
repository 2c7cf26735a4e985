// A picture of the knitted lace fabric (issue 7, preview.png): the chart tiled, seen from the
// right side, each stitch drawn as a knit "V" on a dark cloth, yarn-overs as open holes,
// each decrease leaning its true way (symbols.h lean()): k2tog right, ssk and sk2p left, s2kp
// centred with a vertical spine (the centre stitch standing on top).
//
// Layout (the same conventions as chart.h): knitting-order index 0 of a row is at the RIGHT of
// the picture (the knitter works right to left on the right side); chart row 0 is at the
// bottom; each right-side row is followed by a plain wrong-side (purl) row, which shows as
// knit stitches on the right side. Horizontal stitch positions follow the stitch structure:
// a stitch sits at the mean x of the stitches it is worked over, a yarn-over halfway between
// its neighbours; then positions relax (65%) toward even spacing over the cast-on width
// (fabric stretches), so rows stay about as wide as the cast-on.
//
// Units: pixels; stitch_px is a stitch's width, a row is round(0.8 * stitch_px) high. Colours
// BGR. Pure functions, thread-safe; the returned image is owned by the caller.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "algorithms/lace/chart.h"

namespace atelier::lace {

struct PreviewOptions {
  int repeats_x = 3, repeats_y = 3;  // tiles side by side and stacked (>= 1)
  int stitch_px = 14;                // stitch width in pixels (>= 4); row height ~0.8 of it
  cv::Vec3b yarn{235, 235, 240};
  cv::Vec3b background{60, 45, 40};  // the dark cloth under the lace, seen through holes
};

// One stitch of the picture.
struct PlacedStitch {
  Symbol symbol = Symbol::k;
  cv::Point2d centre;  // pixels, in the returned picture
  int chart_row = -1;  // Chart::rows index, -1 for a wrong-side (purl) row
  int index = 0;       // knitting-order index in the (tiled) row
};

// Where render_preview draws each stitch: rows bottom to top (course 0 is the first RS row of
// the first vertical tile), each row in knitting order.
struct PreviewLayout {
  cv::Size size;  // picture size: cast_on * repeats_x * stitch_px wide,
                  // 2 * rows * tiles_y * row_px high
  int row_px = 0;
  int tiles_y = 0;  // repeats_y, or 1 when the chart does not end as wide as its cast-on
  std::vector<std::vector<PlacedStitch>> courses;
};

// The stitch positions. Throws std::invalid_argument when the chart is not knittable from
// cast_on or the options are out of range.
PreviewLayout layout_preview(const Chart& chart, int cast_on, const PreviewOptions& o = {});

// The picture (CV_8UC3). The chart is tiled repeats_x side by side (each row concatenated
// with itself) and repeats_y high when its last row is as wide as the cast-on (else once).
cv::Mat render_preview(const Chart& chart, int cast_on, const PreviewOptions& o = {});

}  // namespace atelier::lace

// Image to stitch grid: resampling a picture to the knitter's width, honouring gauge.
//
// Pure: no I/O. Thread-safe (no shared state). Throws std::invalid_argument on bad params.
#pragma once

#include <opencv2/core.hpp>

namespace atelier::knit {

enum class Orientation {
  horizontal,  // knitting rows run across the picture (the usual way)
  vertical,    // rows run down the picture: the picture is knitted sideways (e.g. a scarf)
};

struct GaugeParams {
  int width = 120;                 // stitches per row of the result
  double stitches_per_10cm = 28;   // horizontal gauge of the yarn/machine
  double rows_per_10cm = 36;       // vertical gauge; usually > stitches, stitches are wide
  Orientation orientation = Orientation::horizontal;
};

// The longest pattern: 10000 rows, 27.8 m of fabric at 36 rows per 10 cm. Solvers, chart and
// preview are linear in rows, but a picture as tall as the pixel limit allows (200 x 200000)
// would otherwise make a pattern of ~100000 rows that runs for minutes and renders a preview
// of gigabytes; no knitter works from a chart of thousands of pages.
inline constexpr long kMaxRows = 10000;

// The rows of the grid for a picture of picture_w x picture_h pixels as stored (before the
// orientation rotation), as to_stitch_grid computes them; 0 for an empty picture. Throws
// std::invalid_argument on bad params.
long stitch_rows(long picture_w, long picture_h, const GaugeParams& params);

// `image`: any 1, 3 or 4 channel 8-bit image (alpha composited on white).
// Returns CV_8UC1 grey levels (0 black .. 255 white) of size rows x width, where
// rows = round(width * picture_height / picture_width * rows_per_10cm / stitches_per_10cm)
// (picture axes after the orientation rotation), so the knitted picture keeps its aspect.
// Vertical orientation rotates the picture 90 degrees clockwise first. Row 0 is the top of
// the picture as seen on the fabric. Throws std::invalid_argument for 0 rows or more than
// kMaxRows.
cv::Mat to_stitch_grid(const cv::Mat& image, const GaugeParams& params);

// Converts any 8-bit image to one grey channel, compositing alpha on white.
cv::Mat to_gray(const cv::Mat& image);

}  // namespace atelier::knit

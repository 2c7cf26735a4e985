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

// `image`: any 1, 3 or 4 channel 8-bit image (alpha composited on white).
// Returns CV_8UC1 grey levels (0 black .. 255 white) of size rows x width, where
// rows = round(width * picture_height / picture_width * rows_per_10cm / stitches_per_10cm)
// (picture axes after the orientation rotation), so the knitted picture keeps its aspect.
// Vertical orientation rotates the picture 90 degrees clockwise first. Row 0 is the top of
// the picture as seen on the fabric.
cv::Mat to_stitch_grid(const cv::Mat& image, const GaugeParams& params);

// Converts any 8-bit image to one grey channel, compositing alpha on white.
cv::Mat to_gray(const cv::Mat& image);

}  // namespace atelier::knit

// Stitch-shaped render of a pattern, so a user sees the fabric rather than pixels.
// Pure, thread-safe.
#pragma once

#include <opencv2/core.hpp>

namespace atelier::knit {

struct PreviewStyle {
  cv::Vec3b background{235, 235, 230};  // BGR of the background yarn (colour 0)
  cv::Vec3b contrast{60, 40, 140};      // BGR of the contrast yarn (colour 1)
  int stitch_px = 12;                   // width of one stitch in the render, in pixels
  double stitch_aspect = 0.78;          // stitch height / width (rows_per_10cm ratio)
};

// Returns CV_8UC3 BGR: every stitch drawn as a shaded knit "V" of its yarn colour.
cv::Mat render_preview(const cv::Mat& grid, const PreviewStyle& style);

// The two stitch images render_preview tiles (index 0: background yarn, 1: contrast), each
// CV_8UC3 of stitch_px x round(stitch_px * stitch_aspect) (at least 1). The preview is these
// tiles laid out as the grid says, so a writer may encode it without drawing it
// (convert/knit/knit_preview_png.h). Throws std::invalid_argument as render_preview.
struct StitchTiles {
  cv::Mat tile[2];
};
StitchTiles stitch_tiles(const PreviewStyle& style);

}  // namespace atelier::knit

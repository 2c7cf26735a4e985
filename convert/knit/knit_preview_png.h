// preview.png encoded straight from the stitch grid (issue 22: the preview took 1.2 s of a
// 2.6 s knit job, nearly all of it generic PNG compression of a 10-Mpx render).
//
// The preview is two small stitch tiles laid out as the grid says (algorithms/knit/preview.h),
// so it is written as a palette PNG whose deflate stream is built from that structure: each
// run of same-colour stitches in a pixel row is one back-reference to the last copy of that
// tile row, and repeats of it. Time is proportional to the number of runs, not of pixels.
// The decoded image equals render_preview(grid, style) pixel for pixel.
//
// Pure, thread-safe. Returns an empty string when the two tiles have more than 256 colours
// together (very tall stitches): the caller then encodes render_preview's image as usual.
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "algorithms/knit/preview.h"

namespace atelier {

std::string encode_preview_png(const cv::Mat& grid, const knit::PreviewStyle& style);

}  // namespace atelier

// Starting assignments (paper section 3): threshold and dithering of a grey stitch grid.
//
// Pure, thread-safe. Grids are CV_8UC1 with 1 = contrast colour (dark), 0 = background.
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace atelier::knit {

enum class Dither { threshold, floyd_steinberg, atkinson, ordered, automatic };

// Name as used in configs and reports: "threshold", "floyd-steinberg", "atkinson",
// "ordered", "auto". Throws std::invalid_argument for an unknown name.
Dither dither_from_name(const std::string& name);
std::string dither_name(Dither d);

// True when the grey image looks like a line drawing (mostly two tones with thin dark
// strokes) rather than a continuous-tone picture. Decides `dither = "auto"`.
bool looks_like_line_drawing(const cv::Mat& gray);

// `automatic` resolved for this picture: threshold for line drawings, Floyd-Steinberg
// for continuous tone. Other values are returned unchanged.
Dither resolve_dither(Dither d, const cv::Mat& gray);

// Dithers `gray` (CV_8UC1) into a 0/1 grid of the same size. `threshold` (0..255) is used
// by the threshold method and as the error-diffusion threshold. `automatic` must be resolved
// first (throws std::invalid_argument otherwise). Ordered dithering uses an 8x8 Bayer matrix.
// (For ordered dithering `threshold` shifts the matrix like a brightness control; 128 is
// neutral: a uniform grey g gets about (255 - g) / 255 dark stitches.)
cv::Mat dither(const cv::Mat& gray, Dither method, int threshold = 128);

}  // namespace atelier::knit

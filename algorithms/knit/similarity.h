// Similarity of a pattern to its source "seen from a distance" (paper section 6).
// Pure, thread-safe.
#pragma once

#include <opencv2/core.hpp>

namespace atelier::knit {

// SSIM (Wang et al. 2004, 8-bit constants) between the grey source and the 0/1 grid
// (1 rendered black), both blurred by a Gaussian of `sigma_stitches` stitches.
// `source_gray` is CV_8UC1 of the grid's size. Returns a value in [-1, 1]; 1 = identical.
double blurred_ssim(const cv::Mat& source_gray, const cv::Mat& grid, double sigma_stitches = 2.0);

}  // namespace atelier::knit

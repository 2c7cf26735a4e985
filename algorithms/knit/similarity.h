// Similarity of a pattern to its source "seen from a distance" (paper section 6).
// Pure, thread-safe.
#pragma once

#include <opencv2/core.hpp>

namespace atelier::knit {

// SSIM (Wang et al. 2004, 8-bit constants) between the grey source and the 0/1 grid
// (1 rendered black), both blurred by a Gaussian of `sigma_stitches` stitches.
// `source_gray` is CV_8UC1 of the grid's size. Returns a value in [-1, 1]; 1 = identical.
double blurred_ssim(const cv::Mat& source_gray, const cv::Mat& grid, double sigma_stitches = 2.0);

// The same measure against one source for many grids (the auto search): the source's blur and
// local statistics are computed once. Gives exactly blurred_ssim's value. Immutable after
// construction, so one instance may be used from several threads at once.
class BlurredSsim {
 public:
  BlurredSsim(const cv::Mat& source_gray, double sigma_stitches = 2.0);
  double operator()(const cv::Mat& grid) const;

 private:
  double sigma_;
  cv::Mat a_, mu_a_, mu_a2_, var_a_;  // CV_32F: blurred source, its local mean, mean², variance
};

}  // namespace atelier::knit

// How well a parquetry result reads as its target from a viewing distance: the "blurred SSIM".
//
// Both images are turned grey and blurred by a Gaussian of sigma = kQualityBlurMm (so the wood
// grain finer than that does not count, the piece colours and the edges between them do), then
// compared by the mean SSIM of Wang et al. 2004 (11x11 Gaussian window, sigma 1.5 px,
// C1 = (0.01 * 255)^2, C2 = (0.03 * 255)^2). 1 = identical; the figure the team compares with
// WoodPixel's results in the same setting (issue 23).
//
// Units: px_per_mm of the images (both at the same resolution). Pure, thread-safe.
#pragma once

#include <opencv2/core.hpp>

namespace atelier::parquetry {

inline constexpr double kQualityBlurMm = 2.0;

// `result` and `target`: same size, CV_8UC1, CV_8UC3 (BGR) or CV_8UC4. Throws
// std::invalid_argument for empty images, other types or different sizes.
double blurred_ssim(const cv::Mat& result, const cv::Mat& target, double px_per_mm);

// The per-pixel SSIM whose mean blurred_ssim() is (CV_32F of the images' size).
cv::Mat blurred_ssim_map(const cv::Mat& result, const cv::Mat& target, double px_per_mm);

// How far (px) a change of one pixel moves the map: the blur's radius plus the SSIM window's.
int blurred_ssim_reach_px(double px_per_mm);

}  // namespace atelier::parquetry

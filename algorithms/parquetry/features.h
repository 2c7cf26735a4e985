// Feature maps (paper eq. 1-2): intensity and Sobel edge magnitude, and the CDF-based
// histogram matching of the target's intensity to the pooled wood.
//
// Intensity is grey / 255 (0..1); the edge feature is the 3x3 Sobel gradient magnitude / 4, so
// a black-to-white step reads about 1 as well. Pure, thread-safe.
#pragma once

#include <array>
#include <opencv2/core.hpp>

namespace atelier::parquetry {

// Grey CV_8UC1 from BGR (or grey) 8-bit input.
cv::Mat to_gray(const cv::Mat& image);

// CV_32F intensity (0..1) of a CV_8UC1 grey image.
cv::Mat intensity(const cv::Mat& gray);

// CV_32F Sobel edge magnitude / 4 of a CV_32F intensity map.
cv::Mat edge(const cv::Mat& intens);

// Accumulates `gray` (CV_8UC1) where `mask` (CV_8UC1, may be empty) is non-zero.
void add_histogram(std::array<double, 256>& hist, const cv::Mat& gray, const cv::Mat& mask);

// Eq. 2: grey level -> intensity (0..1), (1 - w_hist) * v / 255 + w_hist * equalize(v), where
// equalize maps the target's CDF onto the wood's (the smallest wood level whose CDF reaches
// the target level's). An empty histogram maps to itself.
std::array<float, 256> matching_lut(const std::array<double, 256>& target_hist,
                                    const std::array<double, 256>& wood_hist, double w_hist);

// Applies a LUT from matching_lut to CV_8UC1 grey: CV_32F intensity.
cv::Mat apply_lut(const cv::Mat& gray, const std::array<float, 256>& lut);

}  // namespace atelier::parquetry

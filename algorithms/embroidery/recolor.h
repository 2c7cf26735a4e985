// Recolouring a reference tile for one region (paper 5.4, after Chang et al. 2015): the tile's
// mean CIELab colour (over its thread pixels) is mapped to the region's palette colour while the
// shading survives. L: a monotone transfer as in Chang et al., but linear around the mean (the
// deviations from the mean kept, scaled down only as far as [0, 100] needs, at least to a
// quarter), then a small shift so the mean lands exactly. Chang et al.'s piecewise-linear
// transfer through (0,0), (mean, target), (100,100) would, with one palette entry and a black
// target, stretch the highlights far above black (mean L 11 for black thread). a and b are
// shifted by the difference of the means. The target L is capped at max_L, because even
// white thread looks grey (the paper's overexposure fix); a capped target's highlights reach
// at most 3 over max_L, so a light colour's sheen does not carry it back above the cap.
// Pure; thread-safe.
#pragma once

#include <opencv2/core.hpp>

namespace atelier::embroidery {

// The mean CIELab colour (L 0..100) of a tile's pixels where alpha >= 128 (all pixels if none).
cv::Vec3f tile_mean_lab(const cv::Mat3b& color, const cv::Mat1b& alpha);

// The tile `color` (8-bit B,G,R) recoloured so its thread pixels' mean is `target_lab` with L
// capped at max_L. `tile_lab` is color converted to CIELab (CV_32FC3, from to_lab()) and
// `mean_lab` its tile_mean_lab(); both are passed in so that a tile converted once serves every
// region. Returns a B,G,R tile of the same size.
cv::Mat3b recolor_tile(const cv::Mat3f& tile_lab, const cv::Mat1b& alpha, const cv::Vec3f& mean_lab,
                       const cv::Vec3f& target_lab, double max_L);

// 8-bit B,G,R -> float CIELab (L 0..100).
cv::Mat3f to_lab(const cv::Mat3b& bgr);

}  // namespace atelier::embroidery

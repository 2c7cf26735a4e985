// The texture of a pencil line (Meraj et al. 2008, section 3.2): seed the pixels around a path
// with grey levels from the pencil's profile by a bell-shaped fall-off across the line, enforce
// the profile's co-occurrence matrix along the line in 3x3 neighbourhoods until the changes
// stop, then one 3x3 Gaussian pass.
//
// Units: pixels, image coordinates (x right, y down; pixel (x, y) centred at (x, y)); grey
// levels 0 (black) .. 255 (white paper). Pure: works on the caller's canvas only, in a small
// region around the path; one canvas per thread.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "algorithms/pencil/profile.h"

namespace atelier::pencil {

// The CCM step stops after this many passes even if pixels still change.
inline constexpr int kMaxCcmPasses = 10;
// Sigma (px) of the final 3x3 Gaussian pass: enough to soften tone steps and aliasing, mild
// enough that a profile learned back from the drawn line keeps its dark centres (OpenCV's
// default for 3x3, 0.8, lightens a 6B centre by ~15 grey levels).
inline constexpr double kBlurSigma = 0.5;

// Draws the line along `path` (e.g. human_path(...).path) into `canvas` (CV_8UC1, paper = 255;
// existing marks combine by min), reproducibly from `seed`. Pixels within width_px / 2 of the
// path are the line: the nearest ones (<= 0.5 px) are the centre, drawn from mid_hist in
// [min_mid, max_mid]; the next ones (as far out as the profile's share of grey levels in
// [min_range, max_mid] asks) from hist in [min_range, max_mid]; the rest from hist in
// [max_mid, max_range], lighter further out. The ccm pair of a pixel is with its along-line
// neighbour (the direction that maps to +y when the line is turned vertical); replacements keep
// to the pixel's own range. Parts of the line outside the canvas are clipped; only a region of
// the path's bounding box plus the width is touched. Throws std::invalid_argument for a canvas
// that is not CV_8UC1, a non-finite path point, or a profile without 256-bin histograms and a
// 256 x 256 ccm.
void draw_pencil_line(cv::Mat& canvas, const std::vector<cv::Point2d>& path, const PencilProfile& profile,
                      std::uint64_t seed);

}  // namespace atelier::pencil

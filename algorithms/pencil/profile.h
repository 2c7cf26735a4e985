// The statistical profile of one pencil (Meraj et al. 2008, section 3.2): the grey levels of a
// line's centre and of the whole line, and their co-occurrence along the line.
//
// Units: grey levels 0 (black) .. 255 (white paper); widths in pixels.
// Pure functions; no shared state, safe from any thread. The profile owns its vectors.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace atelier::pencil {

struct PencilProfile {           // statistics of one pencil's lines, grey levels 0 (black) .. 255 (white)
  std::string name;              // "HB", "6B", ...
  int min_mid = 0, max_mid = 0;  // range of the centre grey levels
  int min_range = 0, max_range = 0;  // range of the whole line's grey levels (white paper excluded)
  std::vector<double> mid_hist;  // 256 bins, normalised: centre pixels
  std::vector<double> hist;      // 256 bins, normalised: all line pixels
  std::vector<double> ccm;       // 256 x 256 (row i = upper pixel, column j = the one below), normalised
  double width_px = 0.0;         // typical line width (mean run length across the line)
  // The pixel counts behind the normalised histograms, so that a profile file can store whole
  // counts (hist[i] * line_pixels is one) and read back exactly these doubles. learn_profile
  // fills them; 0 = unknown (a profile made some other way).
  long long mid_pixels = 0;      // centre pixels: one per run across the line
  long long line_pixels = 0;     // all line pixels
  long long ccm_pairs = 0;       // vertical neighbour pairs counted in ccm
};

// The ranges [min_mid, max_mid] and [min_range, max_range] leave out this share of their pixels
// at each end: a few specks (dust, a dent in the paper) should not stretch a pencil's range.
inline constexpr double kRangeTrim = 0.005;

// Learns a profile from a grey image (CV_8UC1) of one or more pencil lines running VERTICALLY
// (rotated first, as the paper does) on white paper: line pixels are darker than
// `paper_threshold`; centre pixels are the darkest pixel of each horizontal run of line pixels;
// the ranges are those of the centre and line pixels less kRangeTrim at each end (the histograms
// keep every pixel); the ccm counts vertical neighbour pairs (I(p,q), I(p,q+1)) of line pixels;
// mid_pixels, line_pixels and ccm_pairs are the totals the histograms were divided by. Throws
// std::invalid_argument for an image that is not CV_8UC1 or holds no line pixel.
PencilProfile learn_profile(const cv::Mat& gray, const std::string& name, int paper_threshold = 245);

// Chi-square distance between two normalised histograms of the same size: the sum of
// (a-b)^2/(a+b) over bins with a+b > 0, halved (0 = identical, 1 = disjoint). Throws
// std::invalid_argument for different sizes.
double chi_square(const std::vector<double>& a, const std::vector<double>& b);

}  // namespace atelier::pencil

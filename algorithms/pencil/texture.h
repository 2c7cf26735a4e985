// The texture of a pencil line (Meraj et al. 2008, section 3.2): seed the pixels around a path
// with grey levels from the pencil's profile by a bell-shaped fall-off across the line, enforce
// the profile's co-occurrence matrix along the line in 3x3 neighbourhoods until the changes
// stop, then one 3x3 Gaussian pass.
//
// Units: pixels, image coordinates (x right, y down; pixel (x, y) centred at (x, y)); grey
// levels 0 (black) .. 255 (white paper). Pure: works on the caller's canvas only, on the pixels
// near the path; one canvas per thread. A PreparedProfile is read-only once made, so threads may
// share one.
//
// Cost: proportional to the line's pixels (length x width), not to its bounding box; a 200 px
// line of a 7 px pencil takes ~0.23-0.25 ms on the 2-core box (bench/pencil_bench.cc). Sketch
// jobs prepare() each pencil once and draw all their lines with the PreparedProfile overload.
#pragma once

#include <array>
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
// to the pixel's own range. Parts of the line outside the canvas are clipped; only pixels within
// the half width of the path are changed. Throws std::invalid_argument for a canvas
// that is not CV_8UC1, a non-finite path point, or a profile without 256-bin histograms and a
// 256 x 256 ccm.
//
// Random numbers: std::mt19937_64 seeded with `seed`, used in the line's pixel order (row-major),
// so the same path, profile and seed give the same pixels.
void draw_pencil_line(cv::Mat& canvas, const std::vector<cv::Point2d>& path, const PencilProfile& profile,
                      std::uint64_t seed);

// The grey levels [lo, hi] of a histogram and their cumulative weights (cdf[v - lo] is the
// weight of lo..v; total = cdf[hi - lo]); total 0 means "sample uniformly". guide[k] is the first
// i with cdf[i] > k * total / 1024, where the search for a sampled weight starts (an inverse-cdf
// table that leaves the result exactly that of a binary search).
struct GreyRange {
  int lo = 0, hi = 0;
  double total = 0.0;
  std::array<double, 256> cdf{};
  std::array<std::uint16_t, 1024> guide{};
};

// What draw_pencil_line derives from a profile, computed once: the three zones' samplers, the
// zone widths and which ccm pairs occur, a byte each (64 KB, against the ccm's 512 KB of
// doubles). Owns its data (keeps no reference to the profile).
struct PreparedProfile {
  double half = 0.5;   // half the line width (px), >= 0.5
  double inner = 0.5;  // the near zone ends this far from the path (px), in [0.5, half]
  GreyRange centre;    // mid_hist over [min_mid, max_mid]
  GreyRange near;      // hist over [min_range, max_mid]
  GreyRange far;       // hist over [max_mid, max_range]
  // Per zone (0 paper, 1 centre, 2 near, 3 far) the levels a pixel may take.
  std::array<int, 4> zone_lo{0, 0, 0, 0}, zone_hi{255, 255, 255, 255};
  std::vector<std::uint8_t> ccm_occurs;  // 256 x 256: 1 where ccm[i * 256 + j] > 0, else 0
  // Whether the pair (upper i, lower j) occurs in the profile's ccm.
  bool occurs(int i, int j) const { return ccm_occurs[static_cast<unsigned>(i) * 256u + static_cast<unsigned>(j)] != 0; }
};

// Prepares `profile` for drawing. Throws std::invalid_argument for a profile without 256-bin
// histograms and a 256 x 256 ccm.
PreparedProfile prepare(const PencilProfile& profile);

// draw_pencil_line with a prepared profile: the same pixels as the overload above (both run the
// same code), without re-deriving the profile per line. Throws std::invalid_argument for a canvas
// that is not CV_8UC1, a non-finite path point, or a profile not made by prepare().
void draw_pencil_line(cv::Mat& canvas, const std::vector<cv::Point2d>& path, const PreparedProfile& profile,
                      std::uint64_t seed);

}  // namespace atelier::pencil

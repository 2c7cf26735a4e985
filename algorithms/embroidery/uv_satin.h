// UV map of a satin region (paper 5.2). Steps, as in the paper, with the simplifications named:
//  1. Skeleton branches (skeleton.h: Zhang-Suen thinning, clean-up, reconnection).
//  2. Sub-regions: every pixel goes to the branch of its nearest curve sample (one distance
//     transform with labels). Simplified: sub-regions are disjoint (a Voronoi split), and
//     their contour is completed by the split line itself instead of lines/splines between
//     nearest contour pixels.
//  3. Each branch gets a cubic B-spline (fit_bspline, extended at the ends), cut into pieces
//     every tile height along its arc length; the cut lines are the curve's normals there.
//  4. Contour pixels of the sub-region are split into the two sides of the curve and ordered
//     by their foot point on the curve (the perpendicular through a contour pixel meets the
//     curve at its foot point, so this is the order of the perpendicular cut lines). Ordering
//     by foot point, not by walking the contour, is what keeps cut lines from crossing: where
//     the paper repairs crossing or doubly-cutting lines (ideal cut lines through inflection
//     points or Harris corners, temporary contour pixels at self-crossings), a non-monotone
//     foot point order is simply sorted, which untangles the lines the same way.
//  5. Within each piece, the contour pixels of the two sides are paired by their relative order
//     (one-to-many when the counts differ); a pair's v is the piece index plus that order.
//  6. A pixel's u is its position along each nearby pair's line (0 on the +normal side), its v
//     the pair's v; pairs are blended with the weights of eq. 7.
// Pixels no branch reaches (a region too small to have a skeleton) fall back to the
// long-short map in the region's direction.
// Units: image pixels. Pure; thread-safe.
#pragma once

#include <vector>

#include "algorithms/embroidery/uv_map.h"

namespace atelier::embroidery {

// mask: 255 = pixel to map, in the frame of `box`. tile_h_px: the satin tile's height in image
// pixels (the length of stitch rows one tile covers); tile_w_px and direction are for the
// fallback only.
RegionUV uv_satin(const cv::Mat1b& mask, const cv::Rect& box, double tile_w_px, double tile_h_px,
                  double direction);

// Step 5 on its own (a pure function, for tests). A contour pixel of one side of a branch.
struct SatinContourPx {
  float s;          // foot point: arc length along the branch's curve, image pixels
  cv::Point2f p;    // the pixel
};
// A pair of contour pixels across the column.
struct SatinPair {
  cv::Point2f c0, c1;   // c0 on the +normal side (u = 0), c1 on the other (u = 1)
  float s_mid;          // where along the curve it sits
  float v;              // unwrapped: piece index + relative order within the piece
  cv::Point2f e;        // c1 - c0
  float len = 0;        // |e|
  float inv_len2 = 0;   // 1 / |e|^2 (0 for a degenerate pair)
};
// a, b: the two sides' contour pixels sorted by s. Pieces are tile_h_px long along s; within
// each piece holding pixels of both sides they pair by relative order (one-to-many when the
// counts differ); a piece with one side only gives no pair. Every pass consumes at least one
// pixel, so it ends after at most a.size() + b.size() passes whatever the values (a
// non-positive or non-finite tile_h_px gives no pair).
std::vector<SatinPair> pair_satin_sides(const std::vector<SatinContourPx>& a, const std::vector<SatinContourPx>& b,
                                        double tile_h_px);

}  // namespace atelier::embroidery

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

#include "algorithms/embroidery/uv_map.h"

namespace atelier::embroidery {

// mask: 255 = pixel to map, in the frame of `box`. tile_h_px: the satin tile's height in image
// pixels (the length of stitch rows one tile covers); tile_w_px and direction are for the
// fallback only.
RegionUV uv_satin(const cv::Mat1b& mask, const cv::Rect& box, double tile_w_px, double tile_h_px,
                  double direction);

}  // namespace atelier::embroidery

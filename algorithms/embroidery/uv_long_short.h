// UV map of a long-short region (paper 5.1). The rotation defines a frame whose x-axis runs
// along the stitches; rows of tiles grow along its y-axis: r = (y - ymin) / h_LS, v = frac(r).
// Along x each pixel scanline of the region (a run of the region in the rotated frame) gets u
// from 0 at its start to 1 at its end: the tile's centre (u in [0.25, 0.75], one stitch period)
// is repeated at its natural size as often as fits, and the two edge parts (u in [0, 0.25] and
// [0.75, 1]) are stretched or shrunk to meet the contour.
// (The tile itself staggers the stitch ends of neighbouring threads: long and short stitches.)
// Units: image pixels; angle in radians (image frame). Pure; thread-safe.
#pragma once

#include "algorithms/embroidery/uv_map.h"

namespace atelier::embroidery {

// mask: 255 = pixel to map, in the frame of `box` (image pixels). tile_w_px, tile_h_px: the
// long-short tile's size in image pixels (its mm size times px_per_mm), both > 0.
RegionUV uv_long_short(const cv::Mat1b& mask, const cv::Rect& box, double angle, double tile_w_px,
                       double tile_h_px);

// The u of a position x in [0, len] along a run of length len (pixels), for a tile tile_w_px
// wide whose centre half repeats. Exposed for tests.
float long_short_u(double x, double len, double tile_w_px);

}  // namespace atelier::embroidery

// UV map of an edge region (paper 5.3), the satin steps simplified: every pixel goes to its
// nearest skeleton branch pixel (skeleton.h); each branch is cut by pixel count into pieces one
// tile long; a pixel belongs to the block of its nearest piece. Each block is filled by a
// line-based morph (Beier and Neely 1992) of the reference tile: the piece's chord is the
// feature line of the tile's centre line, the neighbouring pieces' chords (mapped to the
// neighbouring tiles) join in with Beier-Neely weights so that stitches continue across block
// borders. Across the stroke the tile is scaled to the local stroke width (twice the distance
// transform on the skeleton) so the tile's edges stay inside the region.
// Pixels no branch reaches fall back to the long-short map in the region's direction.
// Units: image pixels. Pure; thread-safe.
#pragma once

#include "algorithms/embroidery/uv_map.h"

namespace atelier::embroidery {

// mask: 255 = pixel to map, in the frame of `box`. tile_w_px: the edge tile's length in image
// pixels (one stitch group along the stroke); tile_h_px and direction are for the fallback.
RegionUV uv_edge(const cv::Mat1b& mask, const cv::Rect& box, double tile_w_px, double tile_h_px,
                 double direction);

}  // namespace atelier::embroidery

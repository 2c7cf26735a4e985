// The UV value image of one region (paper Fig. 2d), as the three per-style mappings
// (uv_long_short.h, uv_satin.h, uv_edge.h) produce it and synthesis.h consumes it.
// Units: image pixels; (u, v) in [0, 1] address the style's reference tile (u = tile x,
// v = tile y); angle = direction of +u in the image frame (radians, x right, y down), with +v
// along angle + pi/2, so the tile's normals can be turned into the image frame.
// Value type; thread-compatible.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace atelier::embroidery {

struct RegionUV {
  cv::Rect box;      // image pixels covered by the Mats below
  cv::Mat1b mask;    // box.size(); 255 = a pixel with a UV value
  cv::Mat2f uv;      // box.size(); (u, v), valid where mask
  cv::Mat1f angle;   // box.size(); +u direction, valid where mask; empty when the whole
                     // region has one direction, `direction`
  float direction = 0;
  float angle_at(int y, int x) const { return angle.empty() ? direction : angle(y, x); }
};

// A RegionUV over `box` for the pixels of `mask`, UVs zero, every pixel at `direction` in a
// per-pixel angle map (the satin and edge maps set each pixel's own angle).
RegionUV region_uv_with_angles(const cv::Rect& box, const cv::Mat1b& mask, double direction);

// For every pixel of an image of `size`, the index into `points` of the nearest point (points
// are in that image's pixel frame and rounded onto its grid; points outside are ignored; of two
// points on one pixel the first wins), or -1 everywhere when no point lies inside. One
// distance transform with pixel labels (5x5 mask), so O(pixels).
cv::Mat1i nearest_point_index(cv::Size size, const std::vector<cv::Point2f>& points);

}  // namespace atelier::embroidery

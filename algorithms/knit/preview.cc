#include "algorithms/knit/preview.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace atelier::knit {
namespace {

// One stitch of one yarn: two slanted legs meeting at the bottom centre (the knit "V") on a
// darker gap colour that shows between the legs and between neighbouring stitches. Each leg
// is shaded like a round strand: bright along its middle, darker towards its edges.
cv::Mat stitch_tile(const cv::Vec3b& yarn, int w, int h) {
  // Drawn at 4x and shrunk with area averaging for smooth edges at any stitch size.
  const int s = 4, W = w * s, H = h * s;
  const cv::Vec3f colour(yarn[0], yarn[1], yarn[2]);
  const double gap_shade = 0.58;
  cv::Mat big(H, W, CV_32FC3, cv::Scalar::all(0));
  struct Leg {
    cv::Point2d centre, axis;  // axis: unit vector along the leg
    double half_length, half_width;
  };
  Leg legs[2];
  for (int side = 0; side < 2; ++side) {
    const double sign = side == 0 ? -1.0 : 1.0;
    const cv::Point2d top(W * (0.5 + sign * 0.30), H * 0.02), bottom(W * (0.5 + sign * 0.05), H * 1.0);
    const cv::Point2d d = bottom - top;
    const double len = std::hypot(d.x, d.y);
    legs[side] = Leg{(top + bottom) * 0.5, d / len, len * 0.56, W * 0.2};
  }
  for (int y = 0; y < H; ++y) {
    cv::Vec3f* row = big.ptr<cv::Vec3f>(y);
    for (int x = 0; x < W; ++x) {
      double shade = gap_shade;
      for (const Leg& leg : legs) {
        const cv::Point2d p = cv::Point2d(x + 0.5, y + 0.5) - leg.centre;
        const double u = (p.x * leg.axis.x + p.y * leg.axis.y) / leg.half_length;
        const double v = (p.x * -leg.axis.y + p.y * leg.axis.x) / leg.half_width;
        const double r2 = u * u + v * v;
        if (r2 > 1.0) continue;
        // Round strand: brightest a little off the middle, falling off to the edge, and
        // slightly darker towards the leg's ends where it dives under the next stitch.
        const double across = std::sqrt(std::max(0.0, 1.0 - (v + 0.25) * (v + 0.25) / 1.6));
        shade = std::max(shade, 0.68 + 0.37 * across * (1.0 - 0.3 * u * u));
      }
      row[x] = colour * static_cast<float>(shade);
    }
  }
  cv::Mat tile;
  cv::resize(big, tile, cv::Size(w, h), 0, 0, cv::INTER_AREA);
  tile.convertTo(tile, CV_8UC3);  // saturates highlights of light yarns at 255
  return tile;
}

}  // namespace

StitchTiles stitch_tiles(const PreviewStyle& style) {
  if (style.stitch_px < 1)
    throw std::invalid_argument("render_preview: stitch_px must be at least 1");
  if (!(style.stitch_aspect > 0) || !std::isfinite(style.stitch_aspect))
    throw std::invalid_argument("render_preview: stitch_aspect must be a positive number");
  const int w = style.stitch_px;
  const int h = std::max(1, static_cast<int>(std::lround(w * style.stitch_aspect)));
  return StitchTiles{{stitch_tile(style.background, w, h), stitch_tile(style.contrast, w, h)}};
}

cv::Mat render_preview(const cv::Mat& grid, const PreviewStyle& style) {
  if (grid.empty() || grid.type() != CV_8UC1)
    throw std::invalid_argument("render_preview: the grid must be a non-empty CV_8UC1 image");
  const StitchTiles st = stitch_tiles(style);
  const cv::Mat* tiles = st.tile;
  const int w = tiles[0].cols, h = tiles[0].rows;
  cv::Mat out(grid.rows * h, grid.cols * w, CV_8UC3);
  for (int y = 0; y < grid.rows; ++y) {
    const uint8_t* g = grid.ptr<uint8_t>(y);
    for (int x = 0; x < grid.cols; ++x)
      tiles[g[x] != 0 ? 1 : 0].copyTo(out(cv::Rect(x * w, y * h, w, h)));
  }
  return out;
}

}  // namespace atelier::knit

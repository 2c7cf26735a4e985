#include "algorithms/embroidery/uv_edge.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "algorithms/embroidery/skeleton.h"
#include "algorithms/embroidery/uv_long_short.h"

namespace atelier::embroidery {
namespace {

// One block's feature line: the chord of a skeleton piece, and the stroke's half width there.
struct Piece {
  cv::Point2f p, q;
  float half_width;
  // Derived once per piece, not per pixel: d = q - p, |d|, and +u's angle atan2(d).
  cv::Point2f d;
  float len = 0;
  float angle = 0;
};

struct Owner {
  int branch, index;   // skeleton pixel
};

}  // namespace

RegionUV uv_edge(const cv::Mat1b& mask, const cv::Rect& box, double tile_w_px, double tile_h_px,
                 double direction) {
  cv::Mat1f dt;
  cv::distanceTransform(mask, dt, cv::DIST_L2, cv::DIST_MASK_5);
  double max_dt = 0;
  cv::minMaxLoc(dt, nullptr, &max_dt);
  const std::vector<SkeletonBranch> branches = skeleton_branches(mask, std::max(3.0, max_dt));
  std::vector<cv::Point2f> pts;
  std::vector<Owner> owner;
  for (int b = 0; b < static_cast<int>(branches.size()); ++b)
    for (int k = 0; k < static_cast<int>(branches[b].pixels.size()); ++k) {
      pts.push_back(branches[b].pixels[k]);
      owner.push_back({b, k});
    }
  const cv::Mat1i nearest = nearest_point_index(mask.size(), pts);
  if (pts.empty() || nearest(0, 0) < 0) return uv_long_short(mask, box, direction, tile_w_px, tile_h_px);

  // Branches cut by pixel count into pieces about one tile long.
  const double piece_px = std::max(2.0, tile_w_px);
  std::vector<std::vector<Piece>> pieces(branches.size());
  std::vector<int> piece_count(branches.size());
  for (size_t b = 0; b < branches.size(); ++b) {
    const auto& px = branches[b].pixels;
    const int n = static_cast<int>(px.size());
    const int count = std::max(1, static_cast<int>(std::lround((n - 1) / piece_px)));
    piece_count[b] = count;
    for (int j = 0; j < count; ++j) {
      const int a = j * (n - 1) / count, e = (j + 1) * (n - 1) / count;
      Piece pc{px[a], px[e], 0.5f};
      for (int k = a; k <= e; ++k) {
        const int x = static_cast<int>(std::lround(px[k].x)), y = static_cast<int>(std::lround(px[k].y));
        if (x >= 0 && y >= 0 && x < mask.cols && y < mask.rows) pc.half_width = std::max(pc.half_width, dt(y, x));
      }
      if (cv::norm(pc.q - pc.p) < 0.5) {   // a one-pixel branch: lay the tile along the region
        const cv::Point2f d(static_cast<float>(std::cos(direction)), static_cast<float>(std::sin(direction)));
        pc.p -= d * 0.5f * static_cast<float>(piece_px);
        pc.q += d * 0.5f * static_cast<float>(piece_px);
      }
      pc.d = pc.q - pc.p;
      pc.len = std::sqrt(pc.d.dot(pc.d));
      pc.angle = std::atan2(pc.d.y, pc.d.x);
      pieces[b].push_back(pc);
    }
  }
  auto piece_of = [&](const Owner& o) {
    const int n = static_cast<int>(branches[o.branch].pixels.size());
    const int count = piece_count[o.branch];
    return n <= 1 ? 0 : std::min(count - 1, o.index * count / std::max(1, n - 1));
  };

  RegionUV out = region_uv_with_angles(box, mask, direction);
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x) {
      if (!mask(y, x)) continue;
      const Owner o = owner[nearest(y, x)];
      const int j = piece_of(o);
      const auto& P = pieces[o.branch];
      const bool ring = is_closed(branches[o.branch]);
      const cv::Point2f X(static_cast<float>(x), static_cast<float>(y));
      // Beier-Neely: each feature line maps X into the reference; the piece's own line maps to
      // tile j, its neighbours' to the neighbouring tiles (the tile repeats along u).
      double sw = 0, sx = 0, sy = 0;
      for (int delta = -1; delta <= 1; ++delta) {
        int i = j + delta;
        if (ring) i = (i + static_cast<int>(P.size())) % static_cast<int>(P.size());
        if (i < 0 || i >= static_cast<int>(P.size()) || (delta != 0 && i == j)) continue;
        const Piece& L = P[i];
        const cv::Point2f d = L.d;
        const float len = L.len;
        const cv::Point2f r = X - L.p;
        const double u = r.dot(d) / (len * len);
        const double v = (d.x * r.y - d.y * r.x) / len;   // signed, along perp = (-d.y, d.x)
        const cv::Point2f rq = X - L.q;
        const double dist = u < 0 ? std::sqrt(static_cast<double>(r.dot(r)))
                            : u > 1 ? std::sqrt(static_cast<double>(rq.dot(rq)))
                                    : std::abs(v);
        const double w = 1.0 / ((1.0 + dist) * (1.0 + dist));   // a = 1, b = 2, p = 0
        sw += w;
        sx += w * (delta + u);
        // Across the stroke the tile spans the stroke's width: its edges stay in the region.
        sy += w * (0.5 + v / (2.0 * (L.half_width + 0.5)));
      }
      const double u = sx / sw, v = std::clamp(sy / sw, 0.0, 1.0);
      out.uv(y, x) = cv::Vec2f(static_cast<float>(u - std::floor(u)), static_cast<float>(std::min(v, 0.9999)));
      out.angle(y, x) = P[j].angle;
    }
  return out;
}

}  // namespace atelier::embroidery

#include "algorithms/embroidery/uv_long_short.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace atelier::embroidery {

float long_short_u(double x, double len, double tile_w_px) {
  if (len <= 0) return 0.5f;
  const double e = 0.25 * tile_w_px, c = 0.5 * tile_w_px;
  // As many whole centre repeats as fit; the two edge parts take up the rest, so that
  // the repeated stitches keep their length and only the ends at the contour stretch.
  const double n = std::max(0.0, std::round((len - 2 * e) / c));
  const double edge = (len - n * c) / 2;
  x = std::clamp(x, 0.0, len);
  if (x <= edge) return static_cast<float>(0.25 * x / edge);
  if (x >= len - edge) return static_cast<float>(0.75 + 0.25 * (x - (len - edge)) / edge);
  const double t = (x - edge) / c;
  const double f = t - std::floor(t);
  return static_cast<float>(0.25 + 0.5 * f);
}

RegionUV uv_long_short(const cv::Mat1b& mask, const cv::Rect& box, double angle, double tile_w_px,
                       double tile_h_px) {
  RegionUV out;
  out.box = box;
  out.mask = mask.clone();
  out.uv = cv::Mat2f(mask.size(), cv::Vec2f(0, 0));
  out.direction = static_cast<float>(angle);   // one direction: no per-pixel angle image
  const double c = std::cos(angle), s = std::sin(angle);
  // Rotated frame: x' = c x + s y (along the stitches), y' = -s x + c y (row growth), at pixel
  // centres. A scanline is the set of pixels with equal floor(y').
  struct Px {
    float xr, yr;
    int y, x, row;
  };
  std::vector<Px> px;
  px.reserve(static_cast<size_t>(cv::countNonZero(mask)));
  double y0 = 1e18;
  for (int y = 0; y < mask.rows; ++y) {
    const uchar* m = mask.ptr<uchar>(y);
    for (int x = 0; x < mask.cols; ++x)
      if (m[x]) {
        const double yr = -s * (x + 0.5) + c * (y + 0.5);
        px.push_back({static_cast<float>(c * (x + 0.5) + s * (y + 0.5)), static_cast<float>(yr), y, x, 0});
        y0 = std::min(y0, yr);
      }
  }
  if (px.empty()) return out;
  // Bucket the pixels by scanline (counting sort), then order each scanline along x'.
  const double row0 = std::floor(y0);
  int rows = 0;
  for (Px& p : px) {
    p.row = static_cast<int>(std::floor(p.yr - row0));
    rows = std::max(rows, p.row + 1);
  }
  std::vector<int> first(rows + 1, 0);
  for (const Px& p : px) ++first[p.row + 1];
  for (int j = 0; j < rows; ++j) first[j + 1] += first[j];
  std::vector<Px> sorted(px.size());
  {
    std::vector<int> at(first.begin(), first.end() - 1);
    for (const Px& p : px) sorted[at[p.row]++] = p;
  }
  // A rotated scanline meets pixel centres at most ~1.5 px apart; a wider gap is outside the
  // region (a concave contour), so the scanline splits into runs there.
  constexpr float kGap = 2.0f;
  for (int j = 0; j < rows; ++j) {
    auto b = sorted.begin() + first[j], e = sorted.begin() + first[j + 1];
    std::sort(b, e, [](const Px& a, const Px& q) { return a.xr < q.xr; });
    for (auto run = b; run != e;) {
      auto end = run + 1;
      while (end != e && end->xr - (end - 1)->xr <= kGap) ++end;
      // The run covers its pixels' centres plus half a pixel at either end.
      const double a = run->xr - 0.5, len = (end - 1)->xr + 0.5 - a;
      for (auto it = run; it != end; ++it) {
        // v: rows of tiles start at the region's ymin (paper: r = (y - ymin) / h_LS).
        const double r = (it->yr - y0) / tile_h_px;
        out.uv(it->y, it->x) =
            cv::Vec2f(long_short_u(it->xr - a, len, tile_w_px), static_cast<float>(r - std::floor(r)));
      }
      run = end;
    }
  }
  return out;
}

}  // namespace atelier::embroidery

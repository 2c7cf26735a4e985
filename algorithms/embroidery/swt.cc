#include "algorithms/embroidery/swt.h"

#include <cmath>
#include <numbers>

namespace atelier::embroidery {
namespace {

struct Grad {
  float x = 0, y = 0, norm = 0;
};

// The 3x3 Sobel of the mask smoothed by the 3x3 binomial filter, evaluated at one pixel only:
// a 5x5 correlation with the separable kernel [-1 -2 0 2 1]/4 x [1 4 6 4 1]/4. Evaluating it
// only at contour pixels keeps the cost proportional to the contour, not the bounding box.
// Summed in integers (every tap is a multiple of 1/16, so the float result is the same) and
// without bounds checks away from the mask's border.
Grad gradient(const cv::Mat1b& m, int x, int y) {
  static constexpr int kd[5] = {-1, -2, 0, 2, 1};
  static constexpr int ks[5] = {1, 4, 6, 4, 1};
  int gx = 0, gy = 0;
  if (x >= 2 && y >= 2 && x + 2 < m.cols && y + 2 < m.rows) {
    for (int j = 0; j < 5; ++j) {
      const uchar* r = m[y + j - 2] + x - 2;
      const int b0 = r[0] != 0, b1 = r[1] != 0, b2 = r[2] != 0, b3 = r[3] != 0, b4 = r[4] != 0;
      gx += ks[j] * (-b0 - 2 * b1 + 2 * b3 + b4);
      gy += kd[j] * (b0 + 4 * b1 + 6 * b2 + 4 * b3 + b4);
    }
  } else {
    for (int j = -2; j <= 2; ++j) {
      const int yy = y + j;
      if (yy < 0 || yy >= m.rows) continue;
      const uchar* row = m[yy];
      for (int i = -2; i <= 2; ++i) {
        const int xx = x + i;
        if (xx < 0 || xx >= m.cols || !row[xx]) continue;
        gx += kd[i + 2] * ks[j + 2];
        gy += ks[i + 2] * kd[j + 2];
      }
    }
  }
  Grad g;
  g.x = static_cast<float>(gx) / 16.f;
  g.y = static_cast<float>(gy) / 16.f;
  g.norm = std::hypot(g.x, g.y);
  return g;
}

}  // namespace

StrokeWidths stroke_widths(const cv::Mat1b& mask, cv::Point origin, cv::Size image) {
  StrokeWidths out;
  const int W = mask.cols, H = mask.rows;
  auto inside = [&](int x, int y) { return x >= 0 && y >= 0 && x < W && y < H && mask(y, x) != 0; };
  // Row pointers instead of bounds-checked lookups: this loop visits the whole bounding box.
  for (int y = 0; y < H; ++y) {
    const uchar* row = mask[y];
    const uchar* up = y > 0 ? mask[y - 1] : nullptr;
    const uchar* down = y + 1 < H ? mask[y + 1] : nullptr;
    for (int x = 0; x < W; ++x) {
      if (!row[x]) continue;
      const bool interior = x > 0 && x + 1 < W && row[x - 1] && row[x + 1] && up && up[x] && down && down[x];
      if (!interior) out.contour.emplace_back(x, y);
    }
  }
  out.width.assign(out.contour.size(), 0.f);
  const float cos_limit = static_cast<float>(std::cos(std::numbers::pi / 6));
  auto on_image_border = [&](int x, int y) {
    const int ix = x + origin.x, iy = y + origin.y;
    return ix <= 0 || iy <= 0 || ix >= image.width - 1 || iy >= image.height - 1;
  };
  auto thin = [&](int x, int y) {
    return (!inside(x - 1, y) && !inside(x + 1, y)) || (!inside(x, y - 1) && !inside(x, y + 1));
  };
  const int max_steps = 2 * (W + H) + 4;
  for (size_t i = 0; i < out.contour.size(); ++i) {
    const cv::Point p = out.contour[i];
    if (on_image_border(p.x, p.y)) continue;
    const Grad gp = gradient(mask, p.x, p.y);
    if (gp.norm < 1e-3f) {
      if (thin(p.x, p.y)) out.width[i] = 1.f;
      continue;
    }
    const float dx = gp.x / gp.norm, dy = gp.y / gp.norm;
    // March in half-pixel steps; q = the last pixel inside before the ray leaves.
    cv::Point q = p;
    for (int s = 1; s <= max_steps; ++s) {
      const float t = 0.5f * static_cast<float>(s);
      const cv::Point c(cvRound(p.x + t * dx), cvRound(p.y + t * dy));
      if (c == q) continue;
      if (!inside(c.x, c.y)) break;
      q = c;
    }
    if (q == p) {
      if (thin(p.x, p.y)) out.width[i] = 1.f;
      continue;
    }
    if (on_image_border(q.x, q.y)) continue;
    const Grad gq = gradient(mask, q.x, q.y);
    if (gq.norm < 1e-3f) continue;
    if (-(dx * gq.x + dy * gq.y) / gq.norm < cos_limit) continue;  // not roughly opposite
    out.width[i] = static_cast<float>(std::hypot(q.x - p.x, q.y - p.y)) + 1.f;
  }
  for (float w : out.width) out.failures += w == 0.f;
  return out;
}

bool swt_forces_long_short(int failures, int area_px) {
  return failures > std::pow(static_cast<double>(area_px), 0.8);
}

}  // namespace atelier::embroidery

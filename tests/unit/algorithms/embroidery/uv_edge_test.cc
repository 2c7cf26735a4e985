// The edge UV map (algorithms/embroidery/uv_edge.h): tiles run along the stroke and span its
// width.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>

#include "algorithms/embroidery/uv_edge.h"
#include "tests/unit/algorithms/embroidery/synthesis_fixture.h"

namespace atelier::embroidery {
namespace {

using test::kPi;

TEST(EmbroiderySynthesis, EdgeTilesRunAlongTheStrokeAndSpanItsWidth) {
  cv::Mat1b mask(160, 260, uchar(0));
  const double a = 20 * kPi / 180;
  const cv::Point2d d(std::cos(a), std::sin(a));
  cv::line(mask, cv::Point(20, 30), cv::Point(20 + static_cast<int>(220 * d.x), 30 + static_cast<int>(220 * d.y)), 255, 5);
  const RegionUV uv = uv_edge(mask, cv::Rect(0, 0, mask.cols, mask.rows), 8, 4, 0.0);
  int tested = 0, along = 0;
  float vmin = 1, vmax = 0;
  for (int y = 1; y + 1 < mask.rows; ++y)
    for (int x = 1; x + 1 < mask.cols; ++x) {
      if (!mask(y, x)) continue;
      vmin = std::min(vmin, uv.uv(y, x)[1]);
      vmax = std::max(vmax, uv.uv(y, x)[1]);
      if (!mask(y, x + 1) || !mask(y, x - 1) || !mask(y + 1, x) || !mask(y - 1, x)) continue;
      // u repeats every tile: differences are taken modulo 1.
      auto du = [](float p, float q) { const double e = p - q; return e - std::round(e); };
      const double gx = du(uv.uv(y, x + 1)[0], uv.uv(y, x - 1)[0]), gy = du(uv.uv(y + 1, x)[0], uv.uv(y - 1, x)[0]);
      const double g = std::hypot(gx, gy);
      if (g < 1e-4) continue;
      ++tested;
      if (std::abs(gx * d.x + gy * d.y) / g > std::cos(30 * kPi / 180)) ++along;
    }
  ASSERT_GT(tested, 300);
  EXPECT_GT(along, 0.85 * tested);
  EXPECT_LT(vmin, 0.2);   // the tile's edges reach the stroke's sides ...
  EXPECT_GT(vmax, 0.8);
}

}  // namespace
}  // namespace atelier::embroidery

// The long-short UV map (algorithms/embroidery/uv_long_short.h): rows grow along y', each run
// spans u, and the centre part of the tile repeats.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <map>

#include "algorithms/embroidery/uv_long_short.h"
#include "tests/unit/algorithms/embroidery/synthesis_fixture.h"

namespace atelier::embroidery {
namespace {

using test::kPi;

TEST(EmbroiderySynthesis, LongShortRowsGrowAlongYAndSpanEachRunInU) {
  cv::Mat1b mask(200, 260, uchar(0));
  cv::ellipse(mask, cv::Point(130, 100), cv::Size(110, 70), 15, 0, 360, 255, cv::FILLED);
  const double tile_w = 32, tile_h = 12;
  // Axis-aligned scanlines start half a pixel from the contour (u 0.031 when the edge part
  // shrinks to 4 px); a rotated scanline only passes near
  // pixel centres, so its first and last pixels may sit up to ~2 px inside (u 0.08 of an 8 px
  // edge part).
  for (const auto& [deg, tol] : {std::pair{0.0, 0.04}, std::pair{30.0, 0.08}}) {
    const double angle = deg * kPi / 180, c = std::cos(angle), s = std::sin(angle);
    const RegionUV uv = uv_long_short(mask, cv::Rect(0, 0, mask.cols, mask.rows), angle, tile_w, tile_h);
    std::map<int, std::pair<float, float>> range;   // y' bin -> (min u, max u)
    std::map<int, int> count;
    int steps = 0, good = 0;
    for (int y = 0; y < mask.rows; ++y)
      for (int x = 0; x < mask.cols; ++x) {
        if (!mask(y, x)) continue;
        const double yr = -s * (x + 0.5) + c * (y + 0.5);
        const int bin = static_cast<int>(std::floor(yr));
        const float u = uv.uv(y, x)[0];
        auto it = range.emplace(bin, std::make_pair(u, u)).first;
        it->second.first = std::min(it->second.first, u);
        it->second.second = std::max(it->second.second, u);
        ++count[bin];
        // Three pixels along +y' (rounded onto the grid): v grows by 3/h (mod 1).
        const int x2 = static_cast<int>(std::lround(x - s * 3)), y2 = static_cast<int>(std::lround(y + c * 3));
        if (x2 < 0 || y2 < 0 || x2 >= mask.cols || y2 >= mask.rows || !mask(y2, x2)) continue;
        double dv = uv.uv(y2, x2)[1] - uv.uv(y, x)[1];
        dv -= std::round(dv);   // modulo the tile
        ++steps;
        if (std::abs(dv - 3.0 / tile_h) < 0.06) ++good;
      }
    int lines = 0;
    for (const auto& [bin, r] : range) {
      if (count[bin] < 20) continue;
      ++lines;
      EXPECT_LT(r.first, tol) << deg << " deg, y' " << bin;
      EXPECT_GT(r.second, 1 - tol) << deg << " deg, y' " << bin;
    }
    EXPECT_GT(lines, 80);
    ASSERT_GT(steps, 1000);
    EXPECT_GT(good, 0.95 * steps) << deg << " deg";
  }
  // The centre part repeats: a long run passes through the centre of the tile many times.
  EXPECT_NEAR(long_short_u(0, 200, 32), 0.0, 1e-6);
  EXPECT_NEAR(long_short_u(200, 200, 32), 1.0, 1e-6);
  int wraps = 0;
  for (double x = 1; x <= 200; x += 1)
    if (long_short_u(x, 200, 32) < long_short_u(x - 1, 200, 32)) ++wraps;
  EXPECT_GE(wraps, 10);
}

}  // namespace
}  // namespace atelier::embroidery

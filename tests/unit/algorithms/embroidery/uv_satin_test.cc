// The satin UV map (algorithms/embroidery/uv_satin.h): stitches cross a curved stripe.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>

#include "algorithms/embroidery/uv_satin.h"
#include "tests/unit/algorithms/embroidery/synthesis_fixture.h"

namespace atelier::embroidery {
namespace {

using test::kPi;

TEST(EmbroiderySynthesis, SatinStitchesCrossACurvedStripe) {
  cv::Mat1b mask(260, 300, uchar(0));
  const cv::Point centre(150, 230);
  cv::ellipse(mask, centre, cv::Size(120, 120), 0, 200, 340, 255, 18);
  const RegionUV uv = uv_satin(mask, cv::Rect(0, 0, mask.cols, mask.rows), 64, 4, 0.0);
  int tested = 0, across = 0;
  for (int y = 1; y + 1 < mask.rows; ++y)
    for (int x = 1; x + 1 < mask.cols; ++x) {
      if (!mask(y, x) || !mask(y, x + 1) || !mask(y, x - 1) || !mask(y + 1, x) || !mask(y - 1, x)) continue;
      const double gx = uv.uv(y, x + 1)[0] - uv.uv(y, x - 1)[0], gy = uv.uv(y + 1, x)[0] - uv.uv(y - 1, x)[0];
      if (std::hypot(gx, gy) < 1e-4) continue;
      const cv::Point2d radial(x - centre.x, y - centre.y);
      const cv::Point2d tangent(-radial.y, radial.x);
      const double cosang = std::abs(gx * tangent.x + gy * tangent.y) / (std::hypot(gx, gy) * cv::norm(tangent));
      ++tested;
      if (cosang < std::cos(60 * kPi / 180)) ++across;
    }
  ASSERT_GT(tested, 2000);
  EXPECT_GT(across, 0.85 * tested);
}

}  // namespace
}  // namespace atelier::embroidery

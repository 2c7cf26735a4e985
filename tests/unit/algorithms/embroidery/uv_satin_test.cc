// The satin UV map (algorithms/embroidery/uv_satin.h): stitches cross a curved stripe.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <vector>

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

// Issue 21 point 1: the pairing loop hung when a contour pixel's foot point s equalled a piece
// end (piece + 1) * tile_h rounded to float, below the double value: `s < end` never held, so
// the pass took no pixel and started again at the same one. Tile height of apple.jpg's case
// (the satin tile is 1.2 mm; 388 px over 90 mm).
TEST(UvSatinPairing, APixelOnAFloatRoundedPieceEndIsPairedAndTheLoopEnds) {
  const double tile_h = 1.2 * 388 / 90.0;
  // The first piece end as a float lies below the double one: floor(s / tile_h) = 0, yet
  // s == (float)(1 * tile_h).
  const float s_star = static_cast<float>(tile_h);
  ASSERT_LT(static_cast<double>(s_star), tile_h);
  ASSERT_EQ(std::floor(s_star / tile_h), 0.0);
  const std::vector<SatinContourPx> a = {{0.5f, {0, 0}}, {s_star, {1, 0}}, {s_star + 1.f, {2, 0}}};
  const std::vector<SatinContourPx> b = {{0.7f, {0, 9}}, {s_star + 0.5f, {2, 9}}};
  const std::vector<SatinPair> pairs = pair_satin_sides(a, b, tile_h);
  // Piece 0 holds a[0], a[1] and b[0] (two pairs, one-to-many), piece 1 a[2] and b[1].
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[1].c0, a[1].p);
  EXPECT_EQ(pairs[1].c1, b[0].p);
  EXPECT_FLOAT_EQ(pairs[0].v, 0.25f);
  EXPECT_FLOAT_EQ(pairs[1].v, 0.75f);
  EXPECT_FLOAT_EQ(pairs[2].v, 1.5f);
  EXPECT_FLOAT_EQ(pairs[2].len, 9.f);
}

// Every float of that kind, at every piece end of a long column and for the tile heights of
// widths 380..396 px over 90 mm: each s sits on its own side at a rounded piece end.
TEST(UvSatinPairing, EndsForEveryFloatRoundedPieceEnd) {
  for (int w = 380; w <= 396; ++w) {
    const double tile_h = 1.2 * w / 90.0;
    std::vector<SatinContourPx> a, b;
    for (int k = 0; k < 300; ++k) {
      const float end = static_cast<float>((k + 1) * tile_h);
      a.push_back({end, {static_cast<float>(k), 0}});
      b.push_back({end, {static_cast<float>(k), 5}});
    }
    const std::vector<SatinPair> pairs = pair_satin_sides(a, b, tile_h);
    // Each side's pixel pairs with the other's (same piece, whatever the rounding).
    ASSERT_EQ(pairs.size(), a.size()) << w;
    for (size_t i = 0; i < pairs.size(); ++i) ASSERT_EQ(pairs[i].c0.x, pairs[i].c1.x) << w << " " << i;
  }
}

TEST(UvSatinPairing, OneSidedPiecesAndBadTileHeightsGiveNoPairAndEnd) {
  const std::vector<SatinContourPx> a = {{0.f, {0, 0}}, {100.f, {0, 1}}};
  const std::vector<SatinContourPx> b = {{50.f, {0, 2}}};
  EXPECT_TRUE(pair_satin_sides(a, b, 10.0).empty());
  EXPECT_TRUE(pair_satin_sides(a, a, 0.0).empty());
  EXPECT_TRUE(pair_satin_sides(a, a, std::nan("")).empty());
  EXPECT_EQ(pair_satin_sides(a, a, 1e-300).size(), 2u);   // pieces far beyond int range
}

}  // namespace
}  // namespace atelier::embroidery

// The fabric preview (preview.png): the chart tiled, yarn-overs as open holes where the chart
// puts them, decreases leaning the way a knitter sees them on the right side.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/preview.h"
#include "algorithms/lace/symbols.h"
#include "tests/support/lace_test_charts.h"

namespace atelier::lace {
namespace {

using namespace test;  // row(), knit() and the charts of lace_test_charts.h

// Yarn-overs inside the repeat (none on its edges): 4 per repeat, 8 stitches wide.
Chart eyelets() {
  return Chart{{knit(8), row({"k", "yo", "k2tog", "k", "k", "yo", "k2tog", "k"}), knit(8),
                row({"k", "yo", "sk2p", "yo", "k", "k", "k", "k"})}};
}

// Pixels that look like the cloth under the lace (the background), as a 0/255 mask.
cv::Mat background_mask(const cv::Mat& img, const PreviewOptions& o) {
  cv::Mat diff;
  cv::absdiff(img, cv::Scalar(o.background[0], o.background[1], o.background[2]), diff);
  std::vector<cv::Mat> ch;
  cv::split(diff, ch);
  cv::Mat sum = ch[0] + ch[1] + ch[2];
  return sum < 60;
}

// Background blobs with more than min_area pixels.
int holes(const cv::Mat& img, const PreviewOptions& o, int min_area, int* largest = nullptr) {
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(background_mask(img, o), labels, stats, centroids, 8);
  int count = 0, big = 0;
  for (int i = 1; i < n; ++i) {
    const int area = stats.at<int>(i, cv::CC_STAT_AREA);
    big = std::max(big, area);
    if (area > min_area) ++count;
  }
  if (largest) *largest = big;
  return count;
}

// Ink (yarn) of the stitch at `s`: how far right its upper half sits of its lower half, in
// pixels (positive: the stitch leans right as seen on the right side).
double lean(const cv::Mat& img, const PreviewLayout& layout, const PlacedStitch& s,
            const PreviewOptions& o) {
  cv::Mat gray;
  cv::cvtColor(img, gray, cv::COLOR_BGR2GRAY);
  // The lit crest of the yarn: each loop's highlight runs along the loop, so it shows the
  // direction the stitch lies in (the shaded flanks fill the gaps and would hide it).
  const double lit = 0.95 * o.yarn[1];
  const double half_w = 0.4 * o.stitch_px;  // mostly this stitch, little of its neighbours
  const double top = s.centre.y - 0.8 * layout.row_px, centre = s.centre.y - 0.15 * layout.row_px,
               bottom = s.centre.y + 0.5 * layout.row_px;
  double sx[2] = {0, 0}, n[2] = {0, 0};
  for (int y = std::max(0, cvRound(top)); y <= std::min(gray.rows - 1, cvRound(bottom)); ++y) {
    for (int x = std::max(0, cvRound(s.centre.x - half_w)); x <= std::min(gray.cols - 1, cvRound(s.centre.x + half_w)); ++x) {
      const double v = gray.at<unsigned char>(y, x);
      if (v < lit) continue;
      const int half = y < centre ? 0 : 1;
      sx[half] += x;
      n[half] += 1;
    }
  }
  EXPECT_GT(n[0], 0);
  EXPECT_GT(n[1], 0);
  return sx[0] / n[0] - sx[1] / n[1];
}

TEST(LacePreview, PictureSizeFollowsTheOptions) {
  PreviewOptions o;
  o.repeats_x = 2;
  o.repeats_y = 3;
  o.stitch_px = 10;
  const cv::Mat img = render_preview(eyelets(), 8, o);
  EXPECT_EQ(img.type(), CV_8UC3);
  EXPECT_EQ(img.cols, 8 * 2 * 10);
  EXPECT_EQ(img.rows, 2 * 4 * 3 * 8);  // 4 RS rows, each with its WS row, 3 tiles, 8 px rows
  const cv::Mat dflt = render_preview(eyelets(), 8);
  EXPECT_EQ(dflt.cols, 8 * 3 * 14);
  EXPECT_EQ(dflt.rows, 2 * 4 * 3 * 11);
  // A chart that ends wider than it starts cannot be stacked: one tile high.
  const Chart widening{{row({"k", "yo", "k"})}};
  EXPECT_EQ(render_preview(widening, 2, o).rows, 2 * 1 * 8);
  EXPECT_THROW(render_preview(widening, 3, o), std::invalid_argument);
}

TEST(LacePreview, KnitStitchesFollowTheChartFromTheRight) {
  const PreviewLayout l = layout_preview(eyelets(), 8, {});
  ASSERT_EQ(l.courses.size(), 2u * 4 * 3);
  // Row 0 is at the bottom; knitting-order index 0 is at the right.
  EXPECT_GT(l.courses[0][0].centre.y, l.courses[1][0].centre.y);
  EXPECT_GT(l.courses[0][0].centre.x, l.courses[0][1].centre.x);
  EXPECT_EQ(l.courses[1][0].chart_row, -1);  // the purl row after row 1
  EXPECT_EQ(l.courses[2][1].symbol, Symbol::yo);
  // Every course spans about the picture's width.
  for (const auto& c : l.courses) {
    EXPECT_EQ(c.size(), 24u);
    EXPECT_GT(c.front().centre.x, l.size.width - 14);
    EXPECT_LT(c.back().centre.x, 14);
  }
}

TEST(LacePreview, RowsThatChangeWidthStayAboutAsWideAsTheCastOn) {
  // 6 -> 8 -> 8 -> 6 stitches: the wide rows are squeezed, not spilled over the edges.
  const Chart c{{row({"k", "yo", "k", "k", "k", "k", "yo", "k"}),
                 row({"k", "k", "yo", "k2tog", "ssk", "yo", "k", "k"}),
                 row({"k", "ssk", "k", "k", "k2tog", "k"})}};
  PreviewOptions o;
  o.repeats_x = 2;
  const PreviewLayout l = layout_preview(c, 6, o);
  ASSERT_EQ(l.tiles_y, 3);
  for (const auto& course : l.courses) {
    EXPECT_GT(course.front().centre.x, l.size.width - o.stitch_px);
    EXPECT_LT(course.front().centre.x, l.size.width);
    EXPECT_LT(course.back().centre.x, o.stitch_px);
    EXPECT_GT(course.back().centre.x, 0);
    for (std::size_t j = 1; j < course.size(); ++j)  // knitting order runs leftwards
      EXPECT_LT(course[j].centre.x, course[j - 1].centre.x);
  }
}

TEST(LacePreview, PlainFabricHasNoHolesAndYarnOversDo) {
  const PreviewOptions o;
  const int hole_area = o.stitch_px * o.stitch_px / 4;  // a yarn-over opens more than this
  int largest_gap = 0;
  EXPECT_EQ(holes(render_preview(Chart{{knit(8), knit(8)}}, 8, o), o, hole_area, &largest_gap), 0);
  int largest_hole = 0;
  const cv::Mat lace = render_preview(eyelets(), 8, o);
  EXPECT_EQ(holes(lace, o, hole_area, &largest_hole), 4 * 3 * 3);  // one per yo per tile
  // Holes are clearly larger than the gaps between plain stitches.
  EXPECT_GT(largest_hole, 2 * largest_gap);
  // The holes sit where the yarn-overs are.
  const PreviewLayout l = layout_preview(eyelets(), 8, o);
  const cv::Mat bg = background_mask(lace, o);
  for (const auto& course : l.courses) {
    for (const PlacedStitch& s : course) {
      if (s.symbol != Symbol::yo) continue;
      const cv::Point p(cvRound(s.centre.x), cvRound(s.centre.y - 0.2 * l.row_px));
      EXPECT_EQ(bg.at<unsigned char>(p), 255) << p;
      // ... ringed with yarn (left and right rims of the hole).
      for (int side : {-1, 1}) {
        const cv::Point rim(cvRound(s.centre.x + side * 0.36 * o.stitch_px), p.y);
        if (rim.x < 0 || rim.x >= lace.cols) continue;
        EXPECT_EQ(bg.at<unsigned char>(rim), 0) << rim;
      }
    }
  }
}

TEST(LacePreview, DecreasesLeanAsSeenOnTheRightSide) {
  PreviewOptions o;
  o.repeats_x = o.repeats_y = 1;
  o.stitch_px = 24;
  const Chart c{{knit(12), row({"k", "yo", "k", "k", "k2tog", "k", "k", "ssk", "k", "k", "yo", "k"}),
                 knit(12)}};
  const cv::Mat img = render_preview(c, 12, o);
  const PreviewLayout l = layout_preview(c, 12, o);
  const auto& rs = l.courses[2];  // chart row 1
  ASSERT_EQ(rs[4].symbol, Symbol::k2tog);
  ASSERT_EQ(rs[7].symbol, Symbol::ssk);
  const double plain = lean(img, l, l.courses[0][5], o);
  const double k2tog = lean(img, l, rs[4], o), ssk = lean(img, l, rs[7], o);
  EXPECT_LT(std::abs(plain), 0.05 * o.stitch_px);
  EXPECT_GT(k2tog, 0.08 * o.stitch_px);  // top right of bottom: leans right
  EXPECT_LT(ssk, -0.08 * o.stitch_px);   // leans left
}

// Issue 22, lace point 2: sk2p worked as written leans left, like ssk (its top stitch is the
// right one); it has no centred spine.
TEST(LacePreview, Sk2pLeansLeft) {
  PreviewOptions o;
  o.repeats_x = o.repeats_y = 1;
  o.stitch_px = 24;
  const Chart c{{knit(10), row({"k", "k", "yo", "k", "sk2p", "k", "yo", "k", "k", "k"}), knit(10)}};
  const cv::Mat img = render_preview(c, 10, o);
  const PreviewLayout l = layout_preview(c, 10, o);
  const PlacedStitch& s = l.courses[2][4];
  ASSERT_EQ(s.symbol, Symbol::sk2p);
  // The same chart with the centred s2kp there: sk2p's top sits clearly further left.
  Chart centred = c;
  centred.rows[1][4] = Symbol::s2kp;
  const double upright = lean(render_preview(centred, 10, o), l, s, o);
  const double left = lean(img, l, s, o);
  EXPECT_LT(left, -0.03 * o.stitch_px) << left;
  EXPECT_LT(left, upright - 0.03 * o.stitch_px) << left << " vs s2kp " << upright;
}

// The centred double decrease is s2kp (the evolved charts' double decrease).
TEST(LacePreview, DoubleDecreaseIsCentredWithASpine) {
  PreviewOptions o;
  o.repeats_x = o.repeats_y = 1;
  o.stitch_px = 24;
  const Chart c{{knit(10), row({"k", "k", "yo", "k", "s2kp", "k", "yo", "k", "k", "k"}), knit(10)}};
  const cv::Mat img = render_preview(c, 10, o);
  const PreviewLayout l = layout_preview(c, 10, o);
  const PlacedStitch& s = l.courses[2][4];
  ASSERT_EQ(s.symbol, Symbol::s2kp);
  EXPECT_LT(std::abs(lean(img, l, s, o)), 0.05 * o.stitch_px);
  // The spine: yarn all the way up the stitch's centre line, where a plain V has the edges of
  // its two legs.
  cv::Mat gray;
  cv::cvtColor(img, gray, cv::COLOR_BGR2GRAY);
  auto darkest_on_centre_line = [&](const PlacedStitch& st) {
    const int x = cvRound(st.centre.x);
    const double at = st.centre.y - 0.15 * l.row_px, h = 1.45 * l.row_px;
    int darkest = 255;
    for (int y = cvRound(at - 0.35 * h); y <= cvRound(at + 0.1 * h); ++y)
      darkest = std::min<int>(darkest, gray.at<unsigned char>(y, x));
    return darkest;
  };
  const double mid = (o.yarn[1] + o.background[1]) / 2.0;
  EXPECT_GT(darkest_on_centre_line(s), mid);
  EXPECT_LT(darkest_on_centre_line(l.courses[0][4]), darkest_on_centre_line(s) - 20);
}

}  // namespace
}  // namespace atelier::lace

// A-posteriori cut refinement (paper 3.4, eq. 8-9) on synthetic features: the cut follows
// an edge the wood explains, never costs more than the straight grid, stays a cuttable
// connected curve inside the overlap, and its outlines tile the result.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>

#include "algorithms/parquetry/curved_grid.h"
#include "algorithms/parquetry/cut_refine.h"

namespace atelier::parquetry {
namespace {

using Field = std::function<float(int cell, int x, int y)>;  // result px

// Features of every cell's wood over its window, from a function of result pixels.
SeamInput make_input(int cols, int rows, int pitch, int half, const std::function<float(int, int)>& t1,
                     const std::function<float(int, int)>& t2, const Field& w1, const Field& w2) {
  SeamInput in;
  in.cols = cols;
  in.rows = rows;
  in.pitch = pitch;
  in.half = half;
  const int W = cols * pitch, H = rows * pitch;
  in.target_f1.create(H, W, CV_32F);
  in.target_f2.create(H, W, CV_32F);
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      in.target_f1.at<float>(y, x) = t1(x, y);
      in.target_f2.at<float>(y, x) = t2(x, y);
    }
  }
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const cv::Rect win = cell_window(in, c, r);
      cv::Mat a(win.size(), CV_32F), b(win.size(), CV_32F);
      for (int y = 0; y < win.height; ++y) {
        for (int x = 0; x < win.width; ++x) {
          a.at<float>(y, x) = w1(r * cols + c, win.x + x, win.y + y);
          b.at<float>(y, x) = w2(r * cols + c, win.x + x, win.y + y);
        }
      }
      in.wood_f1.push_back(a);
      in.wood_f2.push_back(b);
    }
  }
  return in;
}

SeamInput random_input(std::mt19937& rng, int cols, int rows, int pitch, int half) {
  cv::theRNG().state = rng();  // cv::randu draws from OpenCV's generator: seed it from ours
  const int W = cols * pitch, H = rows * pitch;
  cv::Mat t1(H, W, CV_32F), t2(H, W, CV_32F);
  cv::randu(t1, 0, 1);
  cv::randu(t2, 0, 1);
  std::vector<cv::Mat> n1, n2;
  for (int k = 0; k < cols * rows; ++k) {
    n1.emplace_back(H, W, CV_32F);
    n2.emplace_back(H, W, CV_32F);
    cv::randu(n1.back(), 0, 1);
    cv::randu(n2.back(), 0, 1);
  }
  return make_input(
      cols, rows, pitch, half, [&](int x, int y) { return t1.at<float>(y, x); },
      [&](int x, int y) { return t2.at<float>(y, x); },
      [&](int k, int x, int y) { return n1[k].at<float>(y, x); },
      [&](int k, int x, int y) { return n2[k].at<float>(y, x); });
}

// Eq. 8 computed here from the labels: the wood of the labelled cell against the target.
double eq8(const SeamInput& in, const cv::Mat& labels) {
  double total = 0;
  for (int y = 0; y < labels.rows; ++y) {
    for (int x = 0; x < labels.cols; ++x) {
      const int k = labels.at<int>(y, x);
      const cv::Rect win = cell_window(in, k % in.cols, k / in.cols);
      EXPECT_TRUE(win.contains(cv::Point(x, y)));
      const double d1 = in.wood_f1[k].at<float>(y - win.y, x - win.x) - in.target_f1.at<float>(y, x);
      const double d2 = in.wood_f2[k].at<float>(y - win.y, x - win.x) - in.target_f2.at<float>(y, x);
      total += d1 * d1 + d2 * d2;
    }
  }
  return total;
}

cv::Mat straight_labels(int cols, int rows, int pitch) {
  cv::Mat l(rows * pitch, cols * pitch, CV_32S);
  for (int y = 0; y < l.rows; ++y) {
    for (int x = 0; x < l.cols; ++x) l.at<int>(y, x) = (y / pitch) * cols + x / pitch;
  }
  return l;
}

// Cuts in their bands, connected, borders fixed; labels as the cuts say; every cell's region
// one 4-connected piece holding the part of its core no band reaches.
void expect_valid(const Seams& s, int cols, int rows, int pitch, int half) {
  const int W = cols * pitch, H = rows * pitch;
  ASSERT_EQ(s.vertical.size(), static_cast<std::size_t>(cols + 1));
  ASSERT_EQ(s.horizontal.size(), static_cast<std::size_t>(rows + 1));
  auto check_cuts = [&](const std::vector<std::vector<int>>& cuts, int n, int length, int end) {
    for (int i = 0; i <= n; ++i) {
      ASSERT_EQ(cuts[i].size(), static_cast<std::size_t>(length));
      for (int k = 0; k < length; ++k) {
        if (i == 0) {
          EXPECT_EQ(cuts[i][k], 0);
        } else if (i == n) {
          EXPECT_EQ(cuts[i][k], end);
        } else {
          EXPECT_GE(cuts[i][k], i * pitch - half);
          EXPECT_LE(cuts[i][k], i * pitch + half);
        }
        if (k > 0) {
          EXPECT_LE(std::abs(cuts[i][k] - cuts[i][k - 1]), 1);
        }
      }
    }
  };
  check_cuts(s.vertical, cols, H, W);
  check_cuts(s.horizontal, rows, W, H);
  const cv::Mat labels = seam_labels(s, cols, rows, W, H);
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      int c = 0, r = 0;
      for (int i = 1; i < cols; ++i) c += s.vertical[i][y] <= x;
      for (int j = 1; j < rows; ++j) r += s.horizontal[j][x] <= y;
      ASSERT_EQ(labels.at<int>(y, x), r * cols + c);
    }
  }
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const cv::Mat mask = labels == r * cols + c;
      cv::Mat comp;
      EXPECT_EQ(cv::connectedComponents(mask, comp, 4), 2) << "cell (" << c << ", " << r << ") in pieces";
      const int x0 = c == 0 ? 0 : c * pitch + half, x1 = c == cols - 1 ? W : (c + 1) * pitch - half;
      const int y0 = r == 0 ? 0 : r * pitch + half, y1 = r == rows - 1 ? H : (r + 1) * pitch - half;
      EXPECT_EQ(cv::countNonZero(mask(cv::Rect(x0, y0, x1 - x0, y1 - y0))), (x1 - x0) * (y1 - y0));
    }
  }
}

TEST(ParquetryCutRefine, CutFollowsASlantedEdgeTheWoodExplains) {
  // Target: 1 left of the edge x = 17.3 + 0.35 y, 0 right of it, inside the overlap band
  // [16, 24] of the line at x = 20. The left cell's wood is 1 everywhere, the right's 0; the
  // second feature is a texture both woods share, so only the first decides.
  const int pitch = 20, half = 4;
  auto edge = [](int y) { return 17.3 + 0.35 * y; };
  auto texture = [](int x, int y) { return static_cast<float>(std::sin(0.7 * x) * std::cos(0.3 * y)); };
  const SeamInput in = make_input(
      2, 1, pitch, half, [&](int x, int y) { return x + 0.5 < edge(y) ? 1.f : 0.f; }, texture,
      [](int cell, int, int) { return cell == 0 ? 1.f : 0.f; }, [&](int, int x, int y) { return texture(x, y); });
  const Seams s = refine_seams(in);
  expect_valid(s, 2, 1, pitch, half);
  for (int y = 0; y < pitch; ++y) EXPECT_LE(std::abs(s.vertical[1][y] - edge(y)), 1.0) << "row " << y;
  EXPECT_LT(s.refined_cost, s.straight_cost);
  EXPECT_NEAR(s.refined_cost, 0.0, 1e-9);  // the edge is cut exactly: every pixel from its own wood
  EXPECT_NEAR(s.straight_cost, eq8(in, straight_labels(2, 1, pitch)), 1e-9);
  EXPECT_GT(s.straight_cost, 10);  // the straight cut gives wrong wood to a wedge of pixels
}

TEST(ParquetryCutRefine, RefinedNeverCostsMoreThanStraightAndCostsAreEq8) {
  std::mt19937 rng(5);
  int improved = 0;
  const int runs = 120;
  for (int run = 0; run < runs; ++run) {
    const int cols = 1 + static_cast<int>(rng() % 4), rows = 1 + static_cast<int>(rng() % 4);
    const int pitch = 3 + static_cast<int>(rng() % 8);
    const int half = 1 + static_cast<int>(rng() % static_cast<unsigned>((pitch - 1) / 2));
    const SeamInput in = random_input(rng, cols, rows, pitch, half);
    const Seams s = refine_seams(in);
    SCOPED_TRACE(testing::Message() << "run " << run << ": " << cols << "x" << rows << " pitch " << pitch
                                    << " half " << half);
    EXPECT_LE(s.refined_cost, s.straight_cost);
    EXPECT_NEAR(s.straight_cost, eq8(in, straight_labels(cols, rows, pitch)), 1e-9 * s.straight_cost);
    const cv::Mat labels = seam_labels(s, cols, rows, cols * pitch, rows * pitch);
    EXPECT_NEAR(s.refined_cost, eq8(in, labels), 1e-9 * s.straight_cost);
    improved += cols * rows > 1 && s.refined_cost < s.straight_cost;
    expect_valid(s, cols, rows, pitch, half);
  }
  // On noise some band pixel always prefers the other wood: with more than one cell the
  // refinement finds a cheaper cut almost every time.
  EXPECT_GT(improved, runs / 2);
}

TEST(ParquetryCutRefine, MoreAlternationsNeverCostMore) {
  std::mt19937 rng(11);
  for (int run = 0; run < 20; ++run) {
    const SeamInput in = random_input(rng, 4, 3, 7, 2);
    double last = refine_seams(in, 0).refined_cost;
    EXPECT_NEAR(last, refine_seams(in, 0).straight_cost, 1e-12);
    for (int it = 1; it <= 3; ++it) {
      const double cost = refine_seams(in, it).refined_cost;
      EXPECT_LE(cost, last) << "iterations " << it;
      last = cost;
    }
  }
}

TEST(ParquetryCutRefine, CutsAreConnectedInTheirBandsAndCellsStayWhole) {
  // The eye plan's grid (28 x 17 cells of 7 px) with noise features: every cut bends, and
  // where four patches meet the cuts must still leave each cell one piece.
  std::mt19937 rng(3);
  for (int half : {1, 2, 3}) {
    const int cols = 28, rows = 17, pitch = 7;
    const SeamInput in = random_input(rng, cols, rows, pitch, half);
    const Seams s = refine_seams(in);
    SCOPED_TRACE(testing::Message() << "half " << half);
    expect_valid(s, cols, rows, pitch, half);
    EXPECT_LT(s.refined_cost, s.straight_cost);
    bool bent = false;
    for (int i = 1; i < cols; ++i) {
      for (int y = 1; y < rows * pitch; ++y) bent |= s.vertical[i][y] != s.vertical[i][y - 1];
    }
    for (int j = 1; j < rows; ++j) {
      for (int x = 1; x < cols * pitch; ++x) bent |= s.horizontal[j][x] != s.horizontal[j][x - 1];
    }
    EXPECT_TRUE(bent) << "noise should bend some cut";
  }
}

TEST(ParquetryCutRefine, RejectsInconsistentInput) {
  std::mt19937 rng(1);
  SeamInput in = random_input(rng, 3, 2, 7, 2);
  SeamInput wide = in;
  wide.half = 4;  // 2 * half >= pitch
  EXPECT_THROW(refine_seams(wide), std::invalid_argument);
  SeamInput missing = in;
  missing.wood_f2.pop_back();
  EXPECT_THROW(refine_seams(missing), std::invalid_argument);
  SeamInput small = in;
  small.wood_f1[2] = cv::Mat::zeros(7, 7, CV_32F);
  EXPECT_THROW(refine_seams(small), std::invalid_argument);
  EXPECT_THROW(refine_seams(in, -1), std::invalid_argument);
}

// Samples of the result at `scale` per px inside exactly one outline (or on a cut).
void expect_outlines_tile(const std::vector<Outline>& cells, int W, int H, double scale) {
  std::vector<std::vector<cv::Point2f>> polys;
  double area = 0;
  for (const Outline& o : cells) {
    const std::vector<cv::Point2d> p = flatten(o, 0.002);
    area += std::abs(polygon_area(p));
    std::vector<cv::Point2f> f;
    for (const auto& q : p) f.emplace_back(static_cast<float>(q.x * scale), static_cast<float>(q.y * scale));
    polys.push_back(f);
  }
  EXPECT_NEAR(area, W * H, 1e-3 * W * H);
  std::vector<cv::Rect> boxes;
  for (const auto& p : polys) boxes.push_back(cv::boundingRect(p));
  int twice = 0, none = 0;
  for (int y = 0; y < H * scale; ++y) {
    for (int x = 0; x < W * scale; ++x) {
      int inside = 0;
      double nearest = 1e9;
      for (std::size_t k = 0; k < polys.size(); ++k) {
        const cv::Rect b(boxes[k].x - 1, boxes[k].y - 1, boxes[k].width + 2, boxes[k].height + 2);
        if (!b.contains(cv::Point(x, y))) continue;
        const double d = cv::pointPolygonTest(polys[k], cv::Point2f(x + 0.5f, y + 0.5f), true);
        inside += d > 0;
        nearest = std::min(nearest, std::abs(d));
      }
      if (nearest < 0.01 * scale) continue;
      twice += inside > 1;
      none += inside == 0;
    }
  }
  EXPECT_EQ(twice, 0);
  EXPECT_EQ(none, 0);
}

TEST(ParquetryCutRefine, SeamLinesGiveOutlinesThatTileAndStayInTheBands) {
  std::mt19937 rng(7);
  for (int half : {1, 2}) {
    const int cols = 6, rows = 4, pitch = 7, W = cols * pitch, H = rows * pitch;
    const SeamInput in = random_input(rng, cols, rows, pitch, half);
    const Seams s = refine_seams(in);
    const GridLines g = seam_lines(s, cols, rows, pitch, 3.0);
    const std::vector<Outline> cells = cell_outlines(g);
    ASSERT_EQ(cells.size(), static_cast<std::size_t>(cols * rows));
    expect_outlines_tile(cells, W, H, 6.0);
    // Each cell's outline stays inside its window: the wood matched for it is the wood cut.
    double worst = 0;
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        const cv::Rect win = cell_window(in, c, r);
        for (const cv::Point2d& p : flatten(cells[r * cols + c], 0.002)) {
          worst = std::max({worst, win.x - p.x, p.x - (win.x + win.width), win.y - p.y, p.y - (win.y + win.height)});
        }
      }
    }
    EXPECT_LE(worst, 1e-9) << "half " << half;
    // Smoothed: the lines follow the cuts, within a pixel, but not as stairs.
    for (int i = 1; i < cols; ++i) {
      for (const cv::Point2d& p : g.vertical[i]) {
        const int y = std::clamp(static_cast<int>(p.y), 0, H - 1);
        EXPECT_LE(std::abs(p.x - s.vertical[i][y]), 1.0 + 1e-9);
      }
    }
  }
}

// A cut that jitters a pixel every other row around one long bump (what the DP leaves where
// the wood barely matters) is laid as one smooth bulge: the curve turns back at most twice
// (into the bump and out), never in small S-wiggles, and it still follows the bump.
TEST(ParquetryCutRefine, SeamLinesSmoothJitterIntoOneGentleCurve) {
  const int cols = 2, rows = 1, pitch = 40, H = rows * pitch;
  Seams s;
  s.vertical = {std::vector<int>(H, 0), std::vector<int>(H, pitch), std::vector<int>(H, 2 * pitch)};
  s.horizontal = {std::vector<int>(2 * pitch, 0), std::vector<int>(2 * pitch, H)};
  std::mt19937 rng(7);
  std::bernoulli_distribution jitter(0.5);
  for (int y = 0; y < H; ++y) {
    const int bump = (y >= 12 && y < 28) ? 4 : 0;
    s.vertical[1][y] = pitch + bump + (jitter(rng) ? 1 : 0);
  }
  const GridLines g = seam_lines(s, cols, rows, pitch, 6.0);  // knots every 6 px
  const std::vector<Outline> cells = cell_outlines(g);
  // The right edge of cell 0 is the cut: its x along y, flattened finely.
  std::vector<cv::Point2d> poly = flatten(cells[0], 0.01);
  std::vector<cv::Point2d> cut;
  for (const cv::Point2d& q : poly) {
    if (q.x > pitch / 2.0) cut.push_back(q);
  }
  std::sort(cut.begin(), cut.end(), [](const cv::Point2d& a, const cv::Point2d& b) { return a.y < b.y; });
  int turns = 0, last = 0;
  double most = 0;
  for (std::size_t k = 1; k < cut.size(); ++k) {
    const double dx = cut[k].x - cut[k - 1].x;
    if (std::abs(dx) < 1e-6) continue;
    const int dir = dx > 0 ? 1 : -1;
    if (last != 0 && dir != last) ++turns;
    last = dir;
    most = std::max(most, cut[k].x - pitch);
  }
  EXPECT_LE(turns, 2);
  EXPECT_GT(most, 2.0);  // the bump is kept (smoothed, not flattened away)
  EXPECT_LT(most, 5.0 + 1e-9);  // inside the cut's own range
}

TEST(ParquetryCutRefine, SeamLinesRejectAVerticalCutBendingAcrossAHorizontalOne) {
  Seams s;
  const int cols = 2, rows = 2, pitch = 7, W = 14, H = 14;
  s.vertical = {std::vector<int>(H, 0), std::vector<int>(H, 7), std::vector<int>(H, W)};
  s.horizontal = {std::vector<int>(W, 0), std::vector<int>(W, 7), std::vector<int>(W, H)};
  s.vertical[1][7] = 8;  // a step right where horizontal cut 1 passes
  EXPECT_THROW(seam_lines(s, cols, rows, pitch, 3.0), std::invalid_argument);
  s.vertical[1][7] = 7;
  EXPECT_NO_THROW(seam_lines(s, cols, rows, pitch, 3.0));
}

}  // namespace
}  // namespace atelier::parquetry

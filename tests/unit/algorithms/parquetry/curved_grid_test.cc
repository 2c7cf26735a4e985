// Curvilinear grid outlines (paper 3.4): the cells of a regular or wavy grid tile the result
// with no gap or overlap, and neighbours share the very same curve, so the laser cuts each
// edge once and the pieces fit.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "algorithms/parquetry/curved_grid.h"

namespace atelier::parquetry {
namespace {

bool same(const Cubic& a, const Cubic& b) {
  return a.p0 == b.p0 && a.c1 == b.c1 && a.c2 == b.c2 && a.p3 == b.p3;
}

Cubic flipped(const Cubic& c) { return {c.p3, c.c2, c.c1, c.p0}; }

// A grid whose inner lines wave by `amp` around their grid positions, sampled every
// pitch / 3 (so crossings fall between the samples and must be found and inserted).
GridLines wavy_lines(int cols, int rows, double pitch, double amp) {
  GridLines g = regular_lines(cols, rows, pitch);
  const double W = cols * pitch, H = rows * pitch;
  for (int i = 1; i < cols; ++i) {
    std::vector<cv::Point2d> line;
    for (double y = 0; y <= H + 1e-9; y += pitch / 3) {
      line.push_back({i * pitch + amp * std::sin(0.37 * y + i), y});
    }
    g.vertical[i] = line;
  }
  for (int j = 1; j < rows; ++j) {
    std::vector<cv::Point2d> line;
    for (double x = 0; x <= W + 1e-9; x += pitch / 3.5) {
      line.push_back({x, j * pitch + amp * std::cos(0.29 * x + 2 * j)});
    }
    line.back().x = W;
    g.horizontal[j] = line;
  }
  return g;
}

// Checks that the flattened cells cover every point of the W x H result exactly once: the
// areas add up, and at `scale` samples per unit every sample centre lies in exactly one cell
// (or on a boundary, within `edge`).
void expect_tiling(const std::vector<Outline>& cells, double W, double H, double scale) {
  std::vector<std::vector<cv::Point2f>> polys;
  double area = 0;
  for (const Outline& o : cells) {
    const std::vector<cv::Point2d> p = flatten(o, 0.002);
    const double a = polygon_area(p);
    EXPECT_GT(a, 0) << "a cell is not clockwise";
    area += std::abs(a);
    std::vector<cv::Point2f> f;
    for (const auto& q : p) f.emplace_back(static_cast<float>(q.x * scale), static_cast<float>(q.y * scale));
    polys.push_back(f);
  }
  EXPECT_NEAR(area, W * H, 1e-3 * W * H);
  std::vector<cv::Rect> boxes;
  for (const auto& p : polys) boxes.push_back(cv::boundingRect(p));
  const int w = static_cast<int>(std::lround(W * scale)), h = static_cast<int>(std::lround(H * scale));
  int twice = 0, none = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const cv::Point2f c(x + 0.5f, y + 0.5f);
      int inside = 0;
      double nearest = 1e9;
      for (std::size_t k = 0; k < polys.size(); ++k) {
        if (!(cv::Rect(boxes[k].x - 1, boxes[k].y - 1, boxes[k].width + 2, boxes[k].height + 2).contains(cv::Point(x, y)))) continue;
        const double d = cv::pointPolygonTest(polys[k], c, true);
        if (d > 0) ++inside;
        nearest = std::min(nearest, std::abs(d));
      }
      if (nearest < 0.01 * scale) continue;  // on a cut: either side is right
      twice += inside > 1;
      none += inside == 0;
    }
  }
  EXPECT_EQ(twice, 0) << "samples covered by two cells";
  EXPECT_EQ(none, 0) << "samples covered by no cell";
}

// Every non-border segment of a cell is, reversed, exactly one segment of one of its four
// neighbours, and the segments a cell shares with one neighbour form one run.
void expect_shared_edges(const std::vector<Outline>& cells, int cols, int rows, double W, double H) {
  auto on_border = [&](const Cubic& c) {
    auto all = [&](auto pred) { return pred(c.p0) && pred(c.c1) && pred(c.c2) && pred(c.p3); };
    return all([](cv::Point2d p) { return p.x == 0; }) || all([&](cv::Point2d p) { return p.x == W; }) ||
           all([](cv::Point2d p) { return p.y == 0; }) || all([&](cv::Point2d p) { return p.y == H; });
  };
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const Outline& a = cells[r * cols + c];
      const int nb[4][2] = {{c, r - 1}, {c + 1, r}, {c, r + 1}, {c - 1, r}};
      std::vector<int> owner(a.size(), -1);
      for (std::size_t k = 0; k < a.size(); ++k) {
        int matches = 0;
        for (int n = 0; n < 4; ++n) {
          const int nc = nb[n][0], nr = nb[n][1];
          if (nc < 0 || nr < 0 || nc >= cols || nr >= rows) continue;
          for (const Cubic& b : cells[nr * cols + nc]) {
            if (same(flipped(a[k]), b)) {
              ++matches;
              owner[k] = n;
            }
          }
        }
        if (on_border(a[k])) {
          EXPECT_EQ(matches, 0);
        } else {
          EXPECT_EQ(matches, 1) << "cell (" << c << ", " << r << ") segment " << k;
        }
      }
      // Runs: the owner changes at most 4 times going round (top, right, bottom, left).
      int changes = 0;
      for (std::size_t k = 0; k < a.size(); ++k) changes += owner[k] != owner[(k + 1) % a.size()];
      EXPECT_LE(changes, 4) << "cell (" << c << ", " << r << ")";
    }
  }
}

TEST(ParquetryCurvedGrid, RegularGridGivesSquaresOfThePitch) {
  const GridLines g = regular_lines(4, 3, 14.0);
  ASSERT_EQ(g.vertical.size(), 5u);
  ASSERT_EQ(g.horizontal.size(), 4u);
  const std::vector<Outline> cells = cell_outlines(g);
  ASSERT_EQ(cells.size(), 12u);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      const Outline& o = cells[r * 4 + c];
      EXPECT_EQ(o.front().p0, cv::Point2d(c * 14.0, r * 14.0)) << "starts at its top-left crossing";
      const std::vector<cv::Point2d> p = flatten(o, 1e-3);
      EXPECT_NEAR(polygon_area(p), 196.0, 1e-9);
      // Straight: every control point on the square's sides.
      for (const Cubic& s : o) {
        for (cv::Point2d q : {s.c1, s.c2}) {
          const bool on_side = std::abs(q.x - c * 14.0) < 1e-9 || std::abs(q.x - (c + 1) * 14.0) < 1e-9 ||
                               std::abs(q.y - r * 14.0) < 1e-9 || std::abs(q.y - (r + 1) * 14.0) < 1e-9;
          EXPECT_TRUE(on_side);
        }
      }
    }
  }
  expect_shared_edges(cells, 4, 3, 56.0, 42.0);
}

TEST(ParquetryCurvedGrid, StraightLinesWithManyPointsStayStraight) {
  // Unevenly spaced collinear points: a Catmull-Rom fit would wander back and forth along
  // the line; the cells must still be exact squares.
  GridLines g = regular_lines(2, 2, 10.0);
  g.vertical[1] = {{10, 0}, {10, 0.3}, {10, 9.7}, {10, 10.05}, {10, 20}};
  g.horizontal[1] = {{0, 10}, {1, 10}, {9.99, 10}, {19, 10}, {20, 10}};
  const std::vector<Outline> cells = cell_outlines(g);
  for (const Outline& o : cells) {
    EXPECT_NEAR(polygon_area(flatten(o, 1e-4)), 100.0, 1e-9);
    for (const Cubic& s : o) {
      // Control points at the thirds of their segment: straight and monotone.
      EXPECT_NEAR(cv::norm(s.c1 - (s.p0 + (s.p3 - s.p0) / 3.0)), 0, 1e-9);
      EXPECT_NEAR(cv::norm(s.c2 - (s.p0 + (s.p3 - s.p0) * (2.0 / 3.0))), 0, 1e-9);
    }
  }
}

TEST(ParquetryCurvedGrid, WavyGridCellsTileTheResultAndShareTheirEdges) {
  const int cols = 5, rows = 4;
  const double pitch = 12;
  const std::vector<Outline> cells = cell_outlines(wavy_lines(cols, rows, pitch, 2.5));
  ASSERT_EQ(cells.size(), static_cast<std::size_t>(cols * rows));
  // Curved indeed: some control point off every straight line between crossings.
  bool curved = false;
  for (const Outline& o : cells) {
    for (const Cubic& s : o) curved |= cv::norm(s.c1 - (s.p0 + (s.p3 - s.p0) / 3.0)) > 0.05;
  }
  EXPECT_TRUE(curved);
  expect_tiling(cells, cols * pitch, rows * pitch, 8.0);
  expect_shared_edges(cells, cols, rows, cols * pitch, rows * pitch);
}

TEST(ParquetryCurvedGrid, CrossingOnALinePointIsOneKnot) {
  // The vertical line has a point exactly where the horizontal line crosses it: no zero-length
  // segment appears and the outlines still tile.
  GridLines g = regular_lines(2, 2, 10.0);
  g.vertical[1] = {{10, 0}, {11, 5}, {10, 10}, {9, 15}, {10, 20}};
  g.horizontal[1] = {{0, 10}, {5, 11}, {15, 9}, {20, 10}};
  const std::vector<Outline> cells = cell_outlines(g);
  for (const Outline& o : cells) {
    for (const Cubic& s : o) EXPECT_GT(cv::norm(s.p3 - s.p0), 1e-3);
  }
  expect_tiling(cells, 20, 20, 10.0);
  expect_shared_edges(cells, 2, 2, 20, 20);
}

TEST(ParquetryCurvedGrid, LinesThatDoNotCrossAreNamed) {
  GridLines g = regular_lines(3, 2, 10.0);
  g.horizontal[1] = {{0, 10}, {15, 10}};  // stops short of vertical lines 2 and 3
  try {
    cell_outlines(g);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("vertical line 2 and horizontal line 1"), std::string::npos) << e.what();
  }
  GridLines twice = regular_lines(2, 2, 10.0);
  twice.vertical[1] = {{10, 0}, {10, 12}, {8, 8}, {8, 20}};  // back up across horizontal 1
  EXPECT_THROW(cell_outlines(twice), std::invalid_argument);
  GridLines counts = regular_lines(2, 2, 10.0);
  counts.vertical.pop_back();
  EXPECT_THROW(cell_outlines(counts), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::parquetry

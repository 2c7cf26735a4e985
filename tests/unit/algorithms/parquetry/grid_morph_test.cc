// A-priori grid morphing (paper 3.4, eq. 5-7): grid lines snap to the image's large edges and
// every cell stays cuttable.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/parquetry/grid_morph.h"

namespace atelier::parquetry {
namespace {

constexpr double kPitch = 30;

cv::Point2d vertex(const GridLines& g, int i, int j) { return g.vertical[i][j]; }

// The lines are the grid they claim to be: counts, and vertex (i, j) the same in both lists.
void expect_consistent(const GridLines& g, int cols, int rows) {
  ASSERT_EQ(g.cols, cols);
  ASSERT_EQ(g.rows, rows);
  ASSERT_EQ(g.vertical.size(), static_cast<std::size_t>(cols + 1));
  ASSERT_EQ(g.horizontal.size(), static_cast<std::size_t>(rows + 1));
  for (int i = 0; i <= cols; ++i) {
    ASSERT_EQ(g.vertical[i].size(), static_cast<std::size_t>(rows + 1));
    for (int j = 0; j <= rows; ++j) {
      ASSERT_EQ(g.horizontal[j].size(), static_cast<std::size_t>(cols + 1));
      EXPECT_EQ(g.vertical[i][j], g.horizontal[j][i]);
    }
  }
}

bool segments_cross(cv::Point2d a, cv::Point2d b, cv::Point2d c, cv::Point2d d) {
  auto side = [](cv::Point2d p, cv::Point2d q, cv::Point2d r) { return (q - p).cross(r - p); };
  return side(a, b, c) * side(a, b, d) < 0 && side(c, d, a) * side(c, d, b) < 0;
}

// What a cutter needs: corners fixed, borders straight, every cell a convex quad with positive
// area and edges >= min_edge, and no two grid edges crossing.
void expect_fabricable(const GridLines& g, double min_edge) {
  const int cols = g.cols, rows = g.rows;
  EXPECT_EQ(vertex(g, 0, 0), cv::Point2d(0, 0));
  EXPECT_EQ(vertex(g, cols, rows), cv::Point2d(cols * kPitch, rows * kPitch));
  for (int j = 0; j <= rows; ++j) {
    EXPECT_EQ(vertex(g, 0, j).x, 0);
    EXPECT_EQ(vertex(g, cols, j).x, cols * kPitch);
  }
  for (int i = 0; i <= cols; ++i) {
    EXPECT_EQ(vertex(g, i, 0).y, 0);
    EXPECT_EQ(vertex(g, i, rows).y, rows * kPitch);
  }
  std::vector<std::pair<cv::Point2d, cv::Point2d>> edges;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const cv::Point2d q[4] = {vertex(g, c, r), vertex(g, c + 1, r), vertex(g, c + 1, r + 1), vertex(g, c, r + 1)};
      double area = 0;
      for (int k = 0; k < 4; ++k) {
        const cv::Point2d e = q[(k + 1) % 4] - q[k], f = q[(k + 2) % 4] - q[(k + 1) % 4];
        EXPECT_GE(cv::norm(e), min_edge - 1e-9) << "cell " << c << "," << r;
        EXPECT_GT(e.cross(f), 0) << "cell " << c << "," << r << " is not convex";
        area += q[k].cross(q[(k + 1) % 4]) / 2;
      }
      EXPECT_GT(area, 0) << "cell " << c << "," << r;
    }
  }
  for (int i = 0; i <= cols; ++i) {
    for (int j = 0; j < rows; ++j) edges.push_back({vertex(g, i, j), vertex(g, i, j + 1)});
  }
  for (int j = 0; j <= rows; ++j) {
    for (int i = 0; i < cols; ++i) edges.push_back({vertex(g, i, j), vertex(g, i + 1, j)});
  }
  int crossings = 0;
  for (std::size_t a = 0; a < edges.size(); ++a) {
    for (std::size_t b = a + 1; b < edges.size(); ++b) {
      crossings += segments_cross(edges[a].first, edges[a].second, edges[b].first, edges[b].second);
    }
  }
  EXPECT_EQ(crossings, 0);
}

TEST(ParquetryGridMorph, PotentialIsEquationSix) {
  cv::Mat edges = cv::Mat::zeros(10, 100, CV_8UC1);
  edges.col(50).setTo(255);
  const cv::Mat p = edge_potential(edges, 20);
  ASSERT_EQ(p.type(), CV_32F);
  EXPECT_NEAR(p.at<float>(5, 50), 0, 1e-4);   // on the edge
  EXPECT_NEAR(p.at<float>(5, 55), 5, 1e-3);   // rising: D
  EXPECT_NEAR(p.at<float>(5, 60), 10, 1e-3);  // the crest at r / 2
  EXPECT_NEAR(p.at<float>(5, 44), 6, 1e-3);   // either side
  EXPECT_NEAR(p.at<float>(5, 65), 5, 1e-3);   // falling: r - D
  EXPECT_NEAR(p.at<float>(5, 75), 0, 1e-3);   // beyond r: flat
  EXPECT_NEAR(p.at<float>(5, 90), 0, 1e-3);
  const cv::Mat none = edge_potential(cv::Mat::zeros(10, 10, CV_8UC1), 20);
  EXPECT_EQ(cv::countNonZero(none), 0);
}

TEST(ParquetryGridMorph, EdgesKeepLargeShapesAndDropSmallTexture) {
  // A 120 px bright square (a shape a patch boundary should follow) and 3 px specks every 10 px
  // (texture the wood grain renders, smaller than a patch).
  cv::Mat img(240, 360, CV_8UC3, cv::Scalar(60, 60, 60));
  for (int y = 5; y < 235; y += 10) {
    for (int x = 185; x < 355; x += 10) cv::rectangle(img, {x, y, 3, 3}, cv::Scalar(200, 200, 200), cv::FILLED);
  }
  cv::rectangle(img, {40, 60, 120, 120}, cv::Scalar(220, 220, 220), cv::FILLED);
  const cv::Mat e = morph_edges(img, kPitch);
  ASSERT_EQ(e.type(), CV_8UC1);
  ASSERT_EQ(e.size(), img.size());
  // The square's outline is found: most of its 480 px perimeter lies within 1 px of an edge.
  cv::Mat near_edge;
  cv::dilate(e, near_edge, cv::Mat::ones(3, 3, CV_8UC1));
  int found = 0;
  for (int t = 0; t < 120; ++t) {
    found += near_edge.at<uchar>(60, 40 + t) > 0;
    found += near_edge.at<uchar>(179, 40 + t) > 0;
    found += near_edge.at<uchar>(60 + t, 40) > 0;
    found += near_edge.at<uchar>(60 + t, 159) > 0;
  }
  EXPECT_GT(found, 0.9 * 480);
  // The speckled half stays (nearly) free of edges; 24 x 17 specks would give ~4900 px.
  EXPECT_LT(cv::countNonZero(e.colRange(180, 360)), 50);
  // Every value is 0 or 255.
  EXPECT_EQ(cv::countNonZero(e == 0) + cv::countNonZero(e == 255), e.rows * e.cols);
}

TEST(ParquetryGridMorph, AFlatImageLeavesTheGridRegular) {
  const cv::Mat flat(8 * kPitch, 12 * kPitch, CV_8UC3, cv::Scalar(120, 130, 140));
  const GridLines g = morph_grid(flat, 12, 8, kPitch, 10);
  expect_consistent(g, 12, 8);
  for (int i = 0; i <= 12; ++i) {
    for (int j = 0; j <= 8; ++j) {
      EXPECT_LT(cv::norm(vertex(g, i, j) - cv::Point2d(i * kPitch, j * kPitch)), 0.1);
    }
  }
}

TEST(ParquetryGridMorph, AStepEdgePullsTheNearestLineOntoIt) {
  // A vertical step a third of a pitch right of grid line 4.
  const double edge_x = 4 * kPitch + kPitch / 3;  // 130 px
  cv::Mat img(8 * kPitch, 12 * kPitch, CV_8UC3, cv::Scalar(40, 40, 40));
  img.colRange(static_cast<int>(edge_x), img.cols).setTo(cv::Scalar(210, 210, 210));
  const GridLines g = morph_grid(img, 12, 8, kPitch, 10);
  expect_consistent(g, 12, 8);
  expect_fabricable(g, 10);
  double before = 0, after = 0;
  for (int j = 0; j <= 8; ++j) {
    before += std::abs(4 * kPitch - edge_x);
    after += std::abs(vertex(g, 4, j).x - edge_x);
  }
  before /= 9;
  after /= 9;
  EXPECT_LT(after, 0.5 * before) << "mean distance " << before << " -> " << after << " px";
  EXPECT_LT(after, 2.0);  // on the edge, give or take the pixel Canny marks
  // The line stays straight: the edge is.
  for (int j = 1; j <= 8; ++j) EXPECT_NEAR(vertex(g, 4, j).x, vertex(g, 4, 0).x, 0.5);
}

TEST(ParquetryGridMorph, ACircleDrawsTheNearbyVerticesOntoIt) {
  const cv::Point2d centre(6 * kPitch, 6 * kPitch);
  const double radius = 2.6 * kPitch;
  cv::Mat img(12 * kPitch, 12 * kPitch, CV_8UC3, cv::Scalar(30, 50, 70));
  cv::circle(img, cv::Point(static_cast<int>(centre.x), static_cast<int>(centre.y)),
             static_cast<int>(radius), cv::Scalar(200, 220, 240), cv::FILLED, cv::LINE_AA);
  const GridLines g = morph_grid(img, 12, 12, kPitch, 10);
  expect_consistent(g, 12, 12);
  expect_fabricable(g, 10);
  double before = 0, after = 0;
  int nearby = 0;
  for (int i = 0; i <= 12; ++i) {
    for (int j = 0; j <= 12; ++j) {
      const double d0 = std::abs(cv::norm(cv::Point2d(i * kPitch, j * kPitch) - centre) - radius);
      if (d0 >= kPitch / 2) continue;  // the attraction zone: half a pitch
      ++nearby;
      before += d0;
      after += std::abs(cv::norm(vertex(g, i, j) - centre) - radius);
    }
  }
  ASSERT_GE(nearby, 12);
  EXPECT_LT(after, 0.5 * before) << nearby << " vertices, mean distance " << before / nearby << " -> "
                                 << after / nearby << " px";
}

TEST(ParquetryGridMorph, APhotoMorphsIntoFabricableCells) {
  cv::Mat photo = cv::imread(ATELIER_TEST_DATA "/fruits.jpg", cv::IMREAD_COLOR);
  ASSERT_FALSE(photo.empty());
  cv::resize(photo, photo, cv::Size(16 * kPitch, 12 * kPitch), 0, 0, cv::INTER_AREA);
  const double min_edge = 12;
  const GridLines g = morph_grid(photo, 16, 12, kPitch, min_edge);
  expect_consistent(g, 16, 12);
  expect_fabricable(g, min_edge);
  // It did morph: some vertices moved by a good fraction of a pitch.
  int moved = 0;
  for (int i = 0; i <= 16; ++i) {
    for (int j = 0; j <= 12; ++j) moved += cv::norm(vertex(g, i, j) - cv::Point2d(i * kPitch, j * kPitch)) > 5;
  }
  EXPECT_GE(moved, 10);
  // Deterministic.
  const GridLines again = morph_grid(photo, 16, 12, kPitch, min_edge);
  EXPECT_EQ(again.vertical, g.vertical);
  EXPECT_EQ(again.horizontal, g.horizontal);
}

TEST(ParquetryGridMorph, ATightMinimumEdgeHoldsAgainstStrongEdges) {
  // Stripes every 10 px pull vertices from both sides; cells may not shrink below 24 px.
  cv::Mat img(8 * kPitch, 8 * kPitch, CV_8UC3, cv::Scalar(0, 0, 0));
  for (int x = 0; x < img.cols; x += 20) img.colRange(x, x + 10).setTo(cv::Scalar(255, 255, 255));
  for (int y = 0; y < img.rows; y += 40) img.rowRange(y, y + 20) = cv::Scalar(255, 255, 255) - img.rowRange(y, y + 20);
  const GridLines g = morph_grid(img, 8, 8, kPitch, 24);
  expect_fabricable(g, 24);
}

TEST(ParquetryGridMorph, RejectsAGridThatCannotBeCut) {
  const cv::Mat flat(60, 60, CV_8UC3, cv::Scalar::all(0));
  EXPECT_THROW(morph_grid(flat, 2, 2, kPitch, kPitch + 1), std::invalid_argument);
  EXPECT_THROW(morph_grid(flat, 0, 2, kPitch, 10), std::invalid_argument);
  EXPECT_THROW(morph_grid(cv::Mat(), 2, 2, kPitch, 10), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::parquetry

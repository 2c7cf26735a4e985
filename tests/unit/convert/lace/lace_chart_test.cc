// The printable lace chart (chart.svg, chart.pdf): files are written; the drawing shows each
// symbol where the chart puts it (row 1 at the bottom, stitch 1 on the right), with a legend.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unistd.h>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/symbols.h"
#include "convert/common/convert_error.h"
#include "convert/lace/lace_chart.h"
#include "tests/support/lace_test_charts.h"

namespace atelier {
namespace {

using lace::Chart;
using lace::Row;
using lace::Symbol;
using namespace lace::test;  // row(), knit() and the charts of lace_test_charts.h

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

int count(const std::string& text, const std::string& needle) {
  int n = 0;
  for (std::size_t p = text.find(needle); p != std::string::npos; p = text.find(needle, p + 1)) ++n;
  return n;
}

class LaceChartRender : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("atelier_lace_chart_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

// Every symbol, and a row wider than the others (6 -> 7 -> 6 -> 6 stitches).
Chart sampler() {
  return Chart{{row({"k", "yo", "k2tog", "yo", "ssk", "k"}),       // 6 over 6
                row({"k", "yo", "k", "k", "k", "k", "k"}),        // 7 over 6
                row({"k", "sk2p", "yo", "k", "k", "k"}),
                row({"k", "yo", "s2kp", "yo", "k", "k"})}};
}

// Ink (dark pixels) in a small square around the point (fx, fy) of a cell, fractions of its
// size from its top-left corner.
double ink(const cv::Mat& img, const cv::Rect2d& cell, double fx, double fy) {
  const int x = static_cast<int>(cell.x + fx * cell.width), y = static_cast<int>(cell.y + fy * cell.height);
  const int r = std::max(1, static_cast<int>(cell.width * 0.06));
  cv::Mat gray;
  cv::cvtColor(img(cv::Rect(x - r, y - r, 2 * r + 1, 2 * r + 1)), gray, cv::COLOR_BGR2GRAY);
  return cv::countNonZero(gray < 128) / static_cast<double>(gray.total());
}

TEST_F(LaceChartRender, SymbolsSitInTheirCells) {
  const Chart c = sampler();
  ASSERT_TRUE(lace::knittable(c, 6)) << lace::knittable(c, 6).why;
  const LaceChartRaster r = render_lace_chart_png(c, 6, {"sampler"});
  ASSERT_EQ(r.cells.size(), 4u);
  ASSERT_EQ(r.cells[1].size(), 7u);
  // Row 1 is at the bottom, stitch 1 (knitting order 0) on the right.
  EXPECT_GT(r.cells[0][0].y, r.cells[1][0].y);
  EXPECT_GT(r.cells[0][0].x, r.cells[0][1].x);
  const cv::Mat& img = r.image;
  for (std::size_t ri = 0; ri < c.rows.size(); ++ri) {
    for (std::size_t j = 0; j < c.rows[ri].size(); ++j) {
      const cv::Rect2d& cell = r.cells[ri][j];
      const std::string where = "row " + std::to_string(2 * ri + 1) + " stitch " + std::to_string(j + 1);
      switch (c.rows[ri][j]) {
        case Symbol::k:  // an empty square
          EXPECT_EQ(ink(img, cell, 0.5, 0.5), 0.0) << where;
          EXPECT_EQ(ink(img, cell, 0.3, 0.3), 0.0) << where;
          EXPECT_EQ(ink(img, cell, 0.7, 0.7), 0.0) << where;
          break;
        case Symbol::yo:  // a circle: ink on the ring, none in the middle
          EXPECT_GT(ink(img, cell, 0.5, 0.2), 0.2) << where;
          EXPECT_GT(ink(img, cell, 0.8, 0.5), 0.2) << where;
          EXPECT_EQ(ink(img, cell, 0.5, 0.5), 0.0) << where;
          break;
        case Symbol::k2tog:  // "/": the rising diagonal
          EXPECT_GT(ink(img, cell, 0.3, 0.7), 0.2) << where;
          EXPECT_GT(ink(img, cell, 0.7, 0.3), 0.2) << where;
          EXPECT_EQ(ink(img, cell, 0.3, 0.3), 0.0) << where;
          EXPECT_EQ(ink(img, cell, 0.7, 0.7), 0.0) << where;
          break;
        case Symbol::ssk:  // "\": the falling diagonal
          EXPECT_GT(ink(img, cell, 0.3, 0.3), 0.2) << where;
          EXPECT_GT(ink(img, cell, 0.7, 0.7), 0.2) << where;
          EXPECT_EQ(ink(img, cell, 0.3, 0.7), 0.0) << where;
          EXPECT_EQ(ink(img, cell, 0.7, 0.3), 0.0) << where;
          break;
        case Symbol::sk2p:  // an inverted V leaning left (apex over its left leg), no spine
          EXPECT_GT(ink(img, cell, 0.24, 0.3), 0.2) << where;
          EXPECT_GT(ink(img, cell, 0.71, 0.7), 0.2) << where;
          EXPECT_EQ(ink(img, cell, 0.5, 0.75), 0.0) << where;
          EXPECT_EQ(ink(img, cell, 0.78, 0.3), 0.0) << where;
          break;
        case Symbol::s2kp:  // "^" with a vertical line: centred
          EXPECT_GT(ink(img, cell, 0.5, 0.7), 0.2) << where;
          EXPECT_GT(ink(img, cell, 0.26, 0.7), 0.2) << where;
          EXPECT_GT(ink(img, cell, 0.74, 0.7), 0.2) << where;
          EXPECT_EQ(ink(img, cell, 0.22, 0.3), 0.0) << where;
          EXPECT_EQ(ink(img, cell, 0.78, 0.3), 0.0) << where;
          break;
      }
    }
  }
}

// The middle of a cell's pixel: grey for a "no stitch" cell, white for a stitch.
cv::Vec3b centre_of(const cv::Mat& img, const cv::Rect2d& cell) {
  return img.at<cv::Vec3b>(cv::Point(static_cast<int>(cell.x + 0.5 * cell.width), static_cast<int>(cell.y + 0.5 * cell.height)));
}
bool grey(const cv::Vec3b& v) { return v[1] > 100 && v[1] < 200; }

// Issue 22, lace point 1: columns line up. Decreases first (row 1: 7 -> 5 stitches), their
// yarn-overs a row later: row 1 is drawn 7 cells wide with a grey no-stitch cell beside each
// k2tog (columns 2 and 5 from the right), row 3's yarn-overs sit right above them, and every
// plain stitch of row 3 sits in the column of the stitch below it.
TEST_F(LaceChartRender, ColumnsLineUpWithNoStitchCellsWhereADecreaseIsNotYetBalanced) {
  const Chart c{{row({"k", "k2tog", "k", "k2tog", "k"}), row({"k", "yo", "k", "k", "yo", "k", "k"})}};
  const LaceChartRaster r = render_lace_chart_png(c, 7, {"columns"});
  ASSERT_EQ(r.grid.size(), 2u);
  ASSERT_EQ(r.grid[0].size(), 7u);
  ASSERT_EQ(r.grid[1].size(), 7u);
  for (int col = 0; col < 7; ++col) {
    const bool no_stitch = col == 1 || col == 4;
    EXPECT_EQ(grey(centre_of(r.image, r.grid[0][static_cast<std::size_t>(col)])), no_stitch) << "row 1 column " << col + 1;
    EXPECT_FALSE(grey(centre_of(r.image, r.grid[1][static_cast<std::size_t>(col)]))) << "row 3 column " << col + 1;
    EXPECT_DOUBLE_EQ(r.grid[0][static_cast<std::size_t>(col)].x, r.grid[1][static_cast<std::size_t>(col)].x);
  }
  // The k2togs in columns 3 and 6 ("/" ink), the yarn-overs above the grey cells (a ring).
  EXPECT_EQ(r.cells[0][1], r.grid[0][2]);
  EXPECT_EQ(r.cells[0][3], r.grid[0][5]);
  EXPECT_GT(ink(r.image, r.grid[0][2], 0.7, 0.3), 0.2);
  EXPECT_EQ(r.cells[1][1], r.grid[1][1]);
  EXPECT_EQ(r.cells[1][4], r.grid[1][4]);
  EXPECT_GT(ink(r.image, r.grid[1][1], 0.5, 0.2), 0.2);
  EXPECT_EQ(ink(r.image, r.grid[1][1], 0.5, 0.5), 0.0);
  // Row 3's plain stitch 3 is worked into row 1's stitch 2 (the k2tog): same column.
  EXPECT_EQ(r.cells[1][2].x, r.cells[0][1].x);
  // The yarn-over before its decrease (row 3 of the sampler adds a stitch): the column it adds
  // is a grey cell in row 1 right below it, not at the row's left end.
  const Chart s = sampler();
  const LaceChartRaster rs = render_lace_chart_png(s, 6, {"sampler"});
  ASSERT_EQ(rs.grid[0].size(), 7u);
  int greys = 0;
  for (std::size_t col = 0; col < 7; ++col) greys += grey(centre_of(rs.image, rs.grid[0][col]));
  EXPECT_EQ(greys, 1);
  EXPECT_TRUE(grey(centre_of(rs.image, rs.grid[0][1])));       // below row 3's yo (column 2)
  EXPECT_FALSE(grey(centre_of(rs.image, rs.grid[0][6])));      // the left end is a stitch
  EXPECT_EQ(rs.cells[1][1], rs.grid[1][1]);
}

TEST_F(LaceChartRender, SvgIsWrittenWithTitleAndLegend) {
  const auto svg = dir_ / "chart.svg";
  write_lace_chart_svg(sampler(), 6, {"sampler"}, svg);
  const std::string text = slurp(svg);
  EXPECT_TRUE(text.starts_with("<?xml")) << text.substr(0, 60);
  EXPECT_NE(text.find("<svg"), std::string::npos);
  EXPECT_NE(text.find("</svg>"), std::string::npos);
  EXPECT_NE(text.find("<title>sampler - lace chart</title>"), std::string::npos);
  // One stroked circle per yo of the chart, plus the legend's: cairo writes each as an
  // unfilled path of two curves and no straight segments.
  const std::regex stroked(R"re(<path style="fill:none;[^"]*" d="([^"]*)")re");
  int circles = 0;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), stroked); it != std::sregex_iterator(); ++it) {
    const std::string d = (*it)[1].str();
    if (count(d, "C ") == 2 && d.find('L') == std::string::npos) ++circles;
  }
  EXPECT_EQ(circles, 6 + 1);
  for (const char* word : {"yarn over", "knit 2 together", "right-slanting", "left-slanting",
                           "sk2p - RS: slip 1, knit 2 together, pass slipped stitch over (left-slanting double decrease)",
                           "s2kp - RS: slip 2 together knitwise, knit 1, pass the 2 slipped stitches over (centred double decrease)",
                           "Multiple of 6 sts"})
    EXPECT_NE(text.find(word), std::string::npos) << word;
}

// Issue 22, lace point 3: the legend says how to work a double yarn-over on the wrong side,
// only when the chart has one.
TEST_F(LaceChartRender, LegendSaysHowToWorkADoubleYarnOver) {
  const std::string note = "Two yo side by side (double yarn-over): on the next WS row purl 1, knit 1 into it.";
  write_lace_chart_svg(Chart{{row({"k", "ssk", "yo", "yo", "k2tog", "k"})}}, 6, {}, dir_ / "double.svg");
  EXPECT_NE(slurp(dir_ / "double.svg").find(note), std::string::npos);
  write_lace_chart_svg(sampler(), 6, {}, dir_ / "single.svg");
  EXPECT_EQ(slurp(dir_ / "single.svg").find(note), std::string::npos);
}

TEST_F(LaceChartRender, PdfIsA4AndSplitsBigCharts) {
  const auto small = dir_ / "small.pdf";
  EXPECT_EQ(write_lace_chart_pdf(sampler(), 6, {"sampler"}, small), 1);
  const std::string one = slurp(small);
  EXPECT_TRUE(one.starts_with("%PDF"));
  EXPECT_EQ(count(one, "/Type /Page\n") + count(one, "/Type /Page "), 1);
  EXPECT_NE(one.find("595.27"), std::string::npos);  // A4 width in points
  // 60 stitches x 80 rows: at 4 mm cells that is 240 x 320 mm, more than an A4 page holds
  // both ways -> 2 columns of pages x 2 or more rows of pages.
  Chart big;
  for (int r = 0; r < 80; ++r) big.rows.push_back(knit(60));
  const auto bigf = dir_ / "big.pdf";
  const int pages = write_lace_chart_pdf(big, 60, {"big"}, bigf);
  EXPECT_GE(pages, 4);
  const std::string many = slurp(bigf);
  EXPECT_TRUE(many.starts_with("%PDF"));
  EXPECT_EQ(count(many, "/Type /Page\n") + count(many, "/Type /Page "), pages);
}

// The charts go through the atomic output writer: a failed write names the file (not the
// folder it was bound for) and leaves neither a half-written chart nor its temporary file.
TEST_F(LaceChartRender, WriteFailuresNameTheFileAndLeaveNothingBehind) {
  const auto bad = dir_ / "no" / "such" / "dir" / "chart.pdf";
  try {
    write_lace_chart_pdf(sampler(), 6, {}, bad);
    FAIL() << "no error";
  } catch (const ConvertError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find(bad.parent_path().string()), std::string::npos) << what;
    EXPECT_EQ(what.rfind("chart.pdf: cannot write", 0), 0u) << what;
  }
  // The target name is taken by a folder: the rename fails, the folder is untouched.
  for (const char* name : {"chart.svg", "chart.pdf"}) {
    std::filesystem::create_directories(dir_ / name / "inside");
    if (std::string(name) == "chart.svg")
      EXPECT_THROW(write_lace_chart_svg(sampler(), 6, {}, dir_ / name), ConvertError);
    else
      EXPECT_THROW(write_lace_chart_pdf(sampler(), 6, {}, dir_ / name), ConvertError);
    EXPECT_TRUE(std::filesystem::is_directory(dir_ / name / "inside")) << name;
    EXPECT_FALSE(std::filesystem::exists(dir_ / (std::string(name) + ".tmp"))) << name;
  }
  EXPECT_THROW(write_lace_chart_svg(sampler(), 5, {}, dir_ / "new.svg"), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "new.svg"));
}

}  // namespace
}  // namespace atelier

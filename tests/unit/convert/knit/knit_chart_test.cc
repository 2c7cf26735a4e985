// The knit chart PDF (convert/knit/knit_chart.h): pages for a large pattern, written whole
// through the atomic output writer or not at all.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <regex>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "convert/common/convert_error.h"
#include "convert/knit/knit_chart.h"
#include "tests/e2e/daemon_harness.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;

cv::Mat checkerboard(int rows, int cols) {
  cv::Mat grid(rows, cols, CV_8UC1);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) grid.at<uint8_t>(r, c) = (r / 2 + c / 3) % 2;
  return grid;
}

std::string slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(KnitChart, APdfWithOnePagePerTileAndNoTemporaryLeft) {
  test::TempDir tmp;
  const fs::path pdf = tmp.path() / "chart.pdf";
  ChartInfo info;
  info.title = "check.png";
  EXPECT_EQ(write_chart_pdf(checkerboard(20, 20), info, pdf), 1);
  const int big = write_chart_pdf(checkerboard(400, 300), info, tmp.path() / "big.pdf");
  EXPECT_GT(big, 1);
  const std::string text = slurp(tmp.path() / "big.pdf");
  EXPECT_TRUE(text.starts_with("%PDF"));
  EXPECT_NE(text.find("%%EOF"), std::string::npos);  // finished, not cut short
  size_t page_objects = 0;
  for (size_t at = 0; (at = text.find("/Type /Page", at)) != std::string::npos; at += 11)
    if (text.compare(at, 12, "/Type /Pages") != 0) ++page_objects;
  EXPECT_EQ(page_objects, static_cast<size_t>(big));
  for (const auto& e : fs::directory_iterator(tmp.path()))
    EXPECT_NE(e.path().extension(), ".tmp") << e.path();
}

TEST(KnitChart, AFailedWriteNamesTheFileAndLeavesWhatWasThere) {
  test::TempDir tmp;
  const fs::path pdf = tmp.path() / "chart.pdf";
  fs::create_directories(pdf / "inside");  // the name is taken: the final rename fails
  try {
    write_chart_pdf(checkerboard(10, 10), ChartInfo{}, pdf);
    FAIL() << "no error";
  } catch (const ConvertError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("chart.pdf: cannot write", 0), 0u) << e.what();
  }
  EXPECT_TRUE(fs::is_directory(pdf / "inside"));
  EXPECT_FALSE(fs::exists(tmp.path() / "chart.pdf.tmp"));
  EXPECT_THROW(write_chart_pdf(checkerboard(10, 10), ChartInfo{}, tmp.path() / "no" / "chart.pdf"),
               ConvertError);
}

// An asymmetric grid: row r has its contrast stitch at column r (a diagonal from the top left)
// and the bottom row two more at the right end, so no flip or mirror of it equals it.
cv::Mat asymmetric(int rows, int cols) {
  cv::Mat grid(rows, cols, CV_8UC1, cv::Scalar(0));
  for (int r = 0; r < rows; ++r) grid.at<uint8_t>(r, r % cols) = 1;
  grid.at<uint8_t>(rows - 1, cols - 1) = grid.at<uint8_t>(rows - 1, cols - 2) = 1;
  return grid;
}

// The cells drawn on a rendered chart page, bottom row first ("1" = contrast), found by the
// colours: pure green background and pure red contrast cells, which only the grid and the
// colour key (in the header, above the grid) use. Cells are 4.5 mm.
std::vector<std::string> drawn_rows_bottom_first(const cv::Mat& page, double px_per_mm, int rows, int cols) {
  auto cell_colour = [&](int y, int x) -> int {  // 0 green, 1 red, -1 neither
    const cv::Vec3b p = page.at<cv::Vec3b>(y, x);
    if (p == cv::Vec3b(0, 255, 0)) return 0;
    if (p == cv::Vec3b(0, 0, 255)) return 1;
    return -1;
  };
  int bottom = -1, left = page.cols;
  for (int y = 0; y < page.rows; ++y)
    for (int x = 0; x < page.cols; ++x)
      if (cell_colour(y, x) >= 0) bottom = y;
  for (int x = 0; x < page.cols && bottom >= 0; ++x)
    if (cell_colour(bottom, x) >= 0) { left = x; break; }
  const double cell = 4.5 * px_per_mm;
  std::vector<std::string> out;
  for (int i = 0; i < rows; ++i) {
    std::string line;
    for (int k = 0; k < cols; ++k) {
      const int c = cell_colour(static_cast<int>(bottom - (i + 0.5) * cell), static_cast<int>(left + (k + 0.5) * cell));
      line.push_back(c == 1 ? '1' : c == 0 ? '0' : '?');
    }
    out.push_back(line);
  }
  return out;
}

std::string grid_row(const cv::Mat& grid, int r) {
  std::string line;
  for (int c = 0; c < grid.cols; ++c) line.push_back(grid.at<uint8_t>(r, c) ? '1' : '0');
  return line;
}

ChartInfo green_red() {
  ChartInfo info;
  info.title = "order.png";
  info.colors = {Rgb{0, 255, 0}, Rgb{255, 0, 0}};
  info.color_names = {"#00ff00", "#ff0000"};
  return info;
}

// Row 1 is drawn at the bottom and is knitted first: by default pattern.png's bottom row, so the
// chart shows the picture upright, cell for cell (column 0 on the left).
TEST(KnitChart, TheBottomDrawnRowIsThePicturesBottomRowKnittedFirst) {
  const cv::Mat grid = asymmetric(7, 9);
  const double px_per_mm = 4;
  const std::vector<std::string> drawn =
      drawn_rows_bottom_first(render_chart_page(grid, green_red(), 1, px_per_mm), px_per_mm, 7, 9);
  ASSERT_EQ(drawn.size(), 7u);
  for (int i = 0; i < 7; ++i) EXPECT_EQ(drawn[i], grid_row(grid, 6 - i)) << "chart row " << i + 1;
}

// first_row = "top": row 1 (still at the bottom, still knitted first) is the picture's top row,
// so the chart is the picture upside down, as the fabric comes off the machine.
TEST(KnitChart, FirstRowTopDrawsThePicturesTopRowAsRowOne) {
  const cv::Mat grid = asymmetric(7, 9);
  ChartInfo info = green_red();
  info.first_row_top = true;
  const double px_per_mm = 4;
  const std::vector<std::string> drawn =
      drawn_rows_bottom_first(render_chart_page(grid, info, 1, px_per_mm), px_per_mm, 7, 9);
  ASSERT_EQ(drawn.size(), 7u);
  for (int i = 0; i < 7; ++i) EXPECT_EQ(drawn[i], grid_row(grid, i)) << "chart row " << i + 1;
  EXPECT_THROW(render_chart_page(grid, info, 2, px_per_mm), std::out_of_range);
}

// The text of a PDF as pdftotext extracts it, one string per page; empty without pdftotext.
std::vector<std::string> pdf_pages_text(const fs::path& pdf) {
  std::vector<std::string> pages;
  if (std::system("command -v pdftotext > /dev/null 2>&1") != 0) return pages;
  const std::string cmd = "pdftotext -layout '" + pdf.string() + "' - 2>/dev/null";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return pages;
  std::string all;
  char buf[4096];
  for (size_t n; (n = fread(buf, 1, sizeof buf, pipe)) > 0;) all.append(buf, n);
  pclose(pipe);
  std::string page;
  for (char c : all) {
    if (c == '\f') {
      pages.push_back(page);
      page.clear();
    } else {
      page += c;
    }
  }
  if (!page.empty()) pages.push_back(page);
  return pages;
}

// Issue 22: 120 stitches were split 37 + 37 + 37 + 9. Every page's stitch and row range as its
// header states it, read back from the PDF: spread evenly, covering the chart once.
TEST(KnitChart, PagesSplitStitchesAndRowsEvenly) {
  test::TempDir tmp;
  const fs::path pdf = tmp.path() / "chart.pdf";
  ChartInfo info;
  info.title = "even.png";
  const int pages = write_chart_pdf(checkerboard(130, 120), info, pdf);
  const std::vector<std::string> text = pdf_pages_text(pdf);
  if (text.empty()) GTEST_SKIP() << "pdftotext not available";
  ASSERT_EQ(static_cast<int>(text.size()), pages);
  const std::regex head(R"(Page (\d+) of (\d+): rows (\d+)-(\d+), stitches (\d+)-(\d+))");
  std::vector<int> widths, heights;
  std::vector<int> stitch_cover(121, 0), row_cover(131, 0);
  for (const std::string& page : text) {
    std::smatch m;
    ASSERT_TRUE(std::regex_search(page, m, head)) << page.substr(0, 400);
    const int r0 = std::stoi(m[3]), r1 = std::stoi(m[4]), s0 = std::stoi(m[5]), s1 = std::stoi(m[6]);
    widths.push_back(s1 - s0 + 1);
    heights.push_back(r1 - r0 + 1);
    for (int s = s0; s <= s1; ++s) ++stitch_cover[s];
    for (int r = r0; r <= r1; ++r) ++row_cover[r];
  }
  EXPECT_LE(*std::max_element(widths.begin(), widths.end()) - *std::min_element(widths.begin(), widths.end()), 1);
  EXPECT_LE(*std::max_element(heights.begin(), heights.end()) - *std::min_element(heights.begin(), heights.end()), 1);
  // Every stitch on as many pages as there are page rows, every row on as many as columns.
  const int down = static_cast<int>(std::count(stitch_cover.begin() + 1, stitch_cover.end(), stitch_cover[1]));
  EXPECT_EQ(down, 120);
  EXPECT_EQ(std::count(row_cover.begin() + 1, row_cover.end(), row_cover[1]), 130);
  EXPECT_EQ(stitch_cover[1] * row_cover[1], pages);
}

// The first page says which page holds which stitch and row range.
TEST(KnitChart, TheFirstPageCarriesAPageMap) {
  test::TempDir tmp;
  const fs::path pdf = tmp.path() / "chart.pdf";
  ChartInfo info;
  info.title = "map.png";
  const int pages = write_chart_pdf(checkerboard(130, 120), info, pdf);
  ASSERT_GT(pages, 1);
  const std::vector<ChartTile> tiles = chart_layout(120, 130);
  ASSERT_EQ(static_cast<int>(tiles.size()), pages);
  const std::vector<std::string> map = chart_page_map(120, 130);
  ASSERT_FALSE(map.empty());
  std::string joined;
  for (const auto& l : map) joined += l + "\n";
  EXPECT_NE(joined.find("Page map"), std::string::npos);
  // Each page column's stitch range and each page row's rows and pages are named.
  for (const ChartTile& t : tiles) {
    EXPECT_NE(joined.find(std::to_string(t.stitch0) + "-" + std::to_string(t.stitch1)),
              std::string::npos) << joined;
    EXPECT_NE(joined.find("rows " + std::to_string(t.row0) + "-" + std::to_string(t.row1)),
              std::string::npos) << joined;
  }
  EXPECT_TRUE(chart_page_map(20, 20).empty());  // one page: no map
  // Bounded for the largest chart (1000 x 10000): a few lines.
  EXPECT_LE(chart_page_map(1000, 10000).size(), 10u);
  const std::vector<std::string> text = pdf_pages_text(pdf);
  if (text.empty()) GTEST_SKIP() << "pdftotext not available";
  EXPECT_NE(text[0].find("Page map"), std::string::npos) << text[0].substr(0, 600);
  EXPECT_NE(text[0].find("rows " + std::to_string(tiles.back().row0) + "-" + std::to_string(tiles.back().row1)),
            std::string::npos) << text[0].substr(0, 800);
}

}  // namespace
}  // namespace atelier

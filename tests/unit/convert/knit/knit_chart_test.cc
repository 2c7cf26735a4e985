// The knit chart PDF (convert/knit/knit_chart.h): pages for a large pattern, written whole
// through the atomic output writer or not at all.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace atelier

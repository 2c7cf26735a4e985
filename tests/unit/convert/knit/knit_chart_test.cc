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

}  // namespace
}  // namespace atelier

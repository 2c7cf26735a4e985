// threads.pdf (convert/embroidery/thread_sheet.h): the operator's colour sheet lists every
// colour block in sewing order with its stitch count and length, the design's name, size and
// stitch count; it is a real PDF (read back with poppler's pdftotext, tools/install-deps), over
// several pages when the list is long; and a converted job writes it with stitches.png.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "convert/common/param_table.h"
#include "convert/convert.h"
#include "convert/embroidery/thread_sheet.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
namespace emb = embroidery;

struct TempDir {
  TempDir() {
    path = fs::temp_directory_path() / ("atelier-thread-sheet-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  fs::path path;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The PDF's text as poppler reads it, in layout order.
std::string pdf_text(const fs::path& pdf) {
  const std::string cmd = "pdftotext -layout '" + pdf.string() + "' - 2>&1";
  FILE* f = ::popen(cmd.c_str(), "r");
  if (!f) return "";
  std::string out;
  char buf[4096];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) out.append(buf, n);
  const int rc = ::pclose(f);
  EXPECT_EQ(rc, 0) << "pdftotext (poppler-utils, tools/install-deps) failed: " << out;
  return out;
}

struct Row {
  int stop, stitches;
  std::string rgb;
  double length_m;
};

// The colour-order rows: "stop  #rrggbb  thread  stitches  length".
std::vector<Row> rows_of(const std::string& text) {
  std::vector<Row> rows;
  const std::regex row(R"(^\s*(\d+)\s+(#[0-9a-f]{6})\s+.*?\s(\d+)\s+(\d+\.\d\d)\s*$)");
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_match(line, m, row)) rows.push_back({std::stoi(m[1]), std::stoi(m[3]), m[2], std::stod(m[4])});
  }
  return rows;
}

TEST(ThreadSheet, BlocksCountStitchesAndThreadLengthPerColour) {
  emb::StitchPlan plan;
  plan.colors_rgb = {0xff0000, 0x00ff00};
  plan.points = {{0, 0, emb::StitchKind::jump},    {3, 4, emb::StitchKind::stitch},  // 5 mm
                 {3, 4, emb::StitchKind::trim},    {100, 4, emb::StitchKind::jump},  // travel: no thread
                 {100, 10, emb::StitchKind::stitch},                                 // 6 mm
                 {100, 10, emb::StitchKind::color_change},
                 {0, 10, emb::StitchKind::jump},   {0, 0, emb::StitchKind::stitch},  // 10 mm
                 {0, 0, emb::StitchKind::end}};
  const std::vector<ThreadBlock> b = thread_blocks(plan);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[0].rgb, 0xff0000u);
  EXPECT_EQ(b[0].stitches, 2);
  EXPECT_NEAR(b[0].length_m, 0.011, 1e-12);
  EXPECT_EQ(b[1].rgb, 0x00ff00u);
  EXPECT_EQ(b[1].stitches, 1);
  EXPECT_NEAR(b[1].length_m, 0.010, 1e-12);
}

TEST(ThreadSheet, TheSheetListsEveryBlockInOrderOverAsManyPagesAsItNeeds) {
  TempDir tmp;
  ThreadSheet s;
  s.design = "rose.png";
  s.width_mm = 90;
  s.height_mm = 63.5;
  s.stitches = 0;
  s.trims = 7;
  s.picture = cv::Mat3b(300, 420, cv::Vec3b(40, 90, 200));
  // 30 blocks: more than a page holds under the picture.
  for (int i = 0; i < 30; ++i) {
    ThreadBlock b;
    b.rgb = static_cast<std::uint32_t>(0x102030 + 0x050301 * i);
    b.stitches = 1000 + 37 * i;
    b.length_m = 0.5 + 0.25 * i;
    if (i == 2) b.thread = "Brother 205 Yellow";
    s.stitches += b.stitches;
    s.blocks.push_back(b);
  }
  write_thread_sheet(s, tmp.path / "threads.pdf");
  const std::string pdf = slurp(tmp.path / "threads.pdf");
  ASSERT_TRUE(pdf.starts_with("%PDF"));
  const std::string text = pdf_text(tmp.path / "threads.pdf");
  EXPECT_NE(text.find("Thread sheet: rose.png"), std::string::npos) << text;
  EXPECT_NE(text.find("90.0 x 63.5 mm"), std::string::npos);
  EXPECT_NE(text.find(std::to_string(s.stitches) + " stitches"), std::string::npos);
  EXPECT_NE(text.find("30 colours"), std::string::npos);
  EXPECT_NE(text.find("Brother 205 Yellow"), std::string::npos);
  EXPECT_NE(text.find("(page 2)"), std::string::npos) << "30 blocks fit one page?";
  const std::vector<Row> rows = rows_of(text);
  ASSERT_EQ(rows.size(), s.blocks.size()) << text;
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].stop, static_cast<int>(i) + 1);
    EXPECT_EQ(rows[i].stitches, s.blocks[i].stitches) << i;
    char hex[8];
    std::snprintf(hex, sizeof hex, "#%06x", s.blocks[i].rgb);
    EXPECT_EQ(rows[i].rgb, hex) << i;
    EXPECT_NEAR(rows[i].length_m, s.blocks[i].length_m, 0.005) << i;
  }
}

// A converted photo: threads.pdf lists report.json's threads (colour and stitches) in sewing
// order, and stitches.png is the preview's size.
TEST(ThreadSheet, AConvertedDesignWritesItsSheetAndItsStitchPicture) {
  TempDir tmp;
  ConvertRequest req;
  req.kind = "embroidery";
  req.input = fs::path(ATELIER_TEST_DATA) / "HappyFish.jpg";
  req.params = toml::parse("width_mm = 70\n", std::string_view{"test.toml"});
  req.params_source = "test.toml";
  req.output_dir = tmp.path / "out";
  const ConvertResult r = convert(req);
  const nlohmann::json& report = r.report;
  const cv::Mat stitches = cv::imread((req.output_dir / "stitches.png").string(), cv::IMREAD_UNCHANGED);
  const cv::Mat preview = cv::imread((req.output_dir / "preview.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(stitches.empty());
  EXPECT_EQ(stitches.size(), preview.size());
  const std::string text = pdf_text(req.output_dir / "threads.pdf");
  EXPECT_NE(text.find("Thread sheet: HappyFish.jpg"), std::string::npos) << text;
  EXPECT_NE(text.find(std::to_string(report["stitches"].get<int>()) + " stitches"), std::string::npos) << text;
  const std::vector<Row> rows = rows_of(text);
  ASSERT_EQ(rows.size(), report["threads"].size()) << text;
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].rgb, report["threads"][i]["rgb"].get<std::string>()) << i;
    EXPECT_EQ(rows[i].stitches, report["threads"][i]["stitches"].get<int>()) << i;
    EXPECT_GT(rows[i].length_m, 0.0) << i;
  }
  // Each colour names the threads design.pes and design.jef ask the machine for.
  auto count = [&](const std::string& word) {
    size_t n = 0;
    for (size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("Brother "), rows.size()) << text;
  EXPECT_EQ(count("Janome "), rows.size()) << text;
}

}  // namespace
}  // namespace atelier

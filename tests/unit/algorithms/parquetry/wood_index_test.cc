// WoodIndex memory (issue 23): matching windows of many sizes (a morphed grid's cells) keeps
// the per-size maps of a few sizes only, and a size evicted and needed again matches as before.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/parquetry/memory_estimate.h"
#include "algorithms/parquetry/wood_index.h"

namespace atelier::parquetry {
namespace {

std::vector<Sheet> two_sheets() {
  std::vector<Sheet> sheets;
  for (const char* id : {"maple_dark", "cherry_light"}) {
    const std::string path = std::string(ATELIER_TEST_DATA) + "/wood/" + id + ".png";
    sheets.push_back({id, cv::imread(path, cv::IMREAD_COLOR), {}, 25.4});
  }
  return sheets;
}

// Features of a w x h patch cut from a smooth ramp (any target works for the index).
std::pair<cv::Mat, cv::Mat> patch(int w, int h) {
  cv::Mat f1(h, w, CV_32F), f2(h, w, CV_32F);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      f1.at<float>(y, x) = 0.3f + 0.01f * x;
      f2.at<float>(y, x) = 0.02f * ((x + y) % 5);
    }
  return {f1, f2};
}

TEST(ParquetryWoodIndex, ManyWindowSizesKeepTheMapsOfAFewOnly) {
  const auto sheets = two_sheets();
  WoodIndex index(sheets, Stock{}, 1.0, 6, 0.5, 0.5, 0.2);
  const std::size_t before = index.bytes();
  std::size_t one_size = 0;
  std::optional<Match> first;
  for (int s = 0; s < 20; ++s) {
    const auto [f1, f2] = patch(8 + s, 9 + (s % 7));
    const auto m = index.best(f1, f2);
    ASSERT_TRUE(m);
    if (s == 0) {
      one_size = index.cache_bytes();
      first = m;
    }
  }
  ASSERT_GT(one_size, 0u);
  // 20 sizes matched; the maps of at most kCachedSizes (each no larger than the first's).
  EXPECT_LE(index.cache_bytes(), WoodIndex::kCachedSizes * one_size);
  EXPECT_LE(index.bytes(), before + WoodIndex::kCachedSizes * one_size);
  // The first size was evicted; matched again it finds the same window.
  const auto [f1, f2] = patch(8, 9);
  const auto again = index.best(f1, f2);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->copy, first->copy);
  EXPECT_EQ(again->pos, first->pos);
  EXPECT_DOUBLE_EQ(again->cost, first->cost);
}

TEST(ParquetryWoodIndex, MaskedCellsOfManySizesKeepTheMapsOfAFewOnly) {
  const auto sheets = two_sheets();
  WoodIndex index(sheets, Stock{}, 1.0, 6, 0.5, 0.5, 0.2);
  for (int s = 0; s < 20; ++s) {
    const int w = 10 + s, h = 12 + (s % 5);
    const auto [f1, f2] = patch(w, h);
    cv::Mat mask = cv::Mat::zeros(h, w, CV_8UC1);
    cv::ellipse(mask, cv::Point(w / 2, h / 2), cv::Size(w / 2, h / 2), 0, 0, 360, cv::Scalar(255), -1);
    const auto m = index.best(f1, f2, mask);
    ASSERT_TRUE(m);
    // Taking wood drops the free-window maps of that sheet's copies; the rest stay bounded.
    index.take(m->sheet, {{m->pos.x + 0.0, m->pos.y + 0.0}, {m->pos.x + 4.0, m->pos.y + 0.0},
                          {m->pos.x + 4.0, m->pos.y + 4.0}});
  }
  // Two maps per masked cell (its bounding box's free windows, its inner rectangle's sums),
  // each no larger than a full 13 bytes per window position over every copy's canvas.
  const MemoryEstimate e = estimate_plan_memory(
      {{sheets[0].image.size(), 25.4, false}, {sheets[1].image.size(), 25.4, false}}, {{60, 60}},
      [] { Params p; p.px_per_mm = 1.0; p.rotations = 6; p.grid = Grid::morphed; return p; }());
  EXPECT_LE(static_cast<double>(index.cache_bytes()), e.cache_bytes);
  EXPECT_LE(static_cast<double>(index.bytes()), e.copies_bytes + e.cache_bytes);
}

}  // namespace
}  // namespace atelier::parquetry

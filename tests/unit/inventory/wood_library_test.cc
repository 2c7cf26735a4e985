// The wood library on disk (inventory/wood_library.h): folders of scans, library.toml,
// the `wood` list parameter, decoding scans and masks, adding and removing sheets.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "inventory/wood_library.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kWood = fs::path(ATELIER_TEST_DATA) / "wood";

class WoodLibraryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("atelier-wood-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  void write(const fs::path& p, const std::string& text) {
    std::ofstream(p, std::ios::binary) << text;
  }
  std::string message_of(const std::function<void()>& f) {
    try {
      f();
    } catch (const ConvertError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no ConvertError";
    return "";
  }

  fs::path dir_;
};

TEST_F(WoodLibraryTest, FolderWithoutLibraryListsEveryScanSortedById) {
  auto sheets = list_sheets(kWood, 25.4);
  ASSERT_EQ(sheets.size(), 12u);
  EXPECT_EQ(sheets.front().id, "brazilwood_dark");
  EXPECT_EQ(sheets.back().id, "sandlewood_light");
  for (size_t i = 1; i < sheets.size(); ++i) EXPECT_LT(sheets[i - 1].id, sheets[i].id);
  for (const auto& s : sheets) {
    EXPECT_DOUBLE_EQ(s.dpi, 25.4);
    EXPECT_TRUE(s.mask.empty());
    EXPECT_TRUE(fs::is_regular_file(s.image)) << s.image;
  }
}

TEST_F(WoodLibraryTest, ScannedFolderPairsMasksAndSkipsThemAsSheets) {
  fs::copy_file(kWood / "maple_dark.png", dir_ / "maple.png");
  fs::copy_file(kWood / "cherry_dark.png", dir_ / "cherry.jpg");  // any image extension
  cv::Mat mask(160, 160, CV_8UC1, cv::Scalar(255));
  cv::imwrite((dir_ / "maple.mask.png").string(), mask);
  write(dir_ / "notes.txt", "not a scan");
  auto sheets = list_sheets(dir_, 300);
  ASSERT_EQ(sheets.size(), 2u);
  EXPECT_EQ(sheets[0].id, "cherry");
  EXPECT_TRUE(sheets[0].mask.empty());
  EXPECT_EQ(sheets[1].id, "maple");
  EXPECT_EQ(sheets[1].mask, dir_ / "maple.mask.png");
  EXPECT_DOUBLE_EQ(sheets[1].dpi, 300);
}

TEST_F(WoodLibraryTest, LibraryTomlGovernsWithRelativePathsAndDpi) {
  write(dir_ / "library.toml",
        "[[sheet]]\nid = \"b\"\nimage = \"" + (kWood / "maple_dark.png").string() +
            "\"\ndpi = 25.4\n"
            "[[sheet]]\nid = \"a\"\nimage = \"sub/c.png\"\n");
  fs::create_directories(dir_ / "sub");
  fs::copy_file(kWood / "cherry_dark.png", dir_ / "sub" / "c.png");
  fs::copy_file(kWood / "lanta_dark.png", dir_ / "ignored.png");  // not listed: not a sheet
  auto sheets = list_sheets(dir_, 100);
  ASSERT_EQ(sheets.size(), 2u);
  EXPECT_EQ(sheets[0].id, "a");
  EXPECT_EQ(sheets[0].image, dir_ / "sub" / "c.png");
  EXPECT_DOUBLE_EQ(sheets[0].dpi, 100);
  EXPECT_EQ(sheets[1].id, "b");
  EXPECT_DOUBLE_EQ(sheets[1].dpi, 25.4);
}

TEST_F(WoodLibraryTest, ErrorsNameTheFileAndProblem) {
  EXPECT_THAT(message_of([&] { list_sheets(dir_ / "nope", 300); }), HasSubstr("no such wood folder"));

  write(dir_ / "library.toml", "[[sheet]]\nid = \"a\"\nimage = \"x.png\"\n[[sheet]\n");
  EXPECT_THAT(message_of([&] { list_sheets(dir_, 300); }), HasSubstr("library.toml:4"));

  write(dir_ / "library.toml",
        "[[sheet]]\nid = \"a\"\nimage = \"x.png\"\n[[sheet]]\nid = \"a\"\nimage = \"y.png\"\n");
  EXPECT_THAT(message_of([&] { list_sheets(dir_, 300); }), HasSubstr("'a' is used twice"));

  write(dir_ / "library.toml", "[[sheet]]\nid = \"a\"\nimage = \"x.png\"\ncolour = 3\n");
  EXPECT_THAT(message_of([&] { list_sheets(dir_, 300); }),
              testing::AllOf(HasSubstr("library.toml:4"), HasSubstr("unknown sheet key 'colour'")));

  write(dir_ / "library.toml", "[[sheet]]\nid = \"a\"\nimage = \"missing.png\"\n");
  EXPECT_THAT(message_of([&] { list_sheets(dir_, 300); }),
              testing::AllOf(HasSubstr("library.toml"), HasSubstr("missing.png not found")));

  write(dir_ / "library.toml", "[[sheet]]\nid = \"a b\"\nimage = \"x.png\"\n");
  EXPECT_THAT(message_of([&] { list_sheets(dir_, 300); }), HasSubstr("sheet id 'a b'"));
}

TEST_F(WoodLibraryTest, WoodListParameterResolvesAgainstBase) {
  toml::table t = toml::parse(
      "wood = [{id = \"m\", image = \"maple_dark.png\", dpi = 25.4},"
      " {id = \"c\", image = \"cherry_dark.png\"}]",
      std::string_view{"job.toml"});
  auto sheets = sheets_from_toml(*t["wood"].as_array(), kWood, 50, "job.toml");
  ASSERT_EQ(sheets.size(), 2u);
  EXPECT_EQ(sheets[0].id, "c");
  EXPECT_EQ(sheets[0].image, kWood / "cherry_dark.png");
  EXPECT_DOUBLE_EQ(sheets[0].dpi, 50);
  EXPECT_DOUBLE_EQ(sheets[1].dpi, 25.4);

  toml::table bad = toml::parse("wood = [{id = \"m\"}]", std::string_view{"job.toml"});
  EXPECT_THAT(message_of([&] { sheets_from_toml(*bad["wood"].as_array(), kWood, 50, "job.toml"); }),
              testing::AllOf(HasSubstr("job.toml:1"), HasSubstr("no image")));
}

TEST_F(WoodLibraryTest, LoadsScansAsBgrAndMasksAsBinary) {
  cv::Mat mask(160, 160, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(0, 0, 80, 160)).setTo(200);
  cv::imwrite((dir_ / "m.png").string(), mask);
  auto sheets = load_sheets({{"maple", kWood / "maple_dark.png", dir_ / "m.png", 25.4}}, ImageLimits{});
  ASSERT_EQ(sheets.size(), 1u);
  EXPECT_EQ(sheets[0].id, "maple");
  EXPECT_EQ(sheets[0].image.type(), CV_8UC3);
  EXPECT_EQ(sheets[0].image.size(), cv::Size(160, 160));
  EXPECT_EQ(sheets[0].usable.type(), CV_8UC1);
  EXPECT_EQ(cv::countNonZero(sheets[0].usable), 80 * 160);
  EXPECT_EQ(sheets[0].usable.at<uchar>(10, 10), 255);
  EXPECT_DOUBLE_EQ(sheets[0].dpi, 25.4);
}

TEST_F(WoodLibraryTest, LoadRejectsMaskOfAnotherSizeAndBadScans) {
  cv::imwrite((dir_ / "m.png").string(), cv::Mat(10, 10, CV_8UC1, cv::Scalar(255)));
  EXPECT_THAT(message_of([&] {
                load_sheets({{"maple", kWood / "maple_dark.png", dir_ / "m.png", 25.4}}, ImageLimits{});
              }),
              testing::AllOf(HasSubstr("m.png"), HasSubstr("same size")));
  write(dir_ / "fake.png", "hello");
  EXPECT_THAT(message_of([&] { load_sheets({{"x", dir_ / "fake.png", {}, 25.4}}, ImageLimits{}); }),
              HasSubstr("fake.png"));
  ImageLimits tiny;
  tiny.max_pixels = 100;
  EXPECT_THAT(message_of([&] { load_sheets({{"x", kWood / "maple_dark.png", {}, 25.4}}, tiny); }),
              HasSubstr("maple_dark.png"));
}

TEST_F(WoodLibraryTest, AddCreatesLibraryFromScannedFolderAndCopiesFiles) {
  const fs::path lib = dir_ / "lib";
  fs::create_directories(lib);
  fs::copy_file(kWood / "maple_dark.png", lib / "maple.png");
  cv::Mat mask(200, 200, CV_8UC1, cv::Scalar(255));
  cv::imwrite((dir_ / "src-mask.png").string(), mask);
  add_sheet(lib, "cherry", kWood / "cherry_dark.png", 25.4, dir_ / "src-mask.png");
  ASSERT_TRUE(fs::exists(lib / "library.toml"));
  EXPECT_TRUE(fs::exists(lib / "cherry.png"));
  EXPECT_TRUE(fs::exists(lib / "cherry.mask.png"));
  auto sheets = list_sheets(lib, 77);
  ASSERT_EQ(sheets.size(), 2u);
  EXPECT_EQ(sheets[0].id, "cherry");
  EXPECT_DOUBLE_EQ(sheets[0].dpi, 25.4);
  EXPECT_EQ(sheets[0].mask, lib / "cherry.mask.png");
  // The scan that was there keeps following the caller's default dpi.
  EXPECT_EQ(sheets[1].id, "maple");
  EXPECT_DOUBLE_EQ(sheets[1].dpi, 77);
  EXPECT_EQ(load_sheets(sheets, ImageLimits{}).size(), 2u);

  // Replacing an entry: new image, no mask; the old mask goes.
  add_sheet(lib, "cherry", kWood / "lanta_dark.png", 50, {});
  sheets = list_sheets(lib, 77);
  ASSERT_EQ(sheets.size(), 2u);
  EXPECT_DOUBLE_EQ(sheets[0].dpi, 50);
  EXPECT_TRUE(sheets[0].mask.empty());
  EXPECT_FALSE(fs::exists(lib / "cherry.mask.png"));
  EXPECT_EQ(load_sheets({sheets[0]}, ImageLimits{})[0].image.cols, 160);
}

TEST_F(WoodLibraryTest, AddValidatesBeforeChangingAnything) {
  write(dir_ / "fake.png", "hello");
  EXPECT_THAT(message_of([&] { add_sheet(dir_, "x", dir_ / "fake.png", 300, {}); }), HasSubstr("fake.png"));
  EXPECT_THAT(message_of([&] { add_sheet(dir_, "../x", kWood / "maple_dark.png", 300, {}); }),
              HasSubstr("sheet id '../x'"));
  cv::imwrite((dir_ / "small.png").string(), cv::Mat(10, 10, CV_8UC1, cv::Scalar(255)));
  EXPECT_THAT(message_of([&] { add_sheet(dir_, "x", kWood / "maple_dark.png", 300, dir_ / "small.png"); }),
              HasSubstr("same size"));
  EXPECT_FALSE(fs::exists(dir_ / "library.toml"));
  EXPECT_FALSE(fs::exists(dir_ / "x.png"));
}

TEST_F(WoodLibraryTest, RemoveDropsEntryAndCopiedFiles) {
  add_sheet(dir_, "a", kWood / "maple_dark.png", 25.4, {});
  add_sheet(dir_, "b", kWood / "cherry_dark.png", 25.4, {});
  remove_sheet(dir_, "a");
  EXPECT_FALSE(fs::exists(dir_ / "a.png"));
  auto sheets = list_sheets(dir_, 300);
  ASSERT_EQ(sheets.size(), 1u);
  EXPECT_EQ(sheets[0].id, "b");
  EXPECT_THAT(message_of([&] { remove_sheet(dir_, "a"); }),
              testing::AllOf(HasSubstr("no sheet 'a'"), HasSubstr("sheets: b")));
}

TEST_F(WoodLibraryTest, RemoveFromScannedFolderKeepsTheUsersScan) {
  fs::copy_file(kWood / "maple_dark.png", dir_ / "maple.png");
  fs::copy_file(kWood / "cherry_dark.png", dir_ / "cherry.png");
  remove_sheet(dir_, "maple");
  EXPECT_TRUE(fs::exists(dir_ / "maple.png"));
  auto sheets = list_sheets(dir_, 300);
  ASSERT_EQ(sheets.size(), 1u);
  EXPECT_EQ(sheets[0].id, "cherry");
}

}  // namespace
}  // namespace atelier

// probe_image / load_image on real images and on the bad inputs users actually drop.
#include "convert/common/image_input.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "convert/convert.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

const fs::path kData = ATELIER_TEST_DATA;

class ImageInputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("atelier-image-input-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string& name, const std::vector<unsigned char>& bytes) {
    fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                             static_cast<std::streamsize>(bytes.size()));
    return p;
  }

  static std::vector<unsigned char> read(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  // The message of the ConvertError thrown by `f`, or "" when none was thrown.
  template <typename F>
  static std::string error_of(F f) {
    try {
      f();
    } catch (const ConvertError& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
};

void put_be32(std::vector<unsigned char>& v, uint32_t x) {
  for (int s = 24; s >= 0; s -= 8) v.push_back(static_cast<unsigned char>(x >> s));
}

// A PNG signature and an IHDR chunk claiming width x height (CRC left zero: the size check
// must come before any decoder would look at it).
std::vector<unsigned char> png_header(uint32_t width, uint32_t height) {
  std::vector<unsigned char> v = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  put_be32(v, 13);
  std::vector<unsigned char> chunk = {'I', 'H', 'D', 'R'};
  put_be32(chunk, width);
  put_be32(chunk, height);
  chunk.insert(chunk.end(), {8, 0, 0, 0, 0});  // 8-bit grey, no interlace
  v.insert(v.end(), chunk.begin(), chunk.end());
  put_be32(v, 0);
  return v;
}

TEST_F(ImageInputTest, ProbesRealImagesOfEveryTestFormat) {
  ImageHeader png = probe_image(kData / "pic3.png");
  EXPECT_EQ(png.format, "png");
  EXPECT_EQ(png.width, 400u);
  EXPECT_EQ(png.height, 300u);
  ImageHeader jpg = probe_image(kData / "fruits.jpg");
  EXPECT_EQ(jpg.format, "jpeg");
  cv::Mat decoded = load_image(kData / "fruits.jpg", ImageLimits{});
  EXPECT_EQ(static_cast<uint64_t>(decoded.cols), jpg.width);
  EXPECT_EQ(static_cast<uint64_t>(decoded.rows), jpg.height);
}

TEST_F(ImageInputTest, ProbesFormatsWrittenByOpenCV) {
  cv::Mat img(37, 53, CV_8UC3, cv::Scalar(10, 200, 30));
  cv::Mat gray(37, 53, CV_8UC1, cv::Scalar(90));
  for (const char* ext : {".bmp", ".tiff", ".pnm", ".pgm", ".webp", ".png", ".jpg"}) {
    if (!cv::haveImageWriter(std::string("x") + ext)) continue;  // e.g. a build without WebP
    std::vector<unsigned char> bytes;
    ASSERT_TRUE(cv::imencode(ext, std::string(ext) == ".pgm" ? gray : img, bytes)) << ext;
    fs::path p = write(std::string("x") + ext, bytes);
    ImageHeader h = probe_image(p);
    EXPECT_EQ(h.width, 53u) << ext;
    EXPECT_EQ(h.height, 37u) << ext;
    cv::Mat back = load_image(p, ImageLimits{});
    EXPECT_EQ(back.cols, 53) << ext;
    EXPECT_EQ(back.rows, 37) << ext;
  }
}

TEST_F(ImageInputTest, TruncatedJpegIsRejectedNotHalfGrey) {
  std::vector<unsigned char> full = read(kData / "fruits.jpg");
  ASSERT_GT(full.size(), 1000u);
  std::vector<unsigned char> half(full.begin(), full.begin() + full.size() / 2);
  fs::path p = write("half.jpg", half);
  EXPECT_THAT(error_of([&] { load_image(p, ImageLimits{}); }),
              AllOf(HasSubstr("half.jpg"), HasSubstr("truncated")));
}

TEST_F(ImageInputTest, TruncatedPngIsRejected) {
  std::vector<unsigned char> full = read(kData / "pic3.png");
  std::vector<unsigned char> part(full.begin(), full.begin() + full.size() * 2 / 3);
  fs::path p = write("part.png", part);
  EXPECT_THAT(error_of([&] { load_image(p, ImageLimits{}); }),
              AllOf(HasSubstr("part.png"), HasSubstr("truncated")));
}

TEST_F(ImageInputTest, TextFileNamedPngIsNotAnImage) {
  std::string text = "hello, this is not a picture\n";
  fs::path p = write("pic.png", {text.begin(), text.end()});
  std::string probe_msg = error_of([&] { probe_image(p); });
  EXPECT_EQ(probe_msg, "pic.png: not an image (no PNG, JPEG, BMP, WebP, TIFF or PNM signature)");
  EXPECT_EQ(error_of([&] { load_image(p, ImageLimits{}); }), probe_msg);
}

TEST_F(ImageInputTest, HugePngHeaderIsRefusedBeforeDecoding) {
  fs::path p = write("huge.png", png_header(100000, 100000));
  ImageHeader h = probe_image(p);
  EXPECT_EQ(h.width, 100000u);
  EXPECT_EQ(h.height, 100000u);
  // The file holds no pixel data at all: only a header check can produce this message.
  EXPECT_THAT(error_of([&] { load_image(p, ImageLimits{}); }),
              AllOf(HasSubstr("huge.png"), HasSubstr("100000x100000"), HasSubstr("40000000")));
}

TEST_F(ImageInputTest, EmptyFileIsRejected) {
  fs::path p = write("empty.jpg", {});
  EXPECT_THAT(error_of([&] { probe_image(p); }), AllOf(HasSubstr("empty.jpg"), HasSubstr("empty")));
  EXPECT_THAT(error_of([&] { load_image(p, ImageLimits{}); }),
              AllOf(HasSubstr("empty.jpg"), HasSubstr("empty")));
}

TEST_F(ImageInputTest, FileOverTheSizeLimitIsRejected) {
  ImageLimits small;
  small.max_file_bytes = 1000;
  EXPECT_THAT(error_of([&] { load_image(kData / "pic3.png", small); }),
              AllOf(HasSubstr("pic3.png"), HasSubstr("26055 bytes"), HasSubstr("limit of 1000")));
}

TEST_F(ImageInputTest, PixelLimitAppliesToRealImages) {
  ImageLimits small;
  small.max_pixels = 400 * 300 - 1;
  EXPECT_THAT(error_of([&] { load_image(kData / "pic3.png", small); }),
              AllOf(HasSubstr("pic3.png"), HasSubstr("400x300")));
  small.max_pixels = 400 * 300;
  EXPECT_EQ(load_image(kData / "pic3.png", small).cols, 400);
}

TEST_F(ImageInputTest, HeaderWithoutSizeIsRejected) {
  std::vector<unsigned char> png = png_header(10, 10);
  png.resize(14);  // signature and part of the IHDR length/type
  fs::path p = write("cut.png", png);
  EXPECT_THAT(error_of([&] { probe_image(p); }), AllOf(HasSubstr("cut.png"), HasSubstr("size")));
  fs::path zero = write("zero.png", png_header(0, 10));
  EXPECT_THAT(error_of([&] { probe_image(zero); }), AllOf(HasSubstr("zero.png"), HasSubstr("size")));
}

TEST_F(ImageInputTest, DirectoriesMissingFilesAndDanglingLinksDoNotCrash) {
  EXPECT_THAT(error_of([&] { load_image(dir_, ImageLimits{}); }), HasSubstr("directory"));
  EXPECT_THAT(error_of([&] { load_image(dir_ / "gone.png", ImageLimits{}); }),
              AllOf(HasSubstr("gone.png"), HasSubstr("not found")));
  fs::create_symlink(dir_ / "nowhere.png", dir_ / "link.png");
  EXPECT_THAT(error_of([&] { load_image(dir_ / "link.png", ImageLimits{}); }),
              HasSubstr("link.png"));
  fs::create_symlink("/dev/zero", dir_ / "zero.jpg");
  EXPECT_THAT(error_of([&] { load_image(dir_ / "zero.jpg", ImageLimits{}); }),
              AllOf(HasSubstr("zero.jpg"), HasSubstr("not a regular file")));
}

TEST(ImageDepth, SixteenBitAndFloatPixelsBecomeTheirEightBitGreyLevels) {
  const cv::Mat eight(2, 2, CV_8UC3, cv::Scalar(10, 128, 255));
  EXPECT_EQ(to_8bit(eight).data, eight.data);  // already 8-bit: the same pixels, no copy
  const cv::Mat sixteen(2, 2, CV_16UC1, cv::Scalar(65535));
  EXPECT_EQ(to_8bit(sixteen).at<uchar>(1, 1), 255);
  EXPECT_EQ(to_8bit(cv::Mat(1, 1, CV_16UC1, cv::Scalar(257 * 100))).at<uchar>(0, 0), 100);
  // A float TIFF's 0..1: half grey stays half grey, not black.
  EXPECT_EQ(to_8bit(cv::Mat(1, 1, CV_32FC1, cv::Scalar(0.5))).at<uchar>(0, 0), 128);
  EXPECT_EQ(to_8bit(cv::Mat(1, 1, CV_64FC3, cv::Scalar(1.0, 0.0, 0.25))).at<cv::Vec3b>(0, 0), cv::Vec3b(255, 0, 64));
}

}  // namespace
}  // namespace atelier

// convert() for kind embroidery: an image becomes design.dst, design.exp, preview.png,
// normal.png, regions.png and report.json; bad parameters, a design larger than the hoop and
// bad user textures are clear errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "convert/convert.h"
#include "convert/common/param_table.h"
#include "tests/support/stitch_file_readers.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class ConvertEmbroideryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = fs::temp_directory_path() /
           ("atelier-convert-emb-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(out_);
  }
  void TearDown() override { fs::remove_all(out_); }
  ConvertResult run(const fs::path& input, const std::string& toml_text = "") {
    ConvertRequest req;
    req.kind = "embroidery";
    req.input = input;
    req.params = toml::parse(toml_text, std::string_view{"test.toml"});
    req.params_source = "test.toml";
    req.output_dir = out_;
    return convert(req);
  }
  std::string error_of(const fs::path& input, const std::string& toml_text) {
    try {
      run(input, toml_text);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "";
  }
  fs::path out_;
};

fs::path data(const std::string& name) { return fs::path(ATELIER_TEST_DATA) / name; }

TEST_F(ConvertEmbroideryTest, AnImageBecomesStitchFilesPreviewNormalMapLabelsAndAReport) {
  const ConvertResult r = run(data("HappyFish.jpg"), "width_mm = 70\n");
  for (const char* f : {"design.dst", "design.exp", "preview.png", "normal.png", "regions.png", "report.json"})
    EXPECT_TRUE(fs::exists(out_ / f)) << f;
  const nlohmann::json report = nlohmann::json::parse(slurp(out_ / "report.json"));
  EXPECT_EQ(report, r.report);
  EXPECT_NEAR(report["size_mm"][0].get<double>(), 70.0, 1e-9);
  // The report's counts are the file's: stitches and colour changes decoded from the DST.
  const embroidery::test::DstFile dst = embroidery::test::read_dst(slurp(out_ / "design.dst"));
  ASSERT_TRUE(dst.errors.empty()) << dst.errors.front();
  int colors = 0;
  for (const auto& rec : dst.records) colors += rec.type == embroidery::test::Ev::color;
  EXPECT_EQ(colors, report["color_changes"].get<int>());
  EXPECT_EQ(report["threads"].size(), static_cast<size_t>(colors + 1));
  EXPECT_EQ(dst.header.at("LA").substr(0, 9), "HappyFish");
  int regions = 0;
  for (const auto& [style, e] : report["regions"]["by_style"].items()) regions += e["count"].get<int>();
  EXPECT_EQ(regions, report["regions"]["total"].get<int>());
  EXPECT_LE(report["extent_mm"]["width"].get<double>(), 71.0);
  // Every thread is one of the palette's colours.
  for (const auto& t : report["threads"])
    EXPECT_NE(std::find(report["palette"].begin(), report["palette"].end(), t["rgb"]), report["palette"].end())
        << t.dump();
}

TEST_F(ConvertEmbroideryTest, TransparentPixelsAreNotSewnAndShowAsFabric) {
  run(data("opencv-logo.png"), "width_mm = 60\n");
  const cv::Mat regions = cv::imread((out_ / "regions.png").string());
  const cv::Mat logo = cv::imread(data("opencv-logo.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(logo.channels(), 4);
  cv::Mat alpha;
  cv::extractChannel(logo, alpha, 3);
  cv::resize(alpha, alpha, regions.size(), 0, 0, cv::INTER_NEAREST);
  int transparent = 0, white = 0;
  for (int y = 0; y < regions.rows; ++y)
    for (int x = 0; x < regions.cols; ++x) {
      if (alpha.at<uchar>(y, x) != 0) continue;
      ++transparent;
      white += regions.at<cv::Vec3b>(y, x) == cv::Vec3b(255, 255, 255);
    }
  ASSERT_GT(transparent, 1000);
  EXPECT_GT(white, transparent * 0.97) << "transparent pixels must not be sewn";
}

TEST_F(ConvertEmbroideryTest, ADesignLargerThanTheHoopFailsWithTheSizes) {
  const std::string e = error_of(data("pic1.png"), "width_mm = 150\nhoop_width_mm = 100\nhoop_height_mm = 100\n");
  EXPECT_THAT(e, HasSubstr("pic1.png"));
  EXPECT_THAT(e, HasSubstr("hoop"));
  EXPECT_FALSE(fs::exists(out_ / "design.dst")) << "nothing is written for a design that cannot be sewn";
}

TEST_F(ConvertEmbroideryTest, WithTheDefaultsEveryRealImageFitsTheHoop) {
  for (const char* image : {"fruits.jpg", "butterfly.jpg", "opencv-logo.png", "LinuxLogo.jpg"}) {
    const ConvertResult r = run(data(image));
    const nlohmann::json& e = r.report["extent_mm"];
    EXPECT_LE(e["width"].get<double>(), 100.0) << image;
    EXPECT_LE(e["height"].get<double>(), 100.0) << image;
    EXPECT_NEAR(std::max(r.report["size_mm"][0].get<double>(), r.report["size_mm"][1].get<double>()), 90.0, 1e-6)
        << image << ": as large as fits the 100 mm hoop, 5 mm in from its edge";
  }
}

TEST_F(ConvertEmbroideryTest, AnImageWithNothingToSewFailsSayingSo) {
  const fs::path white = out_.string() + "-white.png";
  cv::imwrite(white.string(), cv::Mat3b(200, 300, cv::Vec3b(255, 255, 255)));
  const std::string e = error_of(white, "");
  fs::remove(white);
  EXPECT_THAT(e, HasSubstr("white.png"));
  EXPECT_THAT(e, HasSubstr("nothing to sew"));
}

TEST_F(ConvertEmbroideryTest, AHugeDesignFailsAtOnceWithoutWorkingOnIt) {
  // 2000 mm at 10 px/mm would be 20000 px wide; the hoop check comes first.
  const std::string e = error_of(data("fruits.jpg"), "width_mm = 2000\n");
  EXPECT_THAT(e, HasSubstr("2000.0 x"));
  EXPECT_THAT(e, HasSubstr("the hoop is 100.0 x 100.0 mm"));
}

TEST_F(ConvertEmbroideryTest, BadParametersNameTheKey) {
  EXPECT_THAT(error_of(data("pic1.png"), "colours = 4\n"), HasSubstr("colours"));
  EXPECT_THAT(error_of(data("pic1.png"), "colors = \"many\"\n"), HasSubstr("colors"));
  EXPECT_THAT(error_of(data("pic1.png"), "eW = 5.0\nsW = 4.0\n"), HasSubstr("sW"));
  EXPECT_THAT(error_of(data("pic1.png"), "median = 4\n"), HasSubstr("median"));
  EXPECT_THAT(error_of(data("pic1.png"), "satin_max_mm = 30\n"), HasSubstr("satin_max_mm"));
  // No stitch may be longer than one DST record.
  EXPECT_THAT(error_of(data("pic1.png"), "satin_max_mm = 12\nsatin_pull_comp_mm = 0.5\n"), HasSubstr("satin_pull_comp_mm"));
  EXPECT_THAT(error_of(data("pic1.png"), "trim_jump_mm = 20\n"), HasSubstr("trim_jump_mm"));
  // The minimum stitch stays below the shortest stitch any style may ask for (0.5 mm).
  EXPECT_THAT(error_of(data("pic1.png"), "min_stitch_mm = 0.5\n"), HasSubstr("min_stitch_mm"));
  EXPECT_THAT(error_of(data("pic1.png"), "texture_dpi = 1\n"), HasSubstr("texture_dpi"));
}

TEST_F(ConvertEmbroideryTest, UserTexturesReplaceTheProceduralOnesAndBadOnesAreNamed) {
  const fs::path tex = out_.string() + "-tex";
  fs::remove_all(tex);
  fs::create_directories(tex);
  // A user's satin texture: grey thread rows with transparent seams, 3 x 1 mm at 254 dpi.
  cv::Mat4b satin(10, 30, cv::Vec4b(150, 150, 150, 255));
  for (int x = 0; x < satin.cols; x += 5) satin.col(x).setTo(cv::Vec4b(0, 0, 0, 0));
  cv::imwrite((tex / "satin.png").string(), satin);
  const ConvertResult r = run(data("pic1.png"), "width_mm = 60\ntextures = \"" + tex.string() + "\"\ntexture_dpi = 254\n");
  EXPECT_EQ(r.report["textures"]["satin"], (tex / "satin.png").string());
  EXPECT_EQ(r.report["textures"]["long_short"], "procedural");
  cv::imwrite((tex / "edge.normal.png").string(), cv::Mat3b(3, 3, cv::Vec3b(255, 128, 128)));
  cv::imwrite((tex / "edge.png").string(), satin);
  EXPECT_THAT(error_of(data("pic1.png"), "textures = \"" + tex.string() + "\"\n"), HasSubstr("edge.normal.png"));
  EXPECT_THAT(error_of(data("pic1.png"), "textures = \"" + tex.string() + "/nope\"\n"), HasSubstr("nope"));
  fs::remove_all(tex);
}


// ---- issue 21 point 3 (colours helper): an opaque RGBA PNG is sewn like the same RGB PNG ----
TEST_F(ConvertEmbroideryTest, AnOpaqueRgbaPngIsSewnLikeTheSameRgbPngWithoutItsWhiteSheet) {
  cv::Mat3b img(300, 400, cv::Vec3b(255, 255, 255));
  cv::circle(img, {120, 150}, 80, cv::Vec3b(0, 0, 0), cv::FILLED);
  cv::rectangle(img, cv::Rect(240, 90, 120, 120), cv::Vec3b(200, 60, 30), cv::FILLED);
  cv::Mat4b rgba;
  cv::cvtColor(img, rgba, cv::COLOR_BGR2BGRA);  // alpha 255 everywhere
  const fs::path rgb_png = out_.string() + "-rgb.png", rgba_png = out_.string() + "-rgba.png";
  cv::imwrite(rgb_png.string(), img);
  cv::imwrite(rgba_png.string(), rgba);
  ASSERT_EQ(cv::imread(rgba_png.string(), cv::IMREAD_UNCHANGED).channels(), 4);
  const nlohmann::json a = run(rgb_png, "width_mm = 80\n").report;
  const nlohmann::json b = run(rgba_png, "width_mm = 80\n").report;
  const cv::Mat regions = cv::imread((out_ / "regions.png").string());
  fs::remove(rgb_png);
  fs::remove(rgba_png);
  const double sa = a["stitches"].get<double>(), sb = b["stitches"].get<double>();
  EXPECT_NEAR(sb, sa, 0.01 * sa) << "the same design, the same stitches";
  EXPECT_EQ(b["palette"], a["palette"]);
  EXPECT_EQ(b["palette"].size(), 2u) << b["palette"].dump() << ": black and blue, no white thread";
  for (const auto& t : b["threads"]) {
    const unsigned long c = std::stoul(t["rgb"].get<std::string>().substr(1), nullptr, 16);
    EXPECT_LT(std::min({c >> 16, (c >> 8) & 0xff, c & 0xff}), 200u) << t.dump() << " is a white thread";
  }
  // The sheet around the shapes is fabric: the design is the shapes' size (the disk's left
  // edge to the blue square's right: 320 of 400 px, 64 mm), not the whole 80 mm.
  EXPECT_LT(b["extent_mm"]["width"].get<double>(), 66.0);
  ASSERT_FALSE(regions.empty());
  EXPECT_EQ(regions.at<cv::Vec3b>(2, 2), cv::Vec3b(255, 255, 255)) << "the corner is not sewn";
}

// ---- issue 21 point 4 (colours helper): the issue's four flat colours are four threads ----
TEST_F(ConvertEmbroideryTest, TheIssuesFourFlatColoursAreSewnInFourThreadsOfTheirColours) {
  const int rgb[4][3] = {{120, 152, 120}, {216, 152, 120}, {120, 184, 184}, {120, 120, 168}};
  cv::Mat3b img(300, 300);
  for (int q = 0; q < 4; ++q)
    img(cv::Rect((q % 2) * 150, (q / 2) * 150, 150, 150)).setTo(cv::Vec3b(rgb[q][2], rgb[q][1], rgb[q][0]));
  const fs::path png = out_.string() + "-four.png";
  cv::imwrite(png.string(), img);
  const nlohmann::json report = run(png, "width_mm = 60\n").report;
  fs::remove(png);
  auto lab = [](int r, int g, int b) {
    cv::Mat3f one(1, 1, cv::Vec3f(b / 255.f, g / 255.f, r / 255.f)), out;
    cv::cvtColor(one, out, cv::COLOR_BGR2Lab);
    return out(0, 0);
  };
  ASSERT_EQ(report["threads"].size(), 4u) << report["threads"].dump();
  for (int q = 0; q < 4; ++q) {
    double nearest = 1e9;
    for (const auto& t : report["threads"]) {
      const unsigned long c = std::stoul(t["rgb"].get<std::string>().substr(1), nullptr, 16);
      nearest = std::min(nearest, cv::norm(lab(int(c >> 16), int((c >> 8) & 0xff), int(c & 0xff)) -
                                           lab(rgb[q][0], rgb[q][1], rgb[q][2])));
    }
    EXPECT_LT(nearest, 5.0) << "no thread near colour " << q;
  }
}

}  // namespace
}  // namespace atelier

// Issue 21 point 2 on real images: every region of more than 4 mm², whatever its style, is
// covered to at least 98 % by its own stitches (thread 0.4 mm wide, coverage.h), at the
// default size (90 mm, the 100 mm hoop less its margin), and report.json says so per style.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "algorithms/embroidery/coverage.h"
#include "algorithms/embroidery/pipeline.h"
#include "convert/common/param_table.h"
#include "convert/convert.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
namespace emb = embroidery;

fs::path data(const std::string& name) { return fs::path(ATELIER_TEST_DATA) / name; }

class EmbroideryCoverageTest : public ::testing::TestWithParam<const char*> {};

TEST_P(EmbroideryCoverageTest, EveryRegionOver4mm2IsCovered) {
  const cv::Mat image = cv::imread(data(GetParam()).string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  const emb::DesignParams params;  // width_mm = 0: 90 mm on the default hoop
  const emb::Design d = emb::make_design(image, emb::procedural_textures(), params);
  EXPECT_NEAR(d.width_mm, 90.0, 1e-6);
  emb::StitchParams sp = params.stitches;
  sp.px_per_mm = d.px_per_mm;
  int measured[emb::kStyleCount] = {0, 0, 0};
  for (const emb::RegionCoverage& r : emb::design_coverage(d.segmentation, d.directions, sp)) {
    if (r.area_mm2 <= 4.0) continue;
    ++measured[static_cast<int>(r.style)];
    EXPECT_GE(r.coverage, 0.98) << GetParam() << ": region " << r.region << " (" << emb::style_name(r.style) << ", "
                                << r.area_mm2 << " mm²)";
  }
  EXPECT_GT(measured[static_cast<int>(emb::Style::satin)], 0) << "no satin region to measure";
}

INSTANTIATE_TEST_SUITE_P(RealImages, EmbroideryCoverageTest,
                         ::testing::Values("fruits.jpg", "HappyFish.jpg", "LinuxLogo.jpg", "butterfly.jpg",
                                           "starry_night.jpg"));

TEST(EmbroideryCoverageReport, ReportGivesCoveragePerStyle) {
  const fs::path out = fs::temp_directory_path() / ("atelier-emb-coverage-" + std::to_string(::getpid()));
  fs::remove_all(out);
  ConvertRequest req;
  req.kind = "embroidery";
  req.input = data("HappyFish.jpg");
  req.params = toml::parse("", std::string_view{"test.toml"});
  req.params_source = "test.toml";
  req.output_dir = out;
  convert(req);
  std::ifstream in(out / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  fs::remove_all(out);
  ASSERT_TRUE(report.contains("coverage"));
  for (const char* style : {"long_short", "satin", "edge"}) {
    const nlohmann::json& c = report["coverage"][style];
    EXPECT_GT(c["regions"].get<int>(), 0) << style;  // HappyFish has regions over 4 mm² of each style
    EXPECT_GE(c["min"].get<double>(), 0.98) << style;
    EXPECT_GE(c["mean"].get<double>(), c["min"].get<double>()) << style;
    EXPECT_EQ(c["regions_below_98"].get<int>(), 0) << style;
  }
}

}  // namespace
}  // namespace atelier

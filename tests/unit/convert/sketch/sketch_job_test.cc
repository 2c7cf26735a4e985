// convert() for kind sketch: an image becomes a pencil drawing (preview.png), its hand-drawn
// paths (lines.svg), an engraving (engrave.gcode) and report.json.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "convert/convert.h"
#include "convert/kinds.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/convert_kind.h"
#include "convert/common/param_table.h"
#include "convert/sketch/pencil_profile_file.h"
#include "drivers/grbl/program.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kData = fs::path(ATELIER_TEST_DATA);

class ConvertSketchTest : public ::testing::Test {
 protected:
  ConvertResult run(const fs::path& input, const std::string& params_toml = "", const std::string& out = "out") {
    return test::convert_kind("sketch", input, params_toml, dir_ / out);
  }
  test::TempDir tmp_;
  const fs::path dir_ = tmp_.path();
};

// Share of the input's edge pixels (Canny on the image, scaled to the drawing) that have a
// pencil mark (darker than 200) within `tolerance` drawing px.
double edges_covered_by_pencil(const cv::Mat& image, const cv::Mat& preview, int tolerance) {
  cv::Mat grey, edges, big;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  cv::Canny(grey, edges, 50, 150);
  cv::resize(edges, big, preview.size(), 0, 0, cv::INTER_NEAREST);
  cv::Mat marks = preview < 200, near;
  cv::dilate(marks, near, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * tolerance + 1, 2 * tolerance + 1}));
  const int all = cv::countNonZero(big);
  return all ? static_cast<double>(cv::countNonZero(big & near)) / all : 0.0;
}

TEST_F(ConvertSketchTest, ALineDrawingIsRedrawnInPencilOverItsEdges) {
  for (const char* name : {"pic1.png", "pic3.png", "pic5.png"}) {
    SCOPED_TRACE(name);
    const ConvertResult r = run(kData / name, "", name);
    const fs::path out = dir_ / name;
    EXPECT_EQ(r.outputs, (std::vector<std::string>{"preview.png", "lines.svg", "engrave.gcode", "report.json"}));
    const cv::Mat image = cv::imread((kData / name).string(), cv::IMREAD_COLOR);
    const cv::Mat preview = cv::imread((out / "preview.png").string(), cv::IMREAD_GRAYSCALE);
    ASSERT_EQ(preview.size(), cv::Size(image.cols * 2, image.rows * 2));
    const double covered = edges_covered_by_pencil(image, preview, 8);
    std::cout << name << ": " << r.report["strokes"] << " strokes, edges covered " << covered << "\n";
    EXPECT_GT(covered, 0.85) << "the pencil lines miss the drawing's edges";
    // Paper stays paper: most of the page is untouched white.
    EXPECT_GT(cv::countNonZero(preview == 255), preview.total() / 2);
    EXPECT_EQ(r.report["pencil"]["name"], "HB");
    EXPECT_EQ(r.report["lines"].get<size_t>(), r.report["strokes"].get<size_t>());
  }
}

TEST_F(ConvertSketchTest, SvgHoldsEveryHandDrawnPathAndTheGcodeEngravesThemWhereAsked) {
  const ConvertResult r = run(kData / "pic3.png", "width_mm = 80\nposition_mm = [20, 30]\npencil = \"2H\"\n");
  const std::string svg = test::read_file(dir_ / "out" / "lines.svg");
  size_t paths = 0;
  for (size_t at = svg.find("<path d=\"M"); at != std::string::npos; at = svg.find("<path d=\"M", at + 1)) ++paths;
  EXPECT_EQ(paths, r.report["lines"].get<size_t>());
  EXPECT_THAT(svg, HasSubstr("width=\"80mm\" height=\"60mm\" viewBox=\"0 0 800 600\""));
  EXPECT_THAT(svg, HasSubstr("stroke=\"#3c3c3c\""));

  const std::string gcode = test::read_file(dir_ / "out" / "engrave.gcode");
  const grbl::Program prog = grbl::parse_program(gcode, 6000);  // GRBL can take every line
  ASSERT_TRUE(prog.bounds);
  // Design (20..100, 30..90) mm on a 400 mm front-left bed: machine Y = 400 - y.
  EXPECT_GE(prog.bounds->min_x, 20 - 0.01);
  EXPECT_LE(prog.bounds->max_x, 100 + 0.01);
  EXPECT_GE(prog.bounds->min_y, 310 - 0.01);
  EXPECT_LE(prog.bounds->max_y, 370 + 0.01);
  EXPECT_GT(prog.bounds->width(), 60);
  EXPECT_EQ(r.report["engrave"]["power_from"], "pencil");
  EXPECT_GT(r.report["engrave"]["length_mm"].get<double>(), 100);
}

TEST_F(ConvertSketchTest, SofterPencilsDrawAndBurnDarker) {
  const ConvertResult hard = run(kData / "pic5.png", "pencil = \"2H\"\n", "2H");
  const ConvertResult soft = run(kData / "pic5.png", "pencil = \"8B\"\n", "8B");
  EXPECT_LT(hard.report["engrave"]["power_pct"].get<double>(), soft.report["engrave"]["power_pct"].get<double>());
  auto darkness = [&](const char* d) {
    const cv::Mat p = cv::imread((dir_ / d / "preview.png").string(), cv::IMREAD_GRAYSCALE);
    return 255.0 - cv::mean(p, p < 250)[0];
  };
  EXPECT_GT(darkness("8B"), darkness("2H") + 20);
  // An explicit power wins.
  const ConvertResult fixed = run(kData / "pic5.png", "pencil = \"8B\"\npower_pct = 12\n", "fixed");
  EXPECT_EQ(fixed.report["engrave"]["power_pct"], 12);
  EXPECT_THAT(test::read_file(dir_ / "fixed" / "engrave.gcode"), HasSubstr("S120"));
}

TEST_F(ConvertSketchTest, SeedsAreReproducibleAndDifferentSeedsDrawDifferentLines) {
  run(kData / "pic1.png", "seed = 7\n", "a");
  run(kData / "pic1.png", "seed = 7\n", "b");
  run(kData / "pic1.png", "seed = 8\n", "c");
  EXPECT_EQ(test::read_file(dir_ / "a" / "lines.svg"), test::read_file(dir_ / "b" / "lines.svg"));
  EXPECT_EQ(test::read_file(dir_ / "a" / "preview.png"), test::read_file(dir_ / "b" / "preview.png"));
  EXPECT_NE(test::read_file(dir_ / "a" / "lines.svg"), test::read_file(dir_ / "c" / "lines.svg"));
  // Without squiggle the lines are straight: the same for every seed.
  run(kData / "pic1.png", "seed = 7\nsquiggle = 0\n", "d");
  run(kData / "pic1.png", "seed = 8\nsquiggle = 0\n", "e");
  EXPECT_EQ(test::read_file(dir_ / "d" / "lines.svg"), test::read_file(dir_ / "e" / "lines.svg"));
}

TEST_F(ConvertSketchTest, HatchingFillsDarkRegionsWithLines) {
  cv::Mat img(200, 300, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::rectangle(img, {50, 50}, {249, 149}, cv::Scalar(30, 30, 30), cv::FILLED);
  cv::imwrite((dir_ / "dark.png").string(), img);
  const ConvertResult plain = run(dir_ / "dark.png", "", "plain");
  const ConvertResult hatched = run(dir_ / "dark.png", "hatching = true\n", "hatched");
  EXPECT_EQ(plain.report["hatch_lines"], 0);
  EXPECT_GT(hatched.report["hatch_lines"].get<int>(), 20);
  const cv::Mat a = cv::imread((dir_ / "plain" / "preview.png").string(), cv::IMREAD_GRAYSCALE);
  const cv::Mat b = cv::imread((dir_ / "hatched" / "preview.png").string(), cv::IMREAD_GRAYSCALE);
  const cv::Rect inside(130, 130, 340, 140);  // the square, inset from its outline (drawing px)
  EXPECT_LT(cv::mean(b(inside))[0], cv::mean(a(inside))[0] - 20) << "hatching did not darken the square";
  const cv::Rect outside(0, 0, 600, 60);  // paper above it
  EXPECT_EQ(cv::countNonZero(b(outside) < 200), 0) << "hatching spilled onto the paper";
  const std::string svg = test::read_file(dir_ / "hatched" / "lines.svg");
  EXPECT_THAT(svg, HasSubstr("<g id=\"hatching\""));
}

TEST_F(ConvertSketchTest, APencilProfileFileCanBeUsed) {
  pencil::PencilProfile mine = shipped_pencil("B");
  mine.name = "my-b";
  { std::ofstream(dir_ / "my-b.toml") << profile_to_toml(mine); }
  std::ofstream(dir_ / "params.toml") << "pencil = \"my-b.toml\"\n";
  ConvertRequest req;
  req.kind = "sketch";
  req.input = kData / "pic1.png";
  req.params = toml::parse_file((dir_ / "params.toml").string());
  validate_kind_params("sketch", req.params, (dir_ / "params.toml").string());
  req.output_dir = dir_ / "out";
  const ConvertResult r = convert(req);
  EXPECT_EQ(r.report["pencil"]["name"], "my-b");
}

TEST_F(ConvertSketchTest, BadInputsAndParametersAreClearErrors) {
  cv::imwrite((dir_ / "blank.png").string(), cv::Mat(100, 100, CV_8UC3, cv::Scalar(255, 255, 255)));
  try {
    run(dir_ / "blank.png");
    FAIL() << "a blank page converted";
  } catch (const ConvertError& e) {
    EXPECT_THAT(e.what(), HasSubstr("blank.png: nothing to draw"));
  }
  try {
    run(kData / "pic1.png", "pencil = \"7B\"\n");
    FAIL() << "an unknown pencil was accepted";
  } catch (const ParamError& e) {
    EXPECT_THAT(e.what(), HasSubstr("test.toml:1: key 'pencil'"));
    EXPECT_THAT(e.what(), HasSubstr("2H, H, F, HB, B, 3B, 6B, 8B"));
  }
  EXPECT_THROW(run(kData / "pic1.png", "squigle = 3\n"), ParamError);
  EXPECT_THROW(run(kData / "pic1.png", "position_mm = [1]\n"), ParamError);
  try {
    run(kData / "pic1.png", "width_mm = 500\n");
    FAIL() << "an engraving larger than the bed was accepted";
  } catch (const ConvertError& e) {
    EXPECT_THAT(e.what(), HasSubstr("pic1.png: engraving 500 mm wide"));
    EXPECT_THAT(e.what(), HasSubstr("outside"));
  }
  try {
    run(kData / "pic1.png", "pencil = \"" + (dir_ / "missing.toml").string() + "\"\n");
    FAIL() << "a missing pencil file was accepted";
  } catch (const ConvertError& e) {
    EXPECT_THAT(e.what(), HasSubstr("missing.toml"));
    // Named by where the parameters came from (was "pencil: key 'pencil'").
    EXPECT_THAT(e.what(), ::testing::StartsWith("parameters: key 'pencil': "));
    EXPECT_THAT(e.what(), HasSubstr("missing.toml: no such file"));
  }
  std::ofstream(dir_ / "text.png") << "not an image";
  EXPECT_THROW(run(dir_ / "text.png"), ConvertError);
}

// A drawing at the bed's corner: hand-drawn lines wander past the drawing's edge by up to the
// squiggle, and the engraving once left the work area there (the job failed at X -0.29 mm).
TEST_F(ConvertSketchTest, AnEngravingAtTheBedsCornerStaysInsideTheDrawingAndTheBed) {
  // All dark: hatch lines run right up to every edge.
  cv::imwrite((dir_ / "dark.png").string(), cv::Mat(200, 300, CV_8UC1, cv::Scalar(20)));
  struct Corner {
    const char* position;
    double x0, y0;
  };
  for (const Corner& c : {Corner{"[0, 0]", 0, 0}, Corner{"[300, 333.333]", 300, 333.333}}) {
    SCOPED_TRACE(c.position);
    const std::string out = "at" + std::to_string(static_cast<int>(c.x0));
    const ConvertResult r =
        run(dir_ / "dark.png", std::string("hatching = true\nwidth_mm = 100\nposition_mm = ") + c.position + "\n", out);
    EXPECT_GT(r.report["hatch_lines"].get<int>(), 20);
    const grbl::Program prog = grbl::parse_program(test::read_file(dir_ / out / "engrave.gcode"), 6000);
    ASSERT_TRUE(prog.bounds);
    // Design x in [x0, x0 + 100], y in [y0, y0 + 66.667] on a 400 mm front-left bed (Y = 400 - y).
    EXPECT_GE(prog.bounds->min_x, c.x0 - 1e-3);
    EXPECT_LE(prog.bounds->max_x, c.x0 + 100 + 1e-3);
    EXPECT_GE(prog.bounds->min_y, 400 - c.y0 - 66.667 - 1e-3);
    EXPECT_LE(prog.bounds->max_y, 400 - c.y0 + 1e-3);
    EXPECT_GT(prog.bounds->width(), 99) << "clipped, not dropped: the engraving still fills the drawing";
  }
}

// position_mm = [nan, 3] once passed the range check and hung the laser planner.
TEST_F(ConvertSketchTest, ANonNumberPositionIsRefusedNamingTheKey) {
  for (const char* pos : {"[nan, 3]", "[3, nan]", "[inf, 3]", "[3, -inf]"}) {
    try {
      run(kData / "pic1.png", std::string("position_mm = ") + pos + "\n");
      FAIL() << pos << " was accepted";
    } catch (const ParamError& e) {
      EXPECT_THAT(e.what(), HasSubstr("test.toml:1: key 'position_mm'")) << pos;
    }
  }
}

// Decoders give a float TIFF's pixels as 0..1: once read as grey levels 0 and 1, a drawing was
// all black (no edges; hatched all over). 16-bit and float pixels draw as their 8-bit image does.
TEST_F(ConvertSketchTest, SixteenBitAndFloatImagesDrawAsTheirEightBitImage) {
  cv::Mat eight(200, 300, CV_8UC1, cv::Scalar(255));
  cv::rectangle(eight, {50, 50}, {250, 150}, cv::Scalar(0), 3);
  cv::Mat sixteen, floating;
  eight.convertTo(sixteen, CV_16U, 257);
  eight.convertTo(floating, CV_32F, 1.0 / 255);
  ASSERT_TRUE(cv::imwrite((dir_ / "eight.png").string(), eight));
  ASSERT_TRUE(cv::imwrite((dir_ / "sixteen.png").string(), sixteen));
  ASSERT_TRUE(cv::imwrite((dir_ / "floating.tiff").string(), floating));
  ASSERT_EQ(cv::imread((dir_ / "floating.tiff").string(), cv::IMREAD_UNCHANGED).depth(), CV_32F);
  const ConvertResult want = run(dir_ / "eight.png", "hatching = true\n", "eight");
  EXPECT_GE(want.report["strokes"].get<int>(), 4);
  EXPECT_LE(want.report["hatch_lines"].get<int>(), 2) << "the white page is not hatched";
  for (const char* other : {"sixteen.png", "floating.tiff"}) {
    SCOPED_TRACE(other);
    const std::string out = std::string("out-") + other;
    run(dir_ / other, "hatching = true\n", out);
    EXPECT_EQ(test::read_file(dir_ / out / "lines.svg"), test::read_file(dir_ / "eight" / "lines.svg"));
  }
}

}  // namespace
}  // namespace atelier

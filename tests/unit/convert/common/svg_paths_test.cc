// read_svg: shapes, units, transforms and stroke colours of SVG drawings, in mm.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <fstream>

#include "convert/convert.h"
#include "convert/common/svg_paths.h"
#include "tests/support/hostile_svg.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using laser::bounds_of;

const fs::path kSvgData = fs::path(ATELIER_TEST_DATA) / "svg";

class SvgPathsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("atelier-svg-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  SvgDrawing read(const std::string& svg, double tolerance = 0.05) {
    fs::path f = dir_ / "drawing.svg";
    std::ofstream(f) << svg;
    return read_svg(f, tolerance);
  }

  fs::path dir_;
};

void expect_box(const laser::Path& p, double x0, double y0, double x1, double y1,
                double tol = 1e-6) {
  laser::Bounds b = bounds_of(p);
  EXPECT_NEAR(b.min_x, x0, tol);
  EXPECT_NEAR(b.min_y, y0, tol);
  EXPECT_NEAR(b.max_x, x1, tol);
  EXPECT_NEAR(b.max_y, y1, tol);
}

TEST_F(SvgPathsTest, ShapesInMillimetresThroughTheViewBox) {
  SvgDrawing d = read_svg(kSvgData / "shapes-mm.svg", 0.05);
  EXPECT_DOUBLE_EQ(d.width_mm, 100);
  EXPECT_DOUBLE_EQ(d.height_mm, 50);
  ASSERT_EQ(d.shapes.size(), 5u);

  const SvgShape& rect = d.shapes[0];
  EXPECT_EQ(rect.stroke, "#000000");
  EXPECT_FALSE(rect.filled);
  ASSERT_EQ(rect.paths.size(), 1u);
  EXPECT_TRUE(rect.paths[0].closed);
  EXPECT_EQ(rect.paths[0].points.size(), 4u);
  expect_box(rect.paths[0], 10, 10, 30, 20);

  const SvgShape& circle = d.shapes[1];
  EXPECT_EQ(circle.stroke, "#ff0000") << "from style=, upper case in the file";
  ASSERT_EQ(circle.paths.size(), 1u);
  EXPECT_TRUE(circle.paths[0].closed);
  for (auto p : circle.paths[0].points) {
    double r = std::hypot(p.x - 50, p.y - 25);
    EXPECT_NEAR(r, 10, 0.05) << "every vertex on the circle, chords within tolerance";
  }
  EXPECT_GE(circle.paths[0].points.size(), 16u);

  // Inside <g stroke="#0000ff" transform="translate(60,5)">: m 10 10 h 10 v 10 h -10 z.
  const SvgShape& relative = d.shapes[2];
  EXPECT_EQ(relative.stroke, "#0000ff") << "inherited from the group";
  ASSERT_EQ(relative.paths.size(), 1u);
  EXPECT_TRUE(relative.paths[0].closed);
  expect_box(relative.paths[0], 70, 15, 80, 25);

  // M 0 30 a 5 5 0 0 1 10 0 q 5 -5 10 0: a half circle up to y = 25, then a bump.
  const SvgShape& arc = d.shapes[3];
  ASSERT_EQ(arc.paths.size(), 1u);
  EXPECT_FALSE(arc.paths[0].closed);
  expect_box(arc.paths[0], 60, 30, 80, 35, 0.05);
  EXPECT_NEAR(arc.paths[0].points.front().x, 60, 1e-6);
  EXPECT_NEAR(arc.paths[0].points.back().x, 80, 1e-6);

  const SvgShape& filled = d.shapes[4];
  EXPECT_EQ(filled.stroke, "") << "no stroke anywhere up the tree";
  EXPECT_TRUE(filled.filled) << "SVG's initial fill is black";
}

TEST_F(SvgPathsTest, PhysicalUnitsWithoutViewBox) {
  // 2 in wide = 192 px user space; a line across it is 50.8 mm long.
  SvgDrawing d = read(R"svg(<svg xmlns="http://www.w3.org/2000/svg" width="2in" height="10cm">
    <line x1="0" y1="0" x2="192" y2="0" stroke="black"/></svg>)svg");
  EXPECT_NEAR(d.width_mm, 50.8, 1e-9);
  EXPECT_NEAR(d.height_mm, 100, 1e-9);
  ASSERT_EQ(d.shapes.size(), 1u);
  EXPECT_NEAR(d.shapes[0].paths[0].points[1].x, 50.8, 1e-9);
}

TEST_F(SvgPathsTest, ViewBoxWithoutSizeIsInPixels) {
  SvgDrawing d = read(R"svg(<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 96 48">
    <rect x="48" y="0" width="48" height="48" stroke="red" fill="none"/></svg>)svg");
  EXPECT_NEAR(d.width_mm, 25.4, 1e-9);
  EXPECT_NEAR(d.height_mm, 12.7, 1e-9);
  expect_box(d.shapes[0].paths[0], 12.7, 0, 25.4, 12.7);
}

TEST_F(SvgPathsTest, NestedTransformsCompose) {
  SvgDrawing d = read(R"svg(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm"
      viewBox="0 0 100 100">
    <g transform="translate(50 50)" stroke="black" fill="none">
      <g transform="scale(2)">
        <rect x="0" y="0" width="10" height="5" transform="rotate(90)"/>
      </g>
    </g></svg>)svg");
  ASSERT_EQ(d.shapes.size(), 1u);
  // rotate(90) maps (10, 5) to (-5, 10); scaled by 2 and moved by (50, 50).
  expect_box(d.shapes[0].paths[0], 40, 50, 50, 70);
}

TEST_F(SvgPathsTest, StrokeFromStyleOverridesAttributeAndCurrentColor) {
  SvgDrawing d = read(R"svg(<svg xmlns="http://www.w3.org/2000/svg" width="10mm" height="10mm"
      viewBox="0 0 10 10">
    <g style="stroke:#00f" color="#123456">
      <path d="M 1 1 L 9 9" stroke="red" style="stroke: #ff0000"/>
      <path d="M 1 9 L 9 1"/>
      <path d="M 1 5 L 9 5" stroke="currentColor"/>
      <path d="M 5 1 L 5 9" stroke="none"/>
    </g></svg>)svg");
  ASSERT_EQ(d.shapes.size(), 4u);
  EXPECT_EQ(d.shapes[0].stroke, "#ff0000");
  EXPECT_EQ(d.shapes[1].stroke, "#0000ff");
  EXPECT_EQ(d.shapes[2].stroke, "#123456");
  EXPECT_EQ(d.shapes[3].stroke, "");
}

TEST_F(SvgPathsTest, PolygonsPolylinesEllipsesAndHiddenGroups) {
  SvgDrawing d = read(R"svg(<svg xmlns="http://www.w3.org/2000/svg" width="50mm" height="50mm"
      viewBox="0 0 50 50">
    <g stroke="black" fill="none">
      <polygon points="0,0 10,0 10,10"/>
      <polyline points="20,0 30,0 30,10"/>
      <ellipse cx="25" cy="25" rx="10" ry="5"/>
      <rect x="1" y="1" width="20" height="10" rx="3"/>
      <g display="none"><rect width="5" height="5"/></g>
    </g></svg>)svg");
  ASSERT_EQ(d.shapes.size(), 4u);
  EXPECT_TRUE(d.shapes[0].paths[0].closed);
  EXPECT_EQ(d.shapes[0].paths[0].points.size(), 3u);
  EXPECT_FALSE(d.shapes[1].paths[0].closed);
  expect_box(d.shapes[2].paths[0], 15, 20, 35, 30, 0.05);
  expect_box(d.shapes[3].paths[0], 1, 1, 21, 11, 0.05);
  EXPECT_GT(d.shapes[3].paths[0].points.size(), 8u) << "rounded corners are flattened";
}

TEST_F(SvgPathsTest, SubpathsAndImplicitClosing) {
  SvgDrawing d = read(R"svg(<svg xmlns="http://www.w3.org/2000/svg" width="50mm" height="50mm"
      viewBox="0 0 50 50">
    <path stroke="black" d="M 0 0 H 10 V 10 H 0 V 0 M 20 20 L 30 20 Z l 0 5"/></svg>)svg");
  ASSERT_EQ(d.shapes.size(), 1u);
  ASSERT_EQ(d.shapes[0].paths.size(), 3u);
  EXPECT_TRUE(d.shapes[0].paths[0].closed) << "ends where it starts";
  EXPECT_EQ(d.shapes[0].paths[0].points.size(), 4u);
  EXPECT_TRUE(d.shapes[0].paths[1].closed);
  // After Z the pen is back at (20, 20).
  EXPECT_NEAR(d.shapes[0].paths[2].points.front().x, 20, 1e-9);
  EXPECT_NEAR(d.shapes[0].paths[2].points.back().y, 25, 1e-9);
}

TEST_F(SvgPathsTest, FilesWithoutNamespaceAndWithEditorExtrasAreRead) {
  SvgDrawing d = read(R"svg(<?xml version="1.0"?>
<svg width="20mm" height="20mm" viewBox="0 0 20 20" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape">
  <title>t</title><defs><rect id="hidden" width="5" height="5" stroke="black"/></defs>
  <inkscape:grid/><text x="1" y="1">words</text>
  <path d="M 1 1 L 5 5" stroke="black" paint-order="stroke" style="mix-blend-mode:normal"/>
</svg>)svg");
  ASSERT_EQ(d.shapes.size(), 1u);
  EXPECT_EQ(d.shapes[0].stroke, "#000000");
}

TEST_F(SvgPathsTest, MalformedFilesNameTheFileAndProblem) {
  try {
    read_svg(kSvgData / "malformed.svg", 0.05);
    FAIL() << "no error";
  } catch (const ConvertError& e) {
    EXPECT_THAT(e.what(), HasSubstr("malformed.svg: line "));
    EXPECT_THAT(e.what(), HasSubstr("not well-formed XML"));
  }
  try {
    read("<html><body>no drawing</body></html>");
    FAIL() << "no error";
  } catch (const ConvertError& e) {
    EXPECT_THAT(e.what(), HasSubstr("drawing.svg: not an SVG file"));
    EXPECT_THAT(e.what(), HasSubstr("<html>"));
  }
  try {
    read(R"svg(<svg xmlns="http://www.w3.org/2000/svg"><path d="M 0 0 L 10 K" stroke="black"/></svg>)svg");
    FAIL() << "no error";
  } catch (const ConvertError& e) {
    EXPECT_THAT(e.what(), HasSubstr("drawing.svg: "));
    EXPECT_THAT(e.what(), HasSubstr("\"d\""));
  }
  EXPECT_THROW(read_svg(dir_ / "missing.svg", 0.05), ConvertError);
  EXPECT_THROW(read(""), ConvertError);
}

TEST_F(SvgPathsTest, ToleranceControlsCurveDetail) {
  const std::string svg = R"svg(<svg xmlns="http://www.w3.org/2000/svg" width="100mm"
      height="100mm" viewBox="0 0 100 100"><circle cx="50" cy="50" r="40" stroke="black"/></svg>)svg";
  size_t coarse = read(svg, 0.5).shapes[0].paths[0].points.size();
  size_t fine = read(svg, 0.01).shapes[0].paths[0].points.size();
  EXPECT_LT(coarse * 3, fine);
  SvgDrawing fine_drawing = read(svg, 0.01);
  for (auto p : fine_drawing.shapes[0].paths[0].points)
    EXPECT_NEAR(std::hypot(p.x - 50, p.y - 50), 40, 0.011);
}

// Hostile drawings: each is refused with the file's name and the limit, in bounded time and
// memory (the converter's budget would otherwise end it with std::bad_alloc or a crash).
std::string refusal(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConvertError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST_F(SvgPathsTest, AMillionNestedGroupsAreRefusedNotAStackOverflow) {
  const std::string why = refusal([&] { read(testing::nested_groups(1000000)); });
  EXPECT_THAT(why, HasSubstr("drawing.svg: elements nested more than 256 deep (limit 256 levels)"));
  // Within the limit, nesting still works.
  EXPECT_EQ(read(testing::nested_groups(200)).shapes.size(), 1u);
}

TEST_F(SvgPathsTest, MoreElementsThanTheLimitAreRefused) {
  const std::string why = refusal([&] { read(testing::many_paths(100001)); });
  EXPECT_THAT(why, HasSubstr("drawing.svg: more than 100000 elements (limit 100000 per drawing)"));
}

TEST_F(SvgPathsTest, CurvesThatFlattenToMillionsOfPointsAreRefused) {
  // Eight circles of 400 km at 0.1 um: about 2 million points, over the limit of a million.
  const std::string why = refusal([&] { read(testing::point_bomb(8), 0.0001); });
  EXPECT_THAT(why, HasSubstr("drawing.svg: more than 1000000 points after flattening the curves"));
  EXPECT_THAT(why, HasSubstr("limit 1000000 points per drawing"));
}

TEST_F(SvgPathsTest, ScaleBombsAreRefusedBeforeFlattening) {
  // A 446-byte drawing whose transforms overflow to infinity: every tolerance test fails on
  // NaN, so each curve used to flatten to 2^24 points (3.7 GB for a handful of curves).
  const std::string inf = refusal([&] {
    read(R"svg(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
      <g transform="scale(1e200)"><g transform="scale(1e200)">
      <path d="M0 0 C 10 10 20 -10 30 0 C 40 10 50 -10 60 0" stroke="black"/></g></g></svg>)svg");
  });
  EXPECT_THAT(inf, HasSubstr("drawing.svg: a shape's coordinates are not finite numbers"));
  // Huge but finite: refused by the coordinate limit.
  const std::string far = refusal([&] {
    read(R"svg(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
      <circle transform="scale(1e9)" cx="50" cy="50" r="40" stroke="black"/></svg>)svg");
  });
  EXPECT_THAT(far, HasSubstr("drawing.svg: a shape reaches "));
  EXPECT_THAT(far, HasSubstr("(limit 1e+06 mm)"));
}

TEST_F(SvgPathsTest, ArcsWithNonFiniteOrDegenerateNumbersNeverReachTheArcCode) {
  // An infinite radius (1e999 parses as inf) is refused with the arc's numbers.
  const std::string why = refusal([&] {
    read(R"svg(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
      <path d="M 10 10 A 1e999 5 0 0 1 50 50" stroke="black"/></svg>)svg");
  });
  EXPECT_THAT(why, HasSubstr("drawing.svg: "));
  EXPECT_THAT(why, ::testing::AnyOf(HasSubstr("not finite"), HasSubstr("\"d\"")));
  // Radii too small or too large for the centre to be computed are the chord, as SVG says
  // of a zero radius; the drawing still reads and ends on the arc's end point.
  SvgDrawing d = read(R"svg(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
      <path d="M 10 10 A 1e-300 1e-300 0 0 1 50 50 A 0 5 0 0 1 60 50 A 1e300 1e300 0 0 1 70 60" stroke="black"/></svg>)svg");
  ASSERT_EQ(d.shapes.size(), 1u);
  const auto& pts = d.shapes[0].paths.at(0).points;
  for (const auto& p : pts) {
    EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y));
  }
  EXPECT_NEAR(pts.back().x, 70, 1e-6);
  EXPECT_NEAR(pts.back().y, 60, 1e-6);
  // An ordinary arc is unchanged: a half circle of radius 20 from (10,50) to (50,50).
  SvgDrawing half = read(R"svg(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
      <path d="M 10 50 A 20 20 0 0 1 50 50" stroke="black"/></svg>)svg", 0.01);
  for (const auto& p : half.shapes.at(0).paths.at(0).points)
    EXPECT_NEAR(std::hypot(p.x - 30, p.y - 50), 20, 0.02);
  EXPECT_NEAR(bounds_of(half.shapes[0].paths[0]).min_y, 30, 0.02);  // sweep 1: over the top
}

}  // namespace
}  // namespace atelier

// plan_job: the G-code a GRBL laser receives for known shapes (order, kerf, power, area).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "algorithms/laser/motion_planner.h"
#include "algorithms/laser/plan.h"
#include "tests/support/laser_test_shapes.h"

namespace atelier::laser {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;
using testing::layer;
using testing::lines_of;
using testing::square;
using testing::width_of;

size_t index_of(const std::vector<std::string>& lines, const std::string& prefix) {
  for (size_t i = 0; i < lines.size(); ++i)
    if (lines[i].rfind(prefix, 0) == 0) return i;
  return lines.size();
}

size_t count_prefix(const std::vector<std::string>& lines, const std::string& prefix) {
  return static_cast<size_t>(std::count_if(lines.begin(), lines.end(), [&](const std::string& l) {
    return l.rfind(prefix, 0) == 0;
  }));
}

TEST(LaserGcode, HeaderAndEnd) {
  Job job = plan_job({layer("black", Mode::cut, {square(10, 10, 20)})}, Machine{});
  auto lines = lines_of(job.gcode);
  ASSERT_GE(lines.size(), 6u);
  EXPECT_EQ(lines[0], "; atelier laser job");
  EXPECT_EQ(lines[1], "; s_max=1000");
  // front-left origin: Y = 400 - y, so the square spans Y 370..390.
  EXPECT_EQ(lines[2], "; bounds=10,370,30,390");
  EXPECT_EQ(lines[3], "G21 G90");
  EXPECT_EQ(lines.back(), "M5");
  for (const auto& l : lines) EXPECT_LE(l.size(), 70u) << l;
  EXPECT_DOUBLE_EQ(job.bounds.min_x, 10);
  EXPECT_DOUBLE_EQ(job.bounds.max_y, 390);
}

TEST(LaserGcode, ANonFinitePointIsRefusedNotPlanned) {
  for (double bad : {std::nan(""), std::numeric_limits<double>::infinity()}) {
    Path p = square(10, 10, 20);
    p.points[2].x = bad;
    try {
      plan_job({layer("black", Mode::engrave, {p})}, Machine{});
      FAIL() << "planned a path through " << bad;
    } catch (const PlanError& e) {
      EXPECT_THAT(e.what(), HasSubstr("layer 'black': a point is not a finite number"));
    }
  }
}

TEST(LaserGcode, InnerSquareIsCutBeforeTheSquareAroundIt) {
  Job job = plan_job({layer("c", Mode::cut, {square(10, 10, 50), square(30, 30, 10)})},
                     Machine{});
  ASSERT_EQ(job.toolpaths.size(), 1u);
  ASSERT_EQ(job.toolpaths[0].paths.size(), 2u);
  EXPECT_NEAR(width_of(job.toolpaths[0].paths[0]), 10, 1e-9);
  EXPECT_NEAR(width_of(job.toolpaths[0].paths[1]), 50, 1e-9);
  auto lines = lines_of(job.gcode);
  // The first travel goes to a corner of the inner square.
  size_t first_g0 = index_of(lines, "G0");
  ASSERT_LT(first_g0, lines.size());
  EXPECT_THAT(lines[first_g0], ::testing::AnyOf(HasSubstr("X30"), HasSubstr("X40")));
}

TEST(LaserGcode, EngraveLayersComeBeforeCutLayers) {
  Layer cut = layer("outline", Mode::cut, {square(0, 0, 40)});
  Layer engrave = layer("logo", Mode::engrave, {Path{{{5, 5}, {20, 5}}, false}});
  engrave.settings.speed_mm_min = 3000;
  engrave.settings.power_pct = 20;
  Job job = plan_job({cut, engrave}, Machine{});
  auto lines = lines_of(job.gcode);
  size_t e = index_of(lines, "; layer logo engrave 3000mm/min 20% x1");
  size_t c = index_of(lines, "; layer outline cut 600mm/min 80% x1");
  ASSERT_LT(e, lines.size());
  ASSERT_LT(c, lines.size());
  EXPECT_LT(e, c);
  ASSERT_EQ(job.layers.size(), 2u);
  EXPECT_EQ(job.layers[0].name, "logo");
  EXPECT_EQ(job.layers[1].name, "outline");
  EXPECT_EQ(lines[e + 1], "M4 S200");
  EXPECT_EQ(lines[c + 1], "M4 S800");
}

TEST(LaserGcode, KerfKeepsPiecesAtTheirDrawnSize) {
  Layer l = layer("c", Mode::cut, {square(10, 10, 20), square(15, 15, 10)});
  l.settings.kerf_mm = 0.2;
  Job job = plan_job({l}, Machine{});
  const auto& paths = job.toolpaths[0].paths;
  ASSERT_EQ(paths.size(), 2u);
  EXPECT_NEAR(width_of(paths[0]), 9.8, 0.002) << "the hole shrinks (cut first)";
  EXPECT_NEAR(width_of(paths[1]), 20.2, 0.002) << "the outer boundary grows";
  EXPECT_NEAR(job.bounds.min_x, 9.9, 0.002);
  // Engrave layers are never offset.
  Layer e = l;
  e.settings.mode = Mode::engrave;
  Job ejob = plan_job({e}, Machine{});
  EXPECT_NEAR(width_of(ejob.toolpaths[0].paths[1]), 20, 1e-9);
}

TEST(LaserGcode, AHoleOnAnotherCutLayerIsStillAHole) {
  // The outline is drawn in black (listed first), its hole in red: the hole's layer is cut
  // first and the hole shrinks, as it would on one layer.
  Layer outline = layer("black", Mode::cut, {square(10, 10, 20)});
  Layer holes = layer("red", Mode::cut, {square(15, 15, 10)});
  outline.settings.kerf_mm = holes.settings.kerf_mm = 0.2;
  Job job = plan_job({outline, holes}, Machine{});
  ASSERT_EQ(job.toolpaths.size(), 2u);
  EXPECT_EQ(job.toolpaths[0].settings.name, "red");
  EXPECT_NEAR(width_of(job.toolpaths[0].paths[0]), 9.8, 0.002) << "the hole shrinks";
  EXPECT_EQ(job.toolpaths[1].settings.name, "black");
  EXPECT_NEAR(width_of(job.toolpaths[1].paths[0]), 20.2, 0.002) << "the outline grows";
}

TEST(LaserGcode, VanishedHoleIsCounted) {
  Layer l = layer("c", Mode::cut, {square(10, 10, 20), square(15, 15, 0.3)});
  l.settings.kerf_mm = 0.5;
  Job job = plan_job({l}, Machine{});
  EXPECT_EQ(job.layers[0].paths, 1u);
  EXPECT_EQ(job.layers[0].vanished_holes, 1u);
}

TEST(LaserGcode, PowerIsScaledToSMax) {
  Layer l = layer("c", Mode::cut, {square(10, 10, 20)});
  l.settings.power_pct = 50;
  Machine grbl255;
  grbl255.s_max = 255;
  auto lines = lines_of(plan_job({l}, grbl255).gcode);
  EXPECT_EQ(lines[1], "; s_max=255");
  EXPECT_EQ(count_prefix(lines, "M4 S128"), 1u) << "round(0.5 * 255)";
  l.settings.power_pct = 80;
  lines = lines_of(plan_job({l}, Machine{}).gcode);
  EXPECT_EQ(count_prefix(lines, "M4 S800"), 1u);
  l.settings.power_pct = 100;
  lines = lines_of(plan_job({l}, grbl255).gcode);
  EXPECT_EQ(count_prefix(lines, "M4 S255"), 1u);
}

TEST(LaserGcode, TravelIsG0AndBurnsAreG1AfterM4) {
  Job job = plan_job({layer("c", Mode::cut, {square(10, 10, 20), square(100, 10, 20)}),
                      layer("e", Mode::engrave, {Path{{{50, 50}, {60, 60}}, false}})},
                     Machine{});
  auto lines = lines_of(job.gcode);
  bool beam_mode = false;  // M4 seen since the last M5
  size_t g0 = 0, g1 = 0;
  std::string previous_motion;
  for (const auto& l : lines) {
    if (l.rfind("M4", 0) == 0) beam_mode = true;
    if (l == "M5") beam_mode = false;
    if (l.rfind("G1", 0) == 0) {
      ++g1;
      EXPECT_TRUE(beam_mode) << "G1 without M4: " << l;
    }
    if (l.rfind("G0", 0) == 0) {
      ++g0;
      EXPECT_THAT(l, ::testing::Not(HasSubstr("S"))) << l;
      EXPECT_NE(previous_motion, "G0") << "two travels in a row";
    }
    if (l.rfind("G0", 0) == 0 || l.rfind("G1", 0) == 0) previous_motion = l.substr(0, 2);
  }
  EXPECT_EQ(g0, 3u) << "one travel per path";
  EXPECT_EQ(g1, 4u + 4u + 1u);
  EXPECT_EQ(lines.back(), "M5");
  EXPECT_EQ(count_prefix(lines, "M3"), 0u) << "constant power would burn at stops";
}

TEST(LaserGcode, FeedIsWrittenOnlyWhenItChanges) {
  Job job = plan_job({layer("c", Mode::cut, {square(10, 10, 20), square(100, 10, 20)})},
                     Machine{});
  size_t feeds = 0;
  for (const auto& l : lines_of(job.gcode))
    if (l.find(" F") != std::string::npos) ++feeds;
  EXPECT_EQ(feeds, 1u);
}

TEST(LaserGcode, OutsideTheWorkAreaThrows) {
  Layer l = layer("c", Mode::cut, {square(380, 10, 40)});
  try {
    plan_job({l}, Machine{});
    FAIL() << "no PlanError";
  } catch (const PlanError& e) {
    EXPECT_THAT(e.what(), HasSubstr("the job spans X 380..420 mm"));
    EXPECT_THAT(e.what(), HasSubstr("outside the 400 x 400 mm work area"));
  }
  // Kerf alone can push a shape drawn on the edge outside.
  Layer edge = layer("c", Mode::cut, {square(0, 0, 20)});
  EXPECT_NO_THROW(plan_job({edge}, Machine{}));
  edge.settings.kerf_mm = 0.2;
  EXPECT_THROW(plan_job({edge}, Machine{}), PlanError);
}

TEST(LaserGcode, NothingToBurnThrows) {
  EXPECT_THROW(plan_job({layer("c", Mode::cut, {})}, Machine{}), PlanError);
  EXPECT_THROW(plan_job({}, Machine{}), PlanError);
}

TEST(LaserGcode, PassesRepeatEachPath) {
  Layer l = layer("c", Mode::cut, {square(10, 10, 20), Path{{{50, 10}, {70, 10}}, false}});
  l.settings.passes = 3;
  Job job = plan_job({l}, Machine{});
  auto lines = lines_of(job.gcode);
  EXPECT_EQ(count_prefix(lines, "G1"), 3u * 4u + 3u);
  EXPECT_EQ(count_prefix(lines, "G0"), 2u) << "repeats need no travel";
  EXPECT_DOUBLE_EQ(job.layers[0].length_mm, 100);
  EXPECT_NEAR(job.cut_length_mm, 300, 1e-9);
  EXPECT_THAT(job.gcode, HasSubstr("; layer c cut 600mm/min 80% x3"));
}

TEST(LaserGcode, NearestNeighbourShortensTravel) {
  // A 6 x 6 grid of small squares in shuffled order.
  std::vector<Path> shapes;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) shapes.push_back(square(10 + 30 * i, 230 + 30 * j, 10));
  std::mt19937 rng(7);
  std::shuffle(shapes.begin(), shapes.end(), rng);
  Machine m;  // the head starts at bed (0, 0): design (0, 400), beside the grid's corner
  double input_order = 0;
  Point at{0, 400};
  for (const auto& s : shapes) {
    input_order += distance(at, s.points.front());
    at = s.points.front();
  }
  Job job = plan_job({layer("c", Mode::cut, shapes)}, m);
  EXPECT_LT(job.travel_length_mm, input_order / 2);
  EXPECT_LT(job.travel_length_mm, 1.1 * (35 * 30 + 14.2)) << "close to the grid walk";
  EXPECT_EQ(job.layers[0].paths, 36u);
}

// Contract A: the program is in bed coordinates (X from the left edge, Y from the front edge)
// whatever the machine's homing corner; the driver places the job at run time.
TEST(LaserGcode, BedCoordinatesMapDesignCoordinates) {
  Layer l = layer("c", Mode::cut, {square(10, 20, 5)});
  Machine m;
  m.width_mm = 300;
  m.height_mm = 200;
  auto lines = lines_of(plan_job({l}, m).gcode);
  EXPECT_EQ(lines[2], "; bounds=10,175,15,180");
  try {
    plan_job({layer("c", Mode::cut, {square(290, 20, 20)})}, m);
    FAIL() << "no PlanError";
  } catch (const PlanError& e) {
    EXPECT_THAT(e.what(), HasSubstr("X 290..310 mm"));
    EXPECT_THAT(e.what(), HasSubstr("(X 0..300, Y 0..200 in bed coordinates)"));
  }
}

TEST(LaserGcode, TimeEstimateFollowsGrblsPlannerNotLengthOverFeed) {
  Layer l = layer("c", Mode::cut, {Path{{{0, 300}, {10, 300}}, false}});
  l.settings.speed_mm_min = 600;
  Machine m;  // head at bed (0, 0) = design (0, 400): 100 mm of travel
  m.travel_mm_min = 6000;
  m.accel_mm_s2 = 500;
  Job job = plan_job({l}, m);
  EXPECT_NEAR(job.travel_length_mm, 100, 1e-9);
  // The travel from rest: 10 mm up to 100 mm/s and 10 mm down again take 0.4 s, 80 mm at speed
  // 0.8 s; the 90 degree corner into the burn is slow (junction deviation 0.01 mm), then 10 mm
  // at 10 mm/s. Length / feed would say 1.0 + 1.0 s.
  MotionSettings ms;
  ms.max_rate_mm_min = {6000, 6000, 500};
  ms.accel_mm_s2 = {500, 500, 100};
  std::vector<PlannedMove> moves(2);
  moves[0].target = {0, 100, 0};
  moves[0].rapid = true;
  moves[0].from_rest = true;
  moves[1].target = {10, 100, 0};
  moves[1].feed_mm_min = 600;
  const std::vector<double> s = move_seconds(moves, ms);
  EXPECT_NEAR(job.estimated_s, s[0] + s[1], 1e-9);
  EXPECT_NEAR(s[0], 1.2, 0.01);
  EXPECT_GT(job.estimated_s, 2.2);
  EXPECT_NEAR(job.layers[0].time_s, job.estimated_s, 1e-9);
}

TEST(LaserGcode, ShortMovesAndCornersMakeTheEstimateLongerThanLengthOverFeed) {
  // A zig-zag of 0.5 mm strokes at 3000 mm/min and GRBL's stock 10 mm/s^2: the head never
  // gets near its feed.
  std::vector<Point> zig;
  for (int i = 0; i <= 100; ++i) zig.push_back({50 + 0.5 * i, 200 + (i % 2) * 0.5});
  Layer l = layer("e", Mode::engrave, {Path{zig, false}});
  l.settings.speed_mm_min = 3000;
  Machine m;
  m.accel_mm_s2 = 10;
  const Job job = plan_job({l}, m);
  const double burn_by_feed = job.engrave_length_mm / 3000 * 60;
  const double travel_by_rate = job.travel_length_mm / m.travel_mm_min * 60;
  EXPECT_GT(job.estimated_s, 3 * (burn_by_feed + travel_by_rate)) << job.estimated_s;
}

TEST(LaserGcode, NumbersAreShort) {
  EXPECT_EQ(format_number(1.23456), "1.235");
  EXPECT_EQ(format_number(2.0), "2");
  EXPECT_EQ(format_number(-0.0001), "0");
  EXPECT_EQ(format_number(-12.5), "-12.5");
  EXPECT_EQ(format_number(400), "400");
  Layer l = layer("c", Mode::cut, {square(10.123456, 10, 3.3333333)});
  for (const auto& line : lines_of(plan_job({l}, Machine{}).gcode)) {
    EXPECT_THAT(line, ::testing::Not(HasSubstr("  "))) << line;
    EXPECT_THAT(line, ::testing::Not(::testing::ContainsRegex("\\.[0-9]{4}"))) << line;
  }
}

TEST(LaserGcode, LongLayerNamesKeepLinesShort) {
  Layer l = layer(std::string(200, 'n') + "\n", Mode::cut, {square(10, 10, 3)});
  for (const auto& line : lines_of(plan_job({l}, Machine{}).gcode)) EXPECT_LE(line.size(), 70u);
  EXPECT_THAT(plan_job({l}, Machine{}).gcode, HasSubstr("nnn cut 600mm/min 80% x1\n"));
}

// The program never holds a number GRBL could not read exactly or would cast out of range:
// at the largest settings the parameters allow (5000 mm bed, s_max and feeds of 100000,
// 50 passes), every word has at most 8 significant digits (GRBL's read_float keeps 8) and
// every G/M number is one of the few it writes (G0 G1 G21 G90, M0 M4 M5).
TEST(LaserGcode, EveryNumberFitsGrblsReader) {
  Machine m;
  m.width_mm = m.height_mm = 5000;
  m.s_max = 100000;
  Layer l = layer("cut", Mode::cut, {square(0.0004, 0.0004, 4999.999), Path{{{1234.5678, 4321.8765}, {2.5, 4999.9999}}, false}});
  l.settings.speed_mm_min = 100000;
  l.settings.power_pct = 100;
  l.settings.passes = 50;
  const Job job = plan_job({l}, m);
  for (const std::string& line : lines_of(job.gcode)) {
    if (line.empty() || line[0] == ';') continue;
    for (size_t i = 0; i < line.size();) {
      if (line[i] == ' ') { ++i; continue; }
      const char letter = line[i++];
      size_t end = i;
      int digits = 0;
      while (end < line.size() && line[end] != ' ') digits += std::isdigit(static_cast<unsigned char>(line[end++])) != 0;
      const double value = std::stod(line.substr(i, end - i));
      EXPECT_LE(digits, 8) << line;
      if (letter == 'G') EXPECT_TRUE(value == 0 || value == 1 || value == 21 || value == 90) << line;
      if (letter == 'M') EXPECT_TRUE(value == 0 || value == 4 || value == 5) << line;
      i = end;
    }
  }
}

}  // namespace
}  // namespace atelier::laser

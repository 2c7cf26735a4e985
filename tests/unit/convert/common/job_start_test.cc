// A knitting job's own start keys (convert/common/job_start.h): the bed's needle names, and the
// keys taken out of a sidecar before the conversion's strict reader sees them.
#include <gtest/gtest.h>

#include "convert/common/job_start.h"
#include "convert/common/laser_params.h"
#include "convert/common/param_table.h"

namespace atelier {
namespace {

toml::table parse(const std::string& text, const std::string& source) {
  return toml::parse(std::string_view(text), std::string_view(source));
}

TEST(JobStartNeedles, TheBedsMarkingsAndCountsFromTheLeftEnd) {
  // KH-930: L100 is the leftmost needle, L1 and R1 either side of the centre, R100 the rightmost.
  EXPECT_EQ(parse_bed_needle("L100", 200), 0);
  EXPECT_EQ(parse_bed_needle("L1", 200), 99);
  EXPECT_EQ(parse_bed_needle("R1", 200), 100);
  EXPECT_EQ(parse_bed_needle("r100", 200), 199);
  EXPECT_EQ(parse_bed_needle("1", 200), 0);
  EXPECT_EQ(parse_bed_needle("200", 200), 199);
  // KH-270: L56..R56.
  EXPECT_EQ(parse_bed_needle("L56", 112), 0);
  EXPECT_EQ(parse_bed_needle("R56", 112), 111);
  for (const char* bad : {"", "L", "R0", "L57", "0", "113", "L-3", "20x", "L 20", "R12345"}) {
    std::string problem;
    EXPECT_FALSE(parse_bed_needle(bad, 112, &problem)) << bad;
    EXPECT_EQ(problem, "needles are named by the bed's markings L56..L1, R1..R56 or counted from the left end, 1..112");
  }
  for (int i = 0; i < 200; ++i) EXPECT_EQ(parse_bed_needle(bed_needle_name(i, 200), 200), i);
  EXPECT_EQ(bed_needle_name(99, 200), "L1");
  EXPECT_EQ(bed_needle_name(100, 200), "R1");
}

TEST(JobStartKeys, AreTakenOutOfTheSidecarAndTheRestIsLeftForTheConversion) {
  toml::table t = parse("width = 60\nautostart = true\nstart_row = 5\nstart_needle = \"L20\"\n", "cat.png.toml");
  const JobStart s = take_job_start(t, "cat.png.toml");
  EXPECT_EQ(s.autostart, true);
  EXPECT_EQ(s.start_row, 5);
  EXPECT_EQ(s.start_needle, "L20");
  EXPECT_EQ(t.size(), 1u);
  EXPECT_TRUE(t.contains("width"));

  toml::table counted = parse("start_needle = 30\n", "a.toml");
  EXPECT_EQ(take_job_start(counted, "a.toml").start_needle, "30");
  toml::table none = parse("width = 60\n", "b.toml");
  const JobStart empty = take_job_start(none, "b.toml");
  EXPECT_FALSE(empty.autostart || empty.start_row || empty.start_needle);
}

TEST(JobStartKeys, BadValuesNameTheFileLineAndKey) {
  auto error = [](const std::string& text) -> std::string {
    toml::table t = parse(text, "cat.png.toml");
    try {
      take_job_start(t, "cat.png.toml");
    } catch (const ParamError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(error("width = 1\nstart_row = 0\n"), "cat.png.toml:2: key 'start_row': rows are counted from 1 (the first row knitted)");
  EXPECT_EQ(error("start_row = \"5\"\n"), "cat.png.toml:1: key 'start_row': expected a row number (1 is the first row knitted)");
  EXPECT_EQ(error("autostart = \"yes\"\n"), "cat.png.toml:1: key 'autostart': expected true or false");
  EXPECT_EQ(error("start_needle = \"M3\"\n"),
            "cat.png.toml:1: key 'start_needle': 'M3' is no needle: needles are named by the bed's markings "
            "L100..L1, R1..R100 or counted from the left end, 1..200");
  EXPECT_EQ(error("start_needle = 1.5\n"), "cat.png.toml:1: key 'start_needle': expected a needle such as \"L20\", \"R5\" or 30");
}

TEST(LaserJobStartKeys, CheckFirstAndStartFromAreTheDaemonsAndTheRestIsLeftForTheConversion) {
  toml::table t = parse("[laser]\ncheck_first = true\nstart_from = \"here\"\ntolerance_mm = 0.05\n", "box.svg.toml");
  const LaserJobStart s = take_laser_job_start(t, "box.svg.toml");
  EXPECT_EQ(s.check_first, true);
  EXPECT_EQ(s.start_from, "here");
  ASSERT_TRUE(t["laser"].as_table());
  EXPECT_EQ(t["laser"].as_table()->size(), 1u);  // tolerance_mm: the conversion's
  toml::table none = parse("[cut]\nkerf_mm = 0.1\n", "b.svg.toml");
  const LaserJobStart empty = take_laser_job_start(none, "b.svg.toml");
  EXPECT_FALSE(empty.check_first || empty.start_from);
}

TEST(LaserJobStartKeys, BadValuesNameTheFileLineAndKey) {
  auto error = [](const std::string& text) -> std::string {
    toml::table t = parse(text, "box.svg.toml");
    try {
      take_laser_job_start(t, "box.svg.toml");
    } catch (const ParamError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(error("[laser]\ncheck_first = 1\n"), "box.svg.toml:2: key 'laser.check_first': expected true or false");
  EXPECT_EQ(error("[laser]\n\nstart_from = \"corner\"\n"),
            "box.svg.toml:3: key 'laser.start_from': expected \"bed\" (the bed's front-left corner), \"origin\" "
            "(the work zero set with `atelierctl laser origin`) or \"here\" (the head's position at start)");
}

TEST(LaserJobStartKeys, AnUnknownLaserKeyInASidecarIsRefusedWithTheFileAndKey) {
  // What the conversion does with what take_laser_job_start leaves: nothing is silently ignored.
  toml::table t = parse("[laser]\nstart_from = \"bed\"\ncheck_frist = true\n", "box.svg.toml");
  take_laser_job_start(t, "box.svg.toml");
  try {
    read_laser_params(*t["laser"].as_table(), "box.svg.toml");
    ADD_FAILURE() << "an unknown key was accepted";
  } catch (const ParamError& e) {
    EXPECT_NE(std::string(e.what()).find("box.svg.toml:3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("check_frist"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace atelier

// Reading chart.json (convert/lace/lace_chart_json.h): numbers outside their range are refused,
// not wrapped.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "convert/lace/lace_chart_json.h"

namespace atelier {
namespace {

using ::testing::HasSubstr;

TEST(LaceChartJson, NumbersOutsideTheirRangeAreRefusedNotWrapped) {
  auto error_of = [](const std::string& text) -> std::string {
    try {
      lace_chart_from_json(nlohmann::json::parse(text), "c.json");
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  const std::string rows = R"("rows": [["k", "k", "k", "k"]])";
  // 2^32 + 4 was read as 4 stitches, and the chart taken as fine.
  EXPECT_THAT(error_of("{" + rows + R"(, "cast_on": 4294967300})"), HasSubstr("c.json: cast_on must be"));
  EXPECT_THAT(error_of("{" + rows + R"(, "cast_on": -4})"), HasSubstr("cast_on must be"));
  EXPECT_THAT(error_of("{" + rows + R"(, "repeats_wide": 4294967297})"), HasSubstr("c.json: repeats_wide must be"));
  EXPECT_THAT(error_of("{" + rows + R"(, "repeats_high": 51})"), HasSubstr("repeats_high must be"));
  EXPECT_THAT(error_of("{" + rows + R"(, "repeats_high": 2.5})"), HasSubstr("repeats_high must be"));
  const LaceChartFile ok = lace_chart_from_json(
      nlohmann::json::parse("{" + rows + R"(, "cast_on": 4, "repeats_wide": 50, "repeats_high": 1})"), "c.json");
  EXPECT_EQ(ok.cast_on, 4);
  EXPECT_EQ(ok.repeats_wide, 50);
}

}  // namespace
}  // namespace atelier

namespace atelier {
namespace {

// chart.json carries the printed layout (issue 22, lace point 1): every row as wide as the
// others, null for a "no stitch" cell, the yarn-overs of row 3 over row 1's no-stitch cells;
// "rows" stay as they were and the file reads back to the same chart.
TEST(LaceChartJson, LayoutIsWrittenBesideTheRowsAndOldFilesStillRead) {
  LaceChartFile f;
  f.chart = lace::Chart{{{lace::Symbol::k, lace::Symbol::k2tog, lace::Symbol::k, lace::Symbol::k2tog, lace::Symbol::k},
                         {lace::Symbol::k, lace::Symbol::yo, lace::Symbol::k, lace::Symbol::k, lace::Symbol::yo,
                          lace::Symbol::k, lace::Symbol::k}}};
  f.cast_on = 7;
  const nlohmann::json j = lace_chart_to_json(f);
  ASSERT_TRUE(j.contains("layout"));
  EXPECT_EQ(j["layout"]["columns"], 7);
  EXPECT_EQ(j["layout"]["rows"][0], nlohmann::json::parse(R"(["k", null, "k2tog", "k", null, "k2tog", "k"])"));
  EXPECT_EQ(j["layout"]["rows"][1], nlohmann::json::parse(R"(["k", "yo", "k", "k", "yo", "k", "k"])"));
  EXPECT_EQ(j["rows"][0], nlohmann::json::parse(R"(["k", "k2tog", "k", "k2tog", "k"])"));
  const LaceChartFile back = lace_chart_from_json(j, "c.json");
  EXPECT_EQ(back.chart, f.chart);
  EXPECT_EQ(back.cast_on, 7);
  // A file written before the layout existed reads the same.
  nlohmann::json old = j;
  old.erase("layout");
  EXPECT_EQ(lace_chart_from_json(old, "old.json").chart, f.chart);
}

}  // namespace
}  // namespace atelier

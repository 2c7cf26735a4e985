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

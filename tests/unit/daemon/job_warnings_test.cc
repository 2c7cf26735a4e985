// The warnings path: report.json "warnings" -> show's JSON -> atelierctl show.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "daemon/job_json.h"
#include "tools/ctl_format.h"

namespace atelier {
namespace {

TEST(JobWarnings, TheReportsWarningsAreRead) {
  EXPECT_EQ(report_warnings(nlohmann::json::parse(R"({"warnings":["a","b"]})")),
            (std::vector<std::string>{"a", "b"}));
  EXPECT_TRUE(report_warnings(nlohmann::json::parse(R"({"warnings":[]})")).empty());
  EXPECT_TRUE(report_warnings(nlohmann::json::parse(R"({"kind":"knit"})")).empty());
  EXPECT_TRUE(report_warnings(nlohmann::json::parse("[1]")).empty());
  EXPECT_TRUE(report_warnings(nlohmann::json::parse(R"({"warnings":"a"})")).empty());
}

TEST(JobWarnings, TheConvertedReasonCarriesTheFirstAndCountsTheRest) {
  EXPECT_EQ(converted_reason("converted; waiting for knitter", {}), "converted; waiting for knitter");
  EXPECT_EQ(converted_reason("converted; waiting for knitter", {"not knittable as is: floats up to 9"}),
            "converted; waiting for knitter; warning: not knittable as is: floats up to 9");
  EXPECT_EQ(converted_reason("converted", {"a", "b", "c"}), "converted; warning: a (and 2 more: atelierctl show)");
}

TEST(JobWarnings, ShowPrintsEachWarningOnItsOwnLine) {
  const nlohmann::json job = {{"id", 4},
                              {"kind", "lace"},
                              {"name", "fruits.jpg"},
                              {"state", "ready"},
                              {"warnings", {"this chart needs a V-bed", "not knittable as is: floats up to 9"}},
                              {"outputs", {"chart.json"}}};
  const std::string out = ctl::format_job_details(job);
  EXPECT_NE(out.find("\nwarnings:\n  this chart needs a V-bed\n  not knittable as is: floats up to 9\n"),
            std::string::npos)
      << out;
  EXPECT_EQ(out.find("[\""), std::string::npos) << "not a JSON dump: " << out;
}

}  // namespace
}  // namespace atelier

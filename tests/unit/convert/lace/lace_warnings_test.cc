// A lace chart the Brother lace carriage cannot make is said at conversion, in
// report.json's warnings (which the daemon puts in the job's reason and atelierctl show).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <toml++/toml.h>

#include "convert/convert.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;

class LaceWarnings : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("atelier-lace-warnings-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  nlohmann::json run(const std::string& toml_text) {
    std::ofstream(dir_ / "swatch.toml") << toml_text;
    ConvertRequest req;
    req.kind = "lace";
    req.input = dir_ / "swatch.toml";
    req.params = toml::parse(toml_text, std::string_view{(dir_ / "swatch.toml").string()});
    req.params_source = (dir_ / "swatch.toml").string();
    req.output_dir = dir_ / "out";
    convert(req);
    std::ifstream in(dir_ / "out" / "report.json");
    return nlohmann::json::parse(in);
  }
  fs::path dir_;
};

TEST_F(LaceWarnings, AChartTheLaceCarriageCannotMakeIsSaid) {
  // A yarn-over right of a k2tog: the carriage's transfer would land on the empty needle.
  const nlohmann::json r = run("generations = 0\npopulation = 10\nstart_chart = [\"k1, yo, k2tog, k1\", \"k4\"]\n");
  ASSERT_FALSE(r["machine"]["lace_carriage"].get<bool>());
  ASSERT_EQ(r["warnings"].size(), 1u) << r["warnings"];
  EXPECT_EQ(r["warnings"][0].get<std::string>(),
            "this chart needs a V-bed / hand transfers: 1 of 2 chart rows the lace carriage cannot make; use "
            "lace_carriage = true for the Brother lace carriage");
}

TEST_F(LaceWarnings, AChartTheLaceCarriageMakesHasNoWarning) {
  const nlohmann::json r = run("generations = 0\npopulation = 10\nstart_chart = [\"k4\", \"k4\"]\n");
  ASSERT_TRUE(r["machine"]["lace_carriage"].get<bool>());
  EXPECT_TRUE(r["warnings"].empty()) << r["warnings"];
}

}  // namespace
}  // namespace atelier

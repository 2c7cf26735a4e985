// convert() for kind lace: a job's parameters become chart.json, chart.svg, chart.pdf,
// instructions.txt, lace.k, preview.png and report.json; variations of a start chart; bad
// parameters and start charts are clear errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "algorithms/lace/hole_lines.h"
#include "algorithms/lace/instructions.h"
#include "convert/common/param_table.h"
#include "convert/convert.h"
#include "convert/lace/lace_chart_json.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Small and quick: the algorithm's own tests cover the evolution at full size.
const std::string kQuick = "population = 60\ngenerations = 15\nwidth = 8\nrows = 6\n";

class ConvertLaceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("atelier-convert-lace-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  enum class Params { parsed, merged };
  // The job file swatch.toml holding `toml_text`, converted into `out`. Params::parsed hands
  // the parsed table over as it is; Params::merged does what atelier-convert (and so the
  // daemon) does, merging it into the parameters, whose copied nodes forget their file and line.
  ConvertResult run(const std::string& toml_text, const std::string& out = "out", Params how = Params::parsed) {
    std::ofstream(dir_ / "swatch.toml") << toml_text;  // relative paths follow the job file
    ConvertRequest req;
    req.kind = "lace";
    req.input = dir_ / "swatch.toml";
    toml::table parsed = toml::parse(toml_text, std::string_view{(dir_ / "swatch.toml").string()});
    if (how == Params::merged) {
      merge_into(req.params, parsed);
      req.params_source = "parameters";
    } else {
      req.params = std::move(parsed);  // moved: a copy would forget the source
      req.params_source = (dir_ / "swatch.toml").string();
    }
    req.output_dir = dir_ / out;
    return convert(req);
  }
  ConvertResult run_merged(const std::string& toml_text) { return run(toml_text, "out", Params::merged); }
  std::string error_of(const std::string& toml_text, Params how = Params::parsed) {
    try {
      run(toml_text, "out", how);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "";
  }
  std::string merged_error_of(const std::string& toml_text) { return error_of(toml_text, Params::merged); }
  LaceChartFile chart_of(const std::string& out = "out") {
    return lace_chart_from_json(nlohmann::json::parse(slurp(dir_ / out / "chart.json")), "chart.json");
  }
  fs::path dir_;
};

TEST_F(ConvertLaceTest, AJobWritesEveryOutputAndItsChartKeepsThePapersConstraints) {
  const ConvertResult result = run(kQuick + "seed = 5\n");
  for (const char* f : {"chart.json", "chart.svg", "chart.pdf", "instructions.txt", "lace.k",
                        "preview.png", "report.json"})
    EXPECT_TRUE(fs::exists(dir_ / "out" / f)) << f;

  const LaceChartFile file = chart_of();
  EXPECT_EQ(file.cast_on, 8);
  EXPECT_EQ(file.chart.rows.size(), 6u);
  EXPECT_EQ(file.repeats_wide, 3);
  EXPECT_TRUE(lace::knittable(file.chart, 8));
  EXPECT_TRUE(lace::yarn_over_balance(file.chart));
  EXPECT_TRUE(lace::adjacent_yarn_overs_ok(file.chart, true));
  EXPECT_TRUE(lace::width_ok(file.chart, 2));

  // The written instructions are the same chart.
  const lace::ParsedInstructions parsed = lace::parse_instructions(slurp(dir_ / "out" / "instructions.txt"));
  EXPECT_EQ(parsed.chart, file.chart);
  EXPECT_EQ(parsed.cast_on, 8);
  EXPECT_THAT(slurp(dir_ / "out" / "instructions.txt"), HasSubstr("Row 1 (RS):"));

  EXPECT_EQ(slurp(dir_ / "out" / "chart.pdf").substr(0, 4), "%PDF");
  EXPECT_THAT(slurp(dir_ / "out" / "chart.svg"), HasSubstr("<svg"));
  EXPECT_EQ(slurp(dir_ / "out" / "lace.k").rfind(";!knitout-2", 0), 0u);
  const cv::Mat preview = cv::imread((dir_ / "out" / "preview.png").string());
  ASSERT_FALSE(preview.empty());
  EXPECT_GT(preview.cols, 3 * 8 * 4) << "three repeats of eight stitches";

  const nlohmann::json& r = result.report;
  EXPECT_EQ(r, nlohmann::json::parse(slurp(dir_ / "out" / "report.json")));
  EXPECT_TRUE(r["constraints"]["all_satisfied"].get<bool>());
  EXPECT_TRUE(r["constraints"]["knittable"].get<bool>());
  EXPECT_EQ(r["generations"], 15);
  EXPECT_EQ(r["best_score"].size(), 16u) << "generation 0 and each of the 15";
  EXPECT_EQ(r["stitches"]["yo"].get<int>(),
            r["stitches"]["k2tog"].get<int>() + r["stitches"]["ssk"].get<int>() +
                2 * (r["stitches"]["sk2p"].get<int>() + r["stitches"]["s2kp"].get<int>()));
  for (const char* term : {"holes", "knit_length", "depth", "symmetry", "score"})
    EXPECT_TRUE(r["fitness"].contains(term)) << term;
  EXPECT_TRUE(r["machine"].contains("problems"));
}

TEST_F(ConvertLaceTest, TheSameParametersGiveTheSameChartAndAnotherSeedAnother) {
  run(kQuick + "seed = 7\n", "a");
  run(kQuick + "seed = 7\n", "b");
  EXPECT_EQ(slurp(dir_ / "a" / "chart.json"), slurp(dir_ / "b" / "chart.json"));
  bool differs = false;
  for (int seed = 8; seed < 12 && !differs; ++seed) {
    run(kQuick + "seed = " + std::to_string(seed) + "\n", "c");
    differs = slurp(dir_ / "c" / "chart.json") != slurp(dir_ / "a" / "chart.json");
  }
  EXPECT_TRUE(differs);
}

TEST_F(ConvertLaceTest, AStartChartWithNoGenerationsComesBackAsItWas) {
  // Inline rows, written as a knitter writes them: a cat's-paw-like eyelet motif, 7 stitches.
  run("generations = 0\npopulation = 10\nstart_chart = [\"k1, k2tog, yo, k1, yo, ssk, k1\", "
      "\"k7\", \"k2tog, yo, k3, yo, ssk\", \"k7\"]\n");
  const LaceChartFile inline_chart = chart_of();
  EXPECT_EQ(inline_chart.cast_on, 7);
  ASSERT_EQ(inline_chart.chart.rows.size(), 4u);
  EXPECT_EQ(inline_chart.chart.rows[2].front(), lace::Symbol::k2tog);

  // The same chart from the job's own instructions.txt and chart.json, relative to the job file.
  fs::rename(dir_ / "out", dir_ / "first");
  run("generations = 0\npopulation = 10\nstart_chart = \"first/instructions.txt\"\n");
  EXPECT_EQ(chart_of().chart, inline_chart.chart);
  fs::remove_all(dir_ / "out");
  run("generations = 0\npopulation = 10\nstart_chart = \"first/chart.json\"\n");
  EXPECT_EQ(chart_of().chart, inline_chart.chart);

  // With generations, variations keep the start chart's width and rows.
  fs::remove_all(dir_ / "out");
  run("generations = 10\npopulation = 40\nstart_chart = \"first/chart.json\"\n");
  const LaceChartFile varied = chart_of();
  EXPECT_EQ(varied.cast_on, 7);
  EXPECT_EQ(varied.chart.rows.size(), 4u);
  EXPECT_TRUE(lace::yarn_over_balance(varied.chart));
}

TEST_F(ConvertLaceTest, BadParametersAndStartChartsAreClearErrors) {
  EXPECT_THAT(error_of("widht = 10\n"), HasSubstr("widht"));
  EXPECT_THAT(error_of("width = 1\n"), HasSubstr("width"));
  EXPECT_THAT(error_of("kind = \"knit\"\n"), HasSubstr("kind"));
  EXPECT_THAT(error_of("start_chart = \"nowhere.json\"\n"), HasSubstr("nowhere.json"));
  EXPECT_THAT(error_of("start_chart = [\"k2, k3tog, yo\"]\n"), HasSubstr("k3tog"));
  // A start chart that cannot be knitted: row 2 is worked over 3 stitches, row 1 made 2.
  EXPECT_THAT(error_of("start_chart = [\"k2\", \"k3\"]\n"), HasSubstr("row"));
  std::ofstream(dir_ / "bad.json") << "{\"rows\": [[\"k\", \"zz\"]]}";
  EXPECT_THAT(error_of("start_chart = \"bad.json\"\n"), HasSubstr("bad.json"));
  EXPECT_FALSE(fs::exists(dir_ / "out" / "chart.json"));
}

TEST_F(ConvertLaceTest, WithTheLaceCarriageOnEveryChartIsOneTheCarriageCanKnit) {
  for (int seed : {1, 2, 3}) {
    const ConvertResult result = run(kQuick + "lace_carriage = true\nseed = " + std::to_string(seed) + "\n");
    const nlohmann::json& m = result.report["machine"];
    EXPECT_TRUE(m["lace_carriage"].get<bool>()) << m.dump();
    EXPECT_TRUE(m["problems"].empty()) << m.dump();
    EXPECT_GT(m["knit_passes"].get<int>(), 0);
    // Not just plain knitting: the first generation pairs yarn-overs as the carriage can.
    EXPECT_GE(result.report["stitches"]["yo"].get<int>(), 6) << result.report["stitches"].dump();
    EXPECT_GT(m["lace_passes"].get<int>(), 0);
    for (const lace::Row& row : chart_of().chart.rows) EXPECT_EQ(lace::produced(row), 8);
  }
}

TEST_F(ConvertLaceTest, APopulationOfTwoEvolves) {
  // The parameters allow population = 2; the tournament and elites must fit inside it.
  const ConvertResult result = run("population = 2\ngenerations = 3\nwidth = 6\nrows = 4\n");
  EXPECT_EQ(result.report["generations"], 3);
  EXPECT_TRUE(lace::knittable(chart_of().chart, 6));
}

TEST_F(ConvertLaceTest, StartChartErrorsNameTheJobFileLineAndKey) {
  const std::string job = (dir_ / "swatch.toml").string();
  EXPECT_EQ(merged_error_of("population = 4\nstart_chart = \"nowhere.json\"\n"),
            job + ":2: key 'start_chart': " + (dir_ / "nowhere.json").string() + ": no such file");
  fs::create_directories(dir_ / "charts");
  EXPECT_EQ(merged_error_of("start_chart = \"charts\"\n"),
            job + ":1: key 'start_chart': " + (dir_ / "charts").string() +
                ": a folder, not a chart file (chart.json or instructions.txt)");
  EXPECT_THAT(merged_error_of("start_chart = [\"k1\"]\n"),
              HasSubstr(":1: key 'start_chart': inline rows: the chart is worked over 1 stitches"));
  EXPECT_THAT(merged_error_of("start_chart = [\"k2, yo\"]\n"),
              HasSubstr(":1: key 'start_chart': inline rows: the chart ends 3 stitches wide but starts from 2"));
  std::string tall;
  for (int r = 0; r < 201; ++r) tall += std::string(r ? ", " : "") + "\"k4\"";
  EXPECT_THAT(merged_error_of("start_chart = [" + tall + "]\n"), HasSubstr("201 right-side rows"));
  EXPECT_THAT(merged_error_of("start_chart = [\"k4\\nCast on a multiple of 2 stitches\", \"k4\"]\n"),
              HasSubstr(":1: key 'start_chart': inline rows: row 1 holds a line break"));
  EXPECT_FALSE(fs::exists(dir_ / "out" / "chart.json"));

  // A relative start chart is found beside the job file, not in the working directory.
  std::ofstream(dir_ / "charts" / "eyelet.json") << R"({"rows": [["k", "yo", "k2tog", "k"], ["k", "k", "k", "k"]]})";
  run_merged("generations = 0\npopulation = 4\nstart_chart = \"charts/eyelet.json\"\n");
  EXPECT_EQ(chart_of().cast_on, 4);
}

TEST_F(ConvertLaceTest, AnInfeasibleStartChartWithNoGenerationsSaysWhatItBreaks) {
  // evolve() only said "no chart satisfied the constraints", naming neither file nor key.
  const std::string job = (dir_ / "swatch.toml").string();
  EXPECT_EQ(merged_error_of("generations = 0\nstart_chart = [\"yo, yo, yo, sk2p, k2tog\"]\n"),
            job + ":2: key 'start_chart': inline rows: with generations = 0 the result is this chart, but it "
                  "breaks the constraints: more than two yarn-overs side by side");
  EXPECT_THAT(merged_error_of("generations = 0\nwidth_tolerance = 0\nstart_chart = [\"yo, k4\", \"k2tog, k3\"]\n"),
              HasSubstr("breaks the constraints: a row wider or narrower than width_tolerance = 0 allows"));
  EXPECT_THAT(merged_error_of("generations = 0\nlace_carriage = true\nstart_chart = [\"k1, yo, k2tog, k1\"]\n"),
              HasSubstr(":3: key 'start_chart': inline rows: with generations = 0 the result is this chart, but "
                        "it breaks the constraints: the lace carriage cannot knit it (row 1 (RS), stitch 3 (k2tog)"));
  EXPECT_FALSE(fs::exists(dir_ / "out" / "chart.json"));

  // As in the evolution, a swatch wider than the machine's bed is reported, not refused.
  const ConvertResult wide = run_merged("generations = 0\nlace_carriage = true\nrepeats_wide = 50\n"
                                        "start_chart = [\"k1, k2tog, yo, k2\"]\n");
  EXPECT_FALSE(wide.report["machine"]["lace_carriage"].get<bool>());
  EXPECT_THAT(wide.report["machine"]["problems"][0].get<std::string>(), HasSubstr("250 stitches wide"));
}

TEST_F(ConvertLaceTest, TheReportListsTheFirstHundredCarriageProblemsAndCountsThemAll) {
  // One problem per row (a yarn-over before a k2tog); a 200 x 200 chart listed thousands.
  std::string rows;
  for (int r = 0; r < 120; ++r) rows += std::string(r ? ", " : "") + "\"k1, yo, k2tog, k1\"";
  const ConvertResult result = run("generations = 0\npopulation = 2\nstart_chart = [" + rows + "]\n");
  const nlohmann::json& m = result.report["machine"];
  EXPECT_FALSE(m["lace_carriage"].get<bool>());
  EXPECT_EQ(m["problems"].size(), 100u);
  EXPECT_EQ(m["problems_total"], 120);
  EXPECT_THAT(m["problems"][0].get<std::string>(), HasSubstr("row 1 (RS), stitch 3 (k2tog)"));
}

TEST_F(ConvertLaceTest, JobsTooBigForMemoryOrTimeAreRefusedByKey) {
  const std::string job = (dir_ / "swatch.toml").string();
  // ~100 GB of forests, and 10^10 niche comparisons per generation.
  EXPECT_THAT(merged_error_of("width = 200\nrows = 200\npopulation = 100000\n"),
              HasSubstr(job + ":3: key 'population': population 100000 of a 200 x 200 chart"));
  EXPECT_THAT(merged_error_of("population = 100000\ngenerations = 10\n"),
              HasSubstr(job + ":1: key 'population': population 100000 for 10 generations"));
  EXPECT_THAT(merged_error_of("width = 200\nrows = 200\ngenerations = 100000\n"),
              HasSubstr(job + ":3: key 'generations': 100000 generations x population 500"));
  // A 10000 x 10000 stitch swatch: gigabytes of lace.k.
  EXPECT_THAT(merged_error_of("width = 200\nrows = 200\nrepeats_wide = 50\nrepeats_high = 50\n"),
              HasSubstr(job + ":4: key 'repeats_high': the swatch (50 x 50 repeats of a 200 x 200 chart)"));
  EXPECT_FALSE(fs::exists(dir_ / "out" / "chart.json"));
}

TEST_F(ConvertLaceTest, AWideSwatchGetsAPreviewOfBoundedSize) {
  // 50 repeats of 200 stitches at 14 px would be 140000 px wide.
  const ConvertResult result =
      run("population = 6\ngenerations = 1\nwidth = 200\nrows = 1\nrepeats_wide = 50\nrepeats_high = 1\n");
  const cv::Mat preview = cv::imread((dir_ / "out" / "preview.png").string());
  ASSERT_FALSE(preview.empty());
  EXPECT_LE(preview.cols, 4096);
  EXPECT_LE(preview.rows, 4096);
  const nlohmann::json& shown = result.report["preview"];
  EXPECT_EQ(preview.cols, 200 * shown["repeats_wide"].get<int>() * shown["stitch_px"].get<int>());
  EXPECT_EQ(shown["repeats_wide"], 5) << "as many repeats as fit at the smallest stitches";
  EXPECT_EQ(chart_of().repeats_wide, 50) << "the job still knits the whole swatch";

  // Smaller stitches come first: 50 repeats of 8 fit at 10 px.
  const ConvertResult narrow =
      run("population = 6\ngenerations = 1\nwidth = 8\nrows = 1\nrepeats_wide = 50\nrepeats_high = 1\n", "narrow");
  EXPECT_EQ(narrow.report["preview"]["repeats_wide"], 50);
  EXPECT_EQ(narrow.report["preview"]["stitch_px"], 10);
  EXPECT_EQ(cv::imread((dir_ / "narrow" / "preview.png").string()).cols, 4000);

  // A big chart 3 x 3 would draw 54000 stitches (rows and their purl rows): 2 x 3 is 36000.
  const ConvertResult big = run("population = 4\ngenerations = 1\nwidth = 60\nrows = 50\n", "big");
  EXPECT_EQ(big.report["preview"]["repeats_wide"], 2);
  EXPECT_EQ(big.report["preview"]["repeats_high"], 3);
  EXPECT_EQ(cv::imread((dir_ / "big" / "preview.png").string()).cols,
            120 * big.report["preview"]["stitch_px"].get<int>());
}

TEST_F(ConvertLaceTest, ReportSaysWhetherTheChartReadsAsADesign) {
  // The defaults' band and lines at a quicker size: the design block holds the chart's figures.
  run("kind = \"lace\"\npopulation = 200\ngenerations = 80\nseed = 2\n");
  const nlohmann::json r = nlohmann::json::parse(slurp(dir_ / "out" / "report.json"));
  ASSERT_TRUE(r.contains("design"));
  const nlohmann::json& d = r["design"];
  const lace::Chart chart = chart_of().chart;
  const lace::HoleLines h = lace::hole_lines(chart, r["cast_on"].get<int>());
  EXPECT_DOUBLE_EQ(d["yo_share"].get<double>(), h.yo_share);
  EXPECT_EQ(d["holes"].get<long>(), h.yarn_overs);
  EXPECT_EQ(d["holes_in_lines"].get<long>(), h.in_lines);
  EXPECT_DOUBLE_EQ(d["hole_lines"].get<double>(), h.hole_lines);
  EXPECT_EQ(d["yo_share_band"], nlohmann::json::array({0.10, 0.25}));
  EXPECT_TRUE(d["yo_share_in_band"].get<bool>()) << d.dump();
  EXPECT_GE(d["yo_share"].get<double>(), 0.10);
  EXPECT_LE(d["yo_share"].get<double>(), 0.25);
  EXPECT_GE(d["symmetry"].get<double>(), 0.0);
  EXPECT_TRUE(r["stopped_by"] == "stagnation" || r["stopped_by"] == "generations") << r["stopped_by"];
  EXPECT_EQ(r["params"]["stagnation"], 100);
  EXPECT_EQ(r["fitness"]["weights"]["hole_lines"], 3.0);
}

TEST_F(ConvertLaceTest, DesignWeightsAreCheckedByKey) {
  EXPECT_THAT(error_of(kQuick + "hole_lines = -1\n"), HasSubstr("hole_lines"));
  EXPECT_THAT(error_of(kQuick + "yo_band = nan\n"), HasSubstr("yo_band"));
  EXPECT_THAT(error_of(kQuick + "yo_share_min = 0.3\n"), HasSubstr("yo_share_min"));
  EXPECT_THAT(error_of(kQuick + "stagnation = -2\n"), HasSubstr("stagnation"));
  EXPECT_THAT(error_of(kQuick + "target_score = \"high\"\n"), HasSubstr("target_score"));
  EXPECT_THAT(error_of(kQuick + "target_score = -1\n"), HasSubstr("target_score"));
  // A target a first generation reaches stops at once (without the minimised terms every
  // feasible chart with lace scores well above 0.01).
  run(kQuick + "target_score = 0.01\nyo_band = 0\nwidth_change = 0\n");
  const nlohmann::json r = nlohmann::json::parse(slurp(dir_ / "out" / "report.json"));
  EXPECT_EQ(r["stopped_by"], "target_score");
  EXPECT_EQ(r["generations"], 0);
}

}  // namespace
}  // namespace atelier

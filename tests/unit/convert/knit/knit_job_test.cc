// convert() for kind knit on real images: every output exists and keeps its promises.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "convert/convert.h"
#include "convert/common/param_table.h"
#include "convert/knit/knit_order.h"
#include "base/error.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

const fs::path kData = ATELIER_TEST_DATA;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// Longest run of one colour in any row of a 0/255 image.
int longest_row_run(const cv::Mat& img) {
  int longest = 0;
  for (int r = 0; r < img.rows; ++r) {
    int run = 0;
    for (int c = 0; c < img.cols; ++c) {
      run = (c > 0 && img.at<uchar>(r, c) == img.at<uchar>(r, c - 1)) ? run + 1 : 1;
      longest = std::max(longest, run);
    }
  }
  return longest;
}

class ConvertKnitTest : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = fs::temp_directory_path() /
           ("atelier-convert-knit-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(out_);
  }
  void TearDown() override { fs::remove_all(out_); }

  ConvertResult run(const fs::path& input, const std::vector<std::string>& sets) {
    ConvertRequest req;
    req.kind = "knit";
    req.input = input;
    for (const auto& s : sets) apply_set(req.params, s);
    req.output_dir = out_;
    req.progress = [this](double f) { progress_.push_back(f); };
    return convert(req);
  }

  // Checks every output for a pattern of `width` stitches and the given max float.
  void check_outputs(int width, int max_float) {
    for (const char* name : {"pattern.png", "preview.png", "chart.pdf", "pattern.k", "report.json"})
      ASSERT_TRUE(fs::exists(out_ / name)) << name;

    cv::Mat pattern = cv::imread((out_ / "pattern.png").string(), cv::IMREAD_GRAYSCALE);
    ASSERT_EQ(pattern.cols, width);
    ASSERT_GT(pattern.rows, 0);
    EXPECT_EQ(cv::countNonZero((pattern != 0) & (pattern != 255)), 0) << "pattern.png is not black/white";
    EXPECT_LE(longest_row_run(pattern), max_float);

    nlohmann::json report = nlohmann::json::parse(slurp(out_ / "report.json"));
    for (const char* key :
         {"parameters", "input", "grid", "conflicts_before", "conflicts_after",
          "consistent_before_pct", "consistent_after_pct", "flips", "random_walk_flips",
          "search_flips", "longest_float", "max_float", "solver", "complete", "similarity",
          "similarity_start", "timings_ms", "outputs", "first_row"})
      EXPECT_TRUE(report.contains(key)) << key;
    EXPECT_EQ(report["conflicts_after"], 0);
    EXPECT_EQ(report["complete"], true);
    EXPECT_EQ(report["grid"]["stitches"], width);
    EXPECT_EQ(report["grid"]["rows"], pattern.rows);
    EXPECT_LE(report["longest_float"].get<int>(), max_float);
    EXPECT_EQ(report["first_row"], "bottom");
    EXPECT_GT(report["similarity"].get<double>(), 0.0);
    EXPECT_EQ(report["flips"].get<long>(),
              report["random_walk_flips"].get<long>() + report["search_flips"].get<long>());

    std::string pdf = slurp(out_ / "chart.pdf");
    EXPECT_EQ(pdf.rfind("%PDF", 0), 0u);

    check_knitout(slurp(out_ / "pattern.k"), pattern);
    ASSERT_FALSE(progress_.empty());
    EXPECT_DOUBLE_EQ(progress_.back(), 1.0);
  }

  // Two passes per row in one direction (carrier 1's, then carrier 2's; no misses), alternating
  // per row; each needle knitted exactly once
  // per row, by carrier 2 exactly where pattern.png is black (f1 = leftmost, row 1 = bottom).
  // `top`: [knit] first_row = "top", row 1 is pattern.png's top row.
  static void check_knitout(const std::string& k, const cv::Mat& pattern, bool top = false) {
    ASSERT_EQ(k.rfind(";!knitout-2\n", 0), 0u);
    EXPECT_THAT(k, HasSubstr(";;Carriers: 1 2 3 4 5 6 7 8 9 10\n"));
    EXPECT_THAT(k, HasSubstr(";;Machine:"));
    EXPECT_THAT(k, HasSubstr(";;Gauge:"));
    EXPECT_THAT(k, HasSubstr("inhook 1\n"));
    EXPECT_THAT(k, HasSubstr("releasehook 1\n"));
    EXPECT_THAT(k, HasSubstr("tuck "));
    EXPECT_GT(k.rfind("outhook 1"), k.rfind("; row "));

    std::istringstream in(k);
    std::string line;
    int row = 0;
    std::vector<std::string> ops;
    char last_dir = 0;
    size_t carrier2_knits = 0;
    auto finish_row = [&]() {
      if (row == 0) return;
      SCOPED_TRACE("row " + std::to_string(row));
      const int w = pattern.cols;
      ASSERT_EQ(ops.size(), static_cast<size_t>(w)) << "each needle knitted once, no misses";
      std::vector<int> knits(w, 0);
      char dir = 0;
      int last_carrier = 1;
      for (size_t i = 0; i < ops.size(); ++i) {
        std::istringstream op(ops[i]);
        std::string verb, d, needle;
        int carrier = 0;
        op >> verb >> d >> needle >> carrier;
        ASSERT_EQ(verb, "knit") << ops[i];
        ASSERT_GE(carrier, last_carrier) << "carrier 1's pass, then carrier 2's: " << ops[i];
        last_carrier = carrier;
        if (dir == 0) dir = d[0];
        ASSERT_EQ(d[0], dir) << "both passes in one direction: " << ops[i];
        int n = std::stoi(needle.substr(1)) - 1;
        ASSERT_TRUE(n >= 0 && n < w) << ops[i];
        ++knits[n];
        bool contrast = pattern.at<uchar>(top ? row - 1 : pattern.rows - row, n) == 0;
        EXPECT_EQ(carrier == 2, contrast) << ops[i];
        if (carrier == 2) ++carrier2_knits;
      }
      for (int n = 0; n < w; ++n) ASSERT_EQ(knits[n], 1) << "needle f" << n + 1;
      ASSERT_NE(dir, last_dir) << "direction alternates";
      last_dir = dir;
    };
    while (std::getline(in, line)) {
      if (line.rfind("; bind-off", 0) == 0) break;  // the rows end there (knit_knitout.h)
      if (line.rfind("; row ", 0) == 0) {
        finish_row();
        ops.clear();
        row = std::stoi(line.substr(6));
      } else if (row > 0 && (line.rfind("knit ", 0) == 0 || line.rfind("miss ", 0) == 0)) {
        ops.push_back(line);
      }
    }
    finish_row();
    EXPECT_EQ(row, pattern.rows);
    EXPECT_GT(carrier2_knits, 0u) << "the contrast carrier is used";
  }

  fs::path out_;
  std::vector<double> progress_;
};

TEST_F(ConvertKnitTest, LineDrawingPic3) {
  ConvertResult r = run(kData / "pic3.png", {"width=90"});
  check_outputs(90, 4);
  // solver = "auto" (issue 22) is resolved by measurement; the report names what ran.
  EXPECT_EQ(r.report["parameters"]["solver"], "auto");
  EXPECT_EQ(r.report["solver"], r.report["solver_auto_choice"]);
  EXPECT_EQ(r.outputs.size(), 5u);
}

// The row order is the job's: first_row = "top" knits pattern.png's top row first in the
// knitout, says so in it, and records it in report.json for the machine (knit_order.h).
TEST_F(ConvertKnitTest, FirstRowTopMakesTheKnitoutStartAtThePicturesTopAndIsRecorded) {
  const ConvertResult r = run(kData / "pic3.png", {"width=60", "first_row=\"top\""});
  const cv::Mat pattern = cv::imread((out_ / "pattern.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_GT(pattern.rows, 2);
  // An upside-down pattern would pass both knitout checks only if pic3 were symmetric.
  cv::Mat flipped;
  cv::flip(pattern, flipped, 0);
  ASSERT_GT(cv::countNonZero(flipped != pattern), 0) << "pic3 is no test of the order";
  const std::string k = slurp(out_ / "pattern.k");
  check_knitout(k, pattern, /*top=*/true);
  EXPECT_THAT(k, HasSubstr("row 1 = top of the picture"));
  EXPECT_EQ(r.report["first_row"], "top");
  EXPECT_EQ(r.report["parameters"]["first_row"], "top");
  EXPECT_EQ(job_knits_top_row_first(out_), true);
  // pattern.png itself stays upright: the same picture as the default order's.
  run(kData / "pic3.png", {"width=60"});
  const cv::Mat upright = cv::imread((out_ / "pattern.png").string(), cv::IMREAD_GRAYSCALE);
  EXPECT_EQ(cv::countNonZero(upright != pattern), 0);
  EXPECT_EQ(job_knits_top_row_first(out_), false);
  EXPECT_THAT(slurp(out_ / "pattern.k"), HasSubstr("row 1 = bottom of the picture"));
}

TEST_F(ConvertKnitTest, TheMachineReadsTheOrderFromTheJobsReport) {
  fs::create_directories(out_);
  EXPECT_FALSE(job_knits_top_row_first(out_)) << "no report: the default, bottom first";
  std::ofstream(out_ / "report.json") << R"({"kind": "knit", "first_row": "top"})";
  EXPECT_TRUE(job_knits_top_row_first(out_));
  std::ofstream(out_ / "report.json") << R"({"kind": "knit", "first_row": "left"})";
  try {
    job_knits_top_row_first(out_);
    FAIL() << "no error";
  } catch (const BadInput& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr("report.json"), HasSubstr("first_row"), HasSubstr("\"left\"")));
  }
  std::ofstream(out_ / "report.json") << "{not json";
  EXPECT_THROW(job_knits_top_row_first(out_), BadInput);
}

TEST_F(ConvertKnitTest, PhotoButterflyWithLongerFloats) {
  run(kData / "butterfly.jpg", {"max_float=6", "solver=\"gsat\"", "dither=atkinson"});
  check_outputs(120, 6);
  nlohmann::json report = nlohmann::json::parse(slurp(out_ / "report.json"));
  EXPECT_EQ(report["parameters"]["dither"], "atkinson");
  EXPECT_EQ(report["parameters"]["dither_used"], "atkinson");
  EXPECT_FALSE(report.contains("dither_auto_choice"));
}

TEST_F(ConvertKnitTest, WidePatternChartSpansSeveralPages) {
  run(kData / "butterfly.jpg", {"width=200"});
  std::string pdf = slurp(out_ / "chart.pdf");
  // Page objects, not the "/Type /Pages" tree.
  size_t pages = count(pdf, "/Type /Page") - count(pdf, "/Type /Pages");
  EXPECT_GT(pages, 1u);
  nlohmann::json report = nlohmann::json::parse(slurp(out_ / "report.json"));
  EXPECT_EQ(report["chart_pages"].get<size_t>(), pages);
  cv::Mat pattern = cv::imread((out_ / "pattern.png").string(), cv::IMREAD_GRAYSCALE);
  EXPECT_EQ(pattern.cols, 200);
}

TEST_F(ConvertKnitTest, AutoDitherExplainsItsChoice) {
  nlohmann::json report = run(kData / "butterfly.jpg", {"width=60"}).report;
  EXPECT_EQ(report["parameters"]["dither"], "auto");
  ASSERT_TRUE(report.contains("dither_auto_choice"));
  EXPECT_EQ(report["dither_auto_choice"], report["parameters"]["dither_used"]);
  EXPECT_TRUE(report.contains("dither_auto_reason"));
}

// Issue 22: on a mostly white card auto took threshold because the picture "looks like a line
// drawing" (blurred SSIM 0.71 where threshold + texturing gave 0.89). Now every dither x
// complete solver is tried and the best blurred SSIM at zero violations kept; the report
// lists the candidates.
TEST_F(ConvertKnitTest, AutoChoosesTheBestMeasuredPairOnAMostlyWhiteCard) {
  fs::create_directories(out_ / "in");
  const fs::path card = out_ / "in" / "card.png";
  cv::Mat img(300, 400, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::rectangle(img, cv::Rect(12, 12, 376, 276), cv::Scalar(40, 40, 40), 2);
  cv::putText(img, "Happy", cv::Point(60, 120), cv::FONT_HERSHEY_SIMPLEX, 2.2, cv::Scalar(20, 20, 20), 5);
  cv::putText(img, "Birthday", cv::Point(50, 210), cv::FONT_HERSHEY_SCRIPT_SIMPLEX, 2.0, cv::Scalar(60, 60, 60), 3);
  for (int i = 0; i < 5; ++i)
    cv::line(img, cv::Point(40 + 60 * i, 250), cv::Point(80 + 60 * i, 270), cv::Scalar(120, 120, 120), 2);
  cv::circle(img, cv::Point(330, 70), 30, cv::Scalar(180, 180, 180), cv::FILLED);  // a light grey dot
  ASSERT_TRUE(cv::imwrite(card.string(), img));

  const nlohmann::json report = run(card, {}).report;
  ASSERT_TRUE(report.contains("auto_search")) << report.dump(1);
  const nlohmann::json& tried = report["auto_search"]["candidates"];
  ASSERT_EQ(tried.size(), 16u);  // 4 dithers x 4 complete solvers
  std::set<std::string> pairs;
  double best = -2;
  for (const auto& c : tried) {
    ASSERT_TRUE(c.contains("similarity") && c.contains("violations")) << c.dump();
    pairs.insert(c["dither"].get<std::string>() + "+" + c["solver"].get<std::string>());
    EXPECT_EQ(c["violations"], 0) << c.dump();  // all complete solvers
    best = std::max(best, c["similarity"].get<double>());
  }
  EXPECT_EQ(pairs.size(), 16u);
  EXPECT_TRUE(pairs.count("threshold+hybrid") && pairs.count("ordered+gsat") &&
              pairs.count("threshold+texturing") && pairs.count("atkinson+hybrid-texturing"));
  const nlohmann::json& chosen = tried[report["auto_search"]["chosen"].get<size_t>()];
  // The pattern written is the chosen pair's: its similarity is the best of all candidates.
  EXPECT_DOUBLE_EQ(report["similarity"].get<double>(), chosen["similarity"].get<double>());
  EXPECT_DOUBLE_EQ(report["similarity"].get<double>(), best);
  EXPECT_EQ(report["parameters"]["dither_used"], chosen["dither"]);
  EXPECT_EQ(report["solver"], chosen["solver"]);
  EXPECT_EQ(report["conflicts_after"], 0);
  EXPECT_THAT(report["dither_auto_reason"].get<std::string>(), HasSubstr("blurred SSIM"));
  // What auto used to pick (threshold, hybrid) measures lower than the choice.
  const nlohmann::json old = run(card, {"dither=\"threshold\"", "solver=\"hybrid\""}).report;
  EXPECT_FALSE(old.contains("auto_search"));
  EXPECT_GT(report["similarity"].get<double>(), old["similarity"].get<double>());
  // Same job, same choice.
  EXPECT_EQ(run(card, {}).report["auto_search"]["chosen"], report["auto_search"]["chosen"]);
}

TEST_F(ConvertKnitTest, RelaxMaskBesideTheInputFreesItsArea) {
  // A copy of pic3 with a mask whose left half is dark (relaxed): the solver leaves the long
  // white floats of the background there, and still removes every one elsewhere.
  fs::create_directories(out_ / "in");
  fs::path input = out_ / "in" / "pic3.png";
  fs::copy_file(kData / "pic3.png", input);
  cv::Mat mask(300, 400, CV_8UC1, cv::Scalar(255));
  mask(cv::Rect(0, 0, 200, 300)).setTo(0);
  ASSERT_TRUE(cv::imwrite((out_ / "in" / "pic3.png.relax.png").string(), mask));
  nlohmann::json report = run(input, {"width=80"}).report;
  EXPECT_GT(report["relaxed_stitches"].get<long>(), 0);
  EXPECT_EQ(report["complete"], true);
  EXPECT_THAT(report["parameters"]["relax_mask"].get<std::string>(), HasSubstr("pic3.png.relax.png"));
  cv::Mat pattern = cv::imread((out_ / "pattern.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(pattern.cols, 80);
  EXPECT_GT(longest_row_run(pattern(cv::Rect(0, 0, 38, pattern.rows))), 4);
  EXPECT_LE(longest_row_run(pattern(cv::Rect(42, 0, 38, pattern.rows))), 4);
}

TEST_F(ConvertKnitTest, BadInputIsAConvertErrorNamingTheFile) {
  fs::create_directories(out_);
  std::ofstream(out_ / "notes.png") << "shopping list\n";
  try {
    run(out_ / "notes.png", {});
    FAIL() << "no error";
  } catch (const ConvertError& e) {
    EXPECT_THAT(e.what(), HasSubstr("notes.png"));
  }
  EXPECT_THROW(run(kData / "pic3.png", {"width=3"}), ParamError);
  EXPECT_THROW(run(kData / "pic3.png", {"relax_mask=\"missing.png\""}), ConvertError);
}

TEST_F(ConvertKnitTest, APatternTallerThanTheRowLimitIsRefusedFromTheHeader) {
  // 200 stitches wide and as tall as the pixel limit lets a picture be: ~128000 rows, which
  // ran for minutes. Refused before decoding, naming the file, the rows and the limit.
  fs::create_directories(out_);
  const fs::path tall = out_ / "tall.png";
  ASSERT_TRUE(cv::imwrite(tall.string(), cv::Mat(100000, 200, CV_8UC1, cv::Scalar(255))));
  try {
    run(tall, {"width=200"});
    FAIL() << "no error";
  } catch (const ConvertError& e) {
    EXPECT_THAT(e.what(), HasSubstr("tall.png: the pattern would have 128571 rows of 200 stitches, "
                                    "more than the limit of 10000 rows (27.8 m of fabric at 36 rows per 10 cm)"));
  }
}

TEST_F(ConvertKnitTest, ALongPatternsPreviewStaysWithinItsPixelLimit) {
  fs::create_directories(out_);
  const fs::path input = out_ / "long.png";
  cv::Mat img(1500, 200, CV_8UC1);
  cv::randu(img, 0, 256);
  ASSERT_TRUE(cv::imwrite(input.string(), img));
  run(input, {"width=200"});
  cv::Mat preview = cv::imread((out_ / "preview.png").string());
  ASSERT_FALSE(preview.empty());
  EXPECT_LE(static_cast<double>(preview.total()), 40e6);
  EXPECT_GE(preview.cols, 200 * 4);  // still several pixels per stitch
}

}  // namespace
}  // namespace atelier

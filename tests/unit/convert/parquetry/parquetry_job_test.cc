// The parquetry conversion end to end on the real wood scans (tests/data/wood at 25.4 dpi:
// 1 px = 1 mm): plan.json, cut files, the laser program, the preview, the stock of used wood,
// several targets together, and the errors a user meets.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "convert/common/param_table.h"
#include "convert/convert.h"
#include "convert/kinds.h"
#include "convert/parquetry/parquetry_job.h"
#include "convert/parquetry/parquetry_params.h"
#include "drivers/grbl/program.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;

const fs::path kData(ATELIER_TEST_DATA);
const fs::path kWood = kData / "wood";
constexpr double kRasterPxPerMm = 10;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

json read_json(const fs::path& p) { return json::parse(slurp(p)); }

// A small, fast job: 84 mm, 14 mm patches (6 x N pieces), 4 rotations.
std::string small_job(const std::string& extra = "") {
  return "wood = \"" + kWood.string() + "\"\ndpi = 25.4\nsize_mm = 84\npatch_mm = 14\nrotations = 4\n" + extra;
}

class ParquetryJobTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("atelier-parquetry-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  ConvertRequest request(const std::string& toml_text, const fs::path& input, const std::string& out) {
    ConvertRequest req;
    req.kind = "parquetry";
    req.input = input;
    req.params = toml::parse(toml_text, std::string_view{"job.toml"});
    req.params_source = "job.toml";
    req.output_dir = dir_ / out;
    return req;
  }

  ConvertResult run(const std::string& toml_text, const std::string& out = "out",
                    const fs::path& input = kData / "fruits.jpg") {
    return convert(request(toml_text, input, out));
  }

  fs::path dir_;
};

// Every source polygon of `plan` on `sheet` rasterised at 10 px/mm, shrunk by `shrink_mm`;
// adds 1 per covered pixel to `count` (CV_16U, at least the sheet's size).
void rasterise(const json& plan, const std::string& sheet, double shrink_mm, cv::Mat& count) {
  const int shrink_px = static_cast<int>(std::lround(shrink_mm * kRasterPxPerMm));
  for (const auto& piece : plan["pieces"]) {
    if (piece["wood"] != sheet) continue;
    std::vector<cv::Point> poly;
    for (const auto& p : piece["source"]) {
      poly.emplace_back(static_cast<int>(std::lround(p[0].get<double>() * kRasterPxPerMm * 16)),
                        static_cast<int>(std::lround(p[1].get<double>() * kRasterPxPerMm * 16)));
    }
    cv::Mat one(count.size(), CV_8UC1, cv::Scalar(0));
    cv::fillPoly(one, std::vector<std::vector<cv::Point>>{poly}, cv::Scalar(1), cv::LINE_8, 4);
    if (shrink_px > 0) {
      cv::erode(one, one, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * shrink_px + 1, 2 * shrink_px + 1}));
    }
    ASSERT_GT(cv::countNonZero(one), 0) << "piece " << piece["id"] << " vanished";
    cv::Mat one16;
    one.convertTo(one16, CV_16U);
    count += one16;
  }
}

std::set<std::string> sheets_of(const json& plan) {
  std::set<std::string> s;
  for (const auto& piece : plan["pieces"]) s.insert(piece["wood"].get<std::string>());
  return s;
}

cv::Mat sheet_counter() { return cv::Mat(2000, 2000, CV_16UC1, cv::Scalar(0)); }  // 200 mm

TEST_F(ParquetryJobTest, WritesEveryOutputAndNoTwoPiecesShareWood) {
  ConvertResult r = run(small_job());
  const fs::path out = dir_ / "out";
  for (const char* f : {"plan.json", "assembly.svg", "cuts.gcode", "preview.png", "report.json"}) {
    EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
  }
  json plan = read_json(out / "plan.json");
  EXPECT_NEAR(std::min(plan["width_mm"].get<double>(), plan["height_mm"].get<double>()), 84, 1e-6);
  const int cells = plan["grid_cols"].get<int>() * plan["grid_rows"].get<int>();
  ASSERT_EQ(plan["pieces"].size(), static_cast<size_t>(cells));
  EXPECT_EQ(r.report["pieces"], cells);

  // Each piece keeps its size (a rigid motion), and no pixel of wood is used twice.
  const double kerf = plan["params"]["kerf_mm"].get<double>();
  for (const auto& piece : plan["pieces"]) {
    auto area = [](const json& poly) {
      std::vector<cv::Point2f> p;
      for (const auto& q : poly) p.emplace_back(q[0].get<float>(), q[1].get<float>());
      return cv::contourArea(p);
    };
    EXPECT_NEAR(area(piece["source"]), area(piece["target"]), 0.5) << "piece " << piece["id"];
    EXPECT_NEAR(area(piece["target"]), 14 * 14, 0.5);
  }
  for (const auto& sheet : sheets_of(plan)) {
    cv::Mat count = sheet_counter();
    rasterise(plan, sheet, kerf / 2, count);
    double most = 0;
    cv::minMaxLoc(count, nullptr, &most);
    EXPECT_LE(most, 1) << "wood of sheet " << sheet << " is used twice";
  }

  // The preview shows the result at about 4 px/mm.
  cv::Mat preview = cv::imread((out / "preview.png").string());
  ASSERT_FALSE(preview.empty());
  EXPECT_NEAR(preview.cols, plan["width_mm"].get<double>() * 4, 1);
  EXPECT_NEAR(preview.rows, plan["height_mm"].get<double>() * 4, 1);
  cv::Mat grey;
  cv::cvtColor(preview, grey, cv::COLOR_BGR2GRAY);
  EXPECT_GT(cv::mean(grey)[0], 40);  // wood, not the black background
}

TEST_F(ParquetryJobTest, CutFilesHoldEveryPieceOfTheirSheetOnceMirrored) {
  run(small_job());
  const fs::path out = dir_ / "out";
  json plan = read_json(out / "plan.json");
  std::map<std::string, std::multiset<int>> planned;
  std::map<int, json> by_id;
  for (const auto& piece : plan["pieces"]) {
    planned[piece["wood"]].insert(piece["id"].get<int>());
    by_id[piece["id"].get<int>()] = piece;
  }
  std::set<std::string> files;
  for (const auto& e : fs::directory_iterator(out)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("cuts-", 0) == 0 && e.path().extension() == ".svg") files.insert(name);
  }
  ASSERT_EQ(files.size(), planned.size());
  const std::regex group(R"re(<g id="piece-(\d+)" data-piece="(\d+)" data-sheet="([^"]+)">\s*<path d="M ([-0-9.]+) ([-0-9.]+) C[^"]*" fill="none" stroke="#ff0000"[^>]*/>\s*<path d="M[^"]+" fill="none" stroke="#0000ff")re");
  std::map<std::string, double> width;
  for (const auto& s : plan["sheets"]) width[s["id"]] = s["width_mm"].get<double>();
  for (const auto& [sheet, ids] : planned) {
    const std::string svg = slurp(out / ("cuts-" + sheet + ".svg"));
    const std::string w = std::to_string(std::lround(width[sheet]));  // scans of 160 or 200 px
    EXPECT_THAT(svg, HasSubstr("width=\"" + w + "mm\" height=\"" + w + "mm\" viewBox=\"0 0 " + w + " " + w + "\""));
    EXPECT_THAT(svg, HasSubstr("mirrored"));
    std::multiset<int> found;
    for (auto it = std::sregex_iterator(svg.begin(), svg.end(), group); it != std::sregex_iterator(); ++it) {
      const int id = std::stoi((*it)[1]);
      EXPECT_EQ(std::stoi((*it)[2]), id);
      EXPECT_EQ((*it)[3], sheet);
      found.insert(id);
      // Face down: the outline starts at the source's first point mirrored (x' = width - x).
      const json& first = by_id[id]["source"][0];
      EXPECT_NEAR(std::stod((*it)[4]), width[sheet] - first[0].get<double>(), 0.002) << "piece " << id;
      EXPECT_NEAR(std::stod((*it)[5]), first[1].get<double>(), 0.002) << "piece " << id;
    }
    EXPECT_EQ(found, ids) << sheet;
  }
  // The assembly holds every piece once.
  const std::string assembly = slurp(out / "assembly.svg");
  for (const auto& [id, piece] : by_id) {
    const std::string tag = "<g id=\"piece-" + std::to_string(id) + "\"";
    EXPECT_NE(assembly.find(tag), std::string::npos) << id;
    EXPECT_EQ(assembly.find(tag), assembly.rfind(tag)) << id;
  }
}

TEST_F(ParquetryJobTest, LaserProgramStaysOnTheBedAndPausesBetweenSheets) {
  run(small_job("[laser]\nwork_area_mm = [300, 210]\n"));
  const fs::path out = dir_ / "out";
  const json plan = read_json(out / "plan.json");
  const size_t sheets = sheets_of(plan).size();
  ASSERT_GE(sheets, 2u) << "the test wants a plan over several sheets";
  const std::string gcode = slurp(out / "cuts.gcode");
  grbl::Program prog = grbl::parse_program(gcode, 6000);
  ASSERT_TRUE(prog.bounds && prog.s_max);
  EXPECT_GE(prog.bounds->min_x, 0);
  EXPECT_GE(prog.bounds->min_y, 0);
  EXPECT_LE(prog.bounds->max_x, 300);
  EXPECT_LE(prog.bounds->max_y, 210);
  // Every coordinate sent, not only the header's claim.
  const std::regex axis(R"(([XY])(-?[0-9.]+))");
  size_t pauses = 0;
  for (const auto& line : prog.lines) {
    if (line == "M0") ++pauses;
    for (auto it = std::sregex_iterator(line.begin(), line.end(), axis); it != std::sregex_iterator(); ++it) {
      const double v = std::stod((*it)[2]);
      EXPECT_GE(v, 0) << line;
      EXPECT_LE(v, (*it)[1] == "X" ? 300 : 210) << line;
    }
  }
  EXPECT_EQ(pauses, sheets - 1);
  // Per sheet: the operator note, then the engraving, then the cutting.
  std::vector<std::string> segments;
  for (size_t from = 0;;) {
    size_t at = gcode.find("\nM0\n", from);
    segments.push_back(gcode.substr(from, at == std::string::npos ? std::string::npos : at - from));
    if (at == std::string::npos) break;
    from = at + 4;
  }
  ASSERT_EQ(segments.size(), sheets);
  for (size_t i = 1; i < segments.size(); ++i) {
    const std::string& before = segments[i - 1];
    // The line right before the M0, which the laser driver shows the operator.
    const std::string last = before.substr(before.rfind('\n') + 1);
    EXPECT_THAT(last, testing::MatchesRegex("; sheet [a-z_]+: place it face down at the origin, then resume"));
  }
  for (const auto& seg : segments) {
    const size_t engrave = seg.find(" engrave "), cut = seg.find(" cut ");
    ASSERT_NE(engrave, std::string::npos);
    ASSERT_NE(cut, std::string::npos);
    EXPECT_LT(engrave, cut);
  }
  json report = read_json(out / "report.json");
  EXPECT_EQ(report["sheets_order"].size(), sheets);
  EXPECT_GT(report["laser"]["cut_length_mm"].get<double>(), 0);
  EXPECT_GT(report["laser"]["engrave_length_mm"].get<double>(), 0);
}

TEST_F(ParquetryJobTest, SheetLargerThanTheBedFailsNamingBothSizes) {
  try {
    run(small_job("[laser]\nwork_area_mm = [150, 150]\n"));
    FAIL() << "no error";
  } catch (const ConvertError& e) {
    EXPECT_THAT(e.what(), testing::AllOf(HasSubstr("160 x 160 mm"), HasSubstr("150 x 150 mm")));
  }
}

TEST_F(ParquetryJobTest, GrainBeatsTheMeanColourBaselineOnAPhoto) {
  ConvertResult r = run(small_job(), "out", kData / "HappyFish.jpg");
  json report = read_json(dir_ / "out" / "report.json");
  EXPECT_LT(report["error"].get<double>(), report["baseline_error"].get<double>());
  EXPECT_EQ(r.report["error"], report["error"]);
  double used = 0;
  for (const auto& s : report["sheets"]) used += s["used_mm2"].get<double>();
  EXPECT_NEAR(used, report["pieces"].get<double>() * 14 * 14, 1);
}

// No sheet pixel lies under pieces of both plans (each piece shrunk by half the kerf).
void expect_no_shared_wood(const json& a, const json& b, const std::string& what) {
  std::set<std::string> all = sheets_of(a);
  for (const auto& s : sheets_of(b)) all.insert(s);
  const double kerf = a["params"]["kerf_mm"].get<double>();
  for (const auto& sheet : all) {
    cv::Mat count = sheet_counter();
    rasterise(a, sheet, kerf / 2, count);
    rasterise(b, sheet, kerf / 2, count);
    double most = 0;
    cv::minMaxLoc(count, nullptr, &most);
    EXPECT_LE(most, 1) << "sheet " << sheet << " " << what;
  }
}

TEST_F(ParquetryJobTest, SecondJobOnTheSameStockUsesOtherWood) {
  const std::string stock = "stock = \"" + (dir_ / "stock").string() + "\"\n";
  run(small_job(stock), "first");
  run(small_job(stock), "second");
  const json a = read_json(dir_ / "first" / "plan.json"), b = read_json(dir_ / "second" / "plan.json");
  expect_no_shared_wood(a, b, "planned twice");
  const json stock_json = read_json(dir_ / "stock" / "stock.json");
  std::map<std::string, int> per_job;
  for (const auto& [sheet, pieces] : stock_json["sheets"].items())
    for (const auto& p : pieces) ++per_job[p["job"].get<std::string>()];
  EXPECT_EQ(per_job["first"], static_cast<int>(a["pieces"].size()));
  EXPECT_EQ(per_job["second"], static_cast<int>(b["pieces"].size()));

  // Converting "first" again (a retry) takes new wood and keeps its earlier pieces taken:
  // they may have been cut already.
  run(small_job(stock), "first");
  per_job.clear();
  const json again = read_json(dir_ / "stock" / "stock.json");
  for (const auto& [sheet, pieces] : again["sheets"].items())
    for (const auto& p : pieces) ++per_job[p["job"].get<std::string>()];
  EXPECT_EQ(per_job["first"], 2 * static_cast<int>(a["pieces"].size()));
  EXPECT_EQ(per_job["second"], static_cast<int>(b["pieces"].size()));
}

TEST_F(ParquetryJobTest, RunningOutOfWoodSaysHowMuchWasNeededAndTakesNothing) {
  fs::create_directories(dir_ / "wood");
  fs::copy_file(kWood / "maple_dark.png", dir_ / "wood" / "maple.png");
  const std::string stock = (dir_ / "stock").string();
  try {
    run("wood = \"" + (dir_ / "wood").string() + "\"\ndpi = 25.4\nsize_mm = 200\npatch_mm = 14\n"
        "rotations = 4\nstock = \"" + stock + "\"\n");
    FAIL() << "no error";
  } catch (const ConvertError& e) {
    EXPECT_THAT(e.what(), testing::AllOf(HasSubstr("fruits.jpg"), HasSubstr("out of wood"),
                                         HasSubstr("needs"), HasSubstr("mm^2")));
  }
  EXPECT_FALSE(fs::exists(fs::path(stock) / "stock.json"));
}

TEST_F(ParquetryJobTest, BadParametersNameTheKey) {
  auto param_error = [&](const std::string& text) -> std::string {
    try {
      run(text);
    } catch (const ParamError& e) {
      return e.what();
    }
    ADD_FAILURE() << "accepted: " << text;
    return "";
  };
  EXPECT_THAT(param_error(small_job("colour = 3\n")), HasSubstr("unknown key 'colour'"));
  EXPECT_THAT(param_error("size_mm = 84\n"), HasSubstr("parquetry needs `wood`"));
  EXPECT_THAT(param_error(small_job("grid = \"hex\"\n")),
              testing::AllOf(HasSubstr("job.toml:6"), HasSubstr("key 'grid'"), HasSubstr("hex")));
  EXPECT_THAT(param_error(small_job("adaptive_levels = 9\n")), HasSubstr("key 'adaptive_levels'"));
  EXPECT_THAT(param_error(small_job("[laser]\nspeed = 3\n")), HasSubstr("laser.speed"));
  // The stock label is the job's own id, never a parameter: one naming another job's pieces
  // could otherwise touch that job's wood.
  EXPECT_THAT(param_error(small_job("job = \"7\"\n")), HasSubstr("unknown key 'job'"));
  // Checked per layer, as the daemon checks a sidecar: no `wood` is fine there.
  toml::table sidecar = toml::parse("patch_mm = 10\norder = \"center\"\n");
  EXPECT_NO_THROW(validate_kind_params("parquetry", sidecar, "x.png.toml"));
}

TEST_F(ParquetryJobTest, RelativeWoodFolderIsRelativeToItsFile) {
  fs::create_directories(dir_ / "conf" / "wood");
  fs::copy_file(kWood / "maple_dark.png", dir_ / "conf" / "wood" / "maple.png");
  std::ofstream(dir_ / "conf" / "p.toml") << "wood = \"wood\"\n";
  toml::table t = toml::parse_file((dir_ / "conf" / "p.toml").string());
  ParquetryParams p = read_parquetry_params(t, "p.toml");
  ASSERT_TRUE(p.wood_folder);
  EXPECT_EQ(*p.wood_folder, dir_ / "conf" / "wood");
  auto sheets = require_wood(p, "p.toml");
  ASSERT_EQ(sheets.size(), 1u);
  EXPECT_EQ(sheets[0].id, "maple");
}

TEST_F(ParquetryJobTest, TargetsConvertedTogetherShareNoWood) {
  ConvertRequest req = request(small_job(), kData / "fruits.jpg", "a");
  req.together.push_back({kData / "HappyFish.jpg", dir_ / "b"});
  convert(req);
  const json a = read_json(dir_ / "a" / "plan.json"), b = read_json(dir_ / "b" / "plan.json");
  EXPECT_TRUE(fs::exists(dir_ / "b" / "cuts.gcode"));
  EXPECT_EQ(read_json(dir_ / "b" / "report.json")["input"]["file"], "HappyFish.jpg");
  expect_no_shared_wood(a, b, "used by both targets");
  // Other kinds take one target only.
  ConvertRequest cut;
  cut.kind = "cut";
  cut.input = kData / "svg" / "box-test.svg";
  cut.output_dir = dir_ / "c";
  cut.together.push_back({kData / "fruits.jpg", dir_ / "d"});
  EXPECT_THROW(convert(cut), ConvertError);
}

// atelier-convert --with INPUT OUTPUT_DIR: one more target planned together, in its own folder
// with its own input copy; --with needs both values.
TEST_F(ParquetryJobTest, CommandLineToolPlansTargetsGivenWithTogether) {
  const std::string tool = std::string(ATELIER_BINARY_DIR) + "/bin/atelier-convert";
  ASSERT_TRUE(fs::exists(tool));
  const std::string sets = " --set wood=" + kWood.string() +
                           " --set dpi=25.4 --set size_mm=84 --set rotations=4";
  std::string cmd = tool + " parquetry " + (kData / "fruits.jpg").string() + " " + (dir_ / "a").string() +
                    sets + " --with " + (kData / "HappyFish.jpg").string() + " " + (dir_ / "b").string() +
                    " >/dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_TRUE(fs::exists(dir_ / "a" / "fruits.jpg"));
  EXPECT_TRUE(fs::exists(dir_ / "b" / "HappyFish.jpg"));
  EXPECT_EQ(read_json(dir_ / "b" / "report.json")["job"], "b");
  EXPECT_EQ(read_json(dir_ / "a" / "plan.json")["job"], "a");
  cmd = tool + " parquetry " + (kData / "fruits.jpg").string() + " " + (dir_ / "c").string() + sets +
        " --with " + (kData / "HappyFish.jpg").string() + " >/dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2) << "--with takes INPUT OUTPUT_DIR";
}

}  // namespace
}  // namespace atelier

namespace atelier {
namespace {

// Issue 23: a plan whose estimated memory is above [limits] job_memory_mb is refused before
// any matching (12 sheets x 4 rotations of 160 mm scans at 8 px/mm: several GB), naming the
// file, the estimate, what drives it and the budget; the same job at 0.5 px/mm runs.
TEST_F(ParquetryJobTest, APlanAboveTheMemoryBudgetIsRefusedBeforeMatching) {
  ConvertRequest req = request(small_job("px_per_mm = 8\n"), kData / "fruits.jpg", "big");
  req.memory_mb = 2048;
  try {
    convert(req);
    FAIL() << "a plan of several GB ran under a 2048 MB budget";
  } catch (const ConvertError& e) {
    const std::string m = e.what();
    EXPECT_THAT(m, ::testing::MatchesRegex("fruits\\.jpg: the parquetry plan needs about [0-9.]+ GB "
                                           "\\(12 sheets x 4 rotations at 8 px/mm\\), above the 2048 MB "
                                           "budget \\(limits\\.job_memory_mb\\); lower px_per_mm or "
                                           "rotations, or use fewer sheets"));
  }
  EXPECT_FALSE(fs::exists(dir_ / "big")) << "outputs were written";

  ConvertRequest small = request(small_job(), kData / "fruits.jpg", "small");
  small.memory_mb = 2048;
  const ConvertResult r = convert(small);
  EXPECT_GT(r.report["pieces"].get<int>(), 0);
}

}  // namespace
}  // namespace atelier

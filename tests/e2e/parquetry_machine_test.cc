// End to end: a photo dropped into incoming/parquetry/ becomes a wood-veneer plan that waits
// for the operator, is cut on the GRBL laser emulator sheet after sheet (a program pause, M0,
// for each sheet swap, resumed with `resume`), and burns what the cut files show; a second
// photo plans only on wood the first left free, and `wood list` / `wood reset` see it.
#include <gtest/gtest.h>

#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "tests/e2e/burn_compare.h"
#include "tests/e2e/daemon_harness.h"

namespace fs = std::filesystem;
using atelier::test::BackgroundProcess;
using atelier::test::DaemonProcess;
using atelier::test::TempDir;
using nlohmann::json;

namespace {

constexpr double kPxPerMm = 5;
constexpr double kWorkMm = 400;
const std::vector<std::string> kSheets = {"maple_light", "cherry_dark", "lanta_light", "mahogony_dark"};

struct ParquetryRig {
  TempDir tmp;
  fs::path link = tmp.path() / "laser";
  fs::path record = tmp.path() / "record.json";
  fs::path render = tmp.path() / "burn.png";
  fs::path wood = tmp.path() / "wood";
  std::unique_ptr<BackgroundProcess> emulator;
  std::unique_ptr<DaemonProcess> daemon;

  ParquetryRig() {
    // The workshop's wood: real scans, read at 25.4 dpi (1 px = 1 mm: 160 mm sheets).
    fs::create_directories(wood);
    std::ofstream lib(wood / "library.toml");
    for (const auto& s : kSheets) {
      fs::copy_file(atelier::test::test_image("wood/" + s + ".png"), wood / (s + ".png"));
      lib << "[[sheet]]\nid = \"" << s << "\"\nimage = \"" << s << ".png\"\ndpi = 25.4\n";
    }
    lib.close();
    emulator = std::make_unique<BackgroundProcess>(
        std::vector<std::string>{atelier::test::binary("atelier-laser-emu").string(), "--link", link.string(),
                                 "--record", record.string(), "--render", render.string(), "--px-per-mm", "5",
                                 "--time-scale", "0.01"},
        tmp.path() / "emu.log");
    for (int i = 0; i < 100 && !fs::exists(link); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    daemon = std::make_unique<DaemonProcess>(
        tmp.path(), "[parquetry]\nwood = \"" + wood.string() +
                        "\"\ndpi = 25.4\nsize_mm = 84\npatch_mm = 14\nrotations = 4\n"
                        "[[device]]\nname = \"laser\"\ndriver = \"grbl\"\nport = \"" + link.string() +
                        "\"\nkinds = [\"parquetry\"]\n");
    daemon->start();
  }

  json job(const std::string& name) {
    for (const auto& j : daemon->jobs())
      if (j["name"] == name) return j;
    return nullptr;
  }
  // Waits until job `name` is in `state` (false at once if it failed instead).
  bool wait_state(const std::string& name, const std::string& state,
                  std::chrono::milliseconds timeout = std::chrono::seconds(60)) {
    daemon->wait_for([&] {
      auto j = job(name);
      return !j.is_null() && (j["state"] == state || j["state"] == "failed");
    }, timeout);
    auto j = job(name);
    return !j.is_null() && j["state"] == state;
  }
  json stock() {
    std::ifstream in(tmp.path() / "wood-stock" / "stock.json");  // <state>/wood-stock: the store's folder
    return in ? json::parse(in) : json();
  }
};

// Every stroke of the job's cuts-<sheet>.svg files, all sheets at the origin as they are cut
// (the files already show each sheet mirrored, face down), in render pixels.
cv::Mat intended_burn(const fs::path& done) {
  cv::Mat mask(static_cast<int>(kWorkMm * kPxPerMm), static_cast<int>(kWorkMm * kPxPerMm), CV_8U, cv::Scalar(0));
  for (const auto& e : fs::directory_iterator(done)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("cuts-", 0) != 0 || e.path().extension() != ".svg") continue;
    atelier::test::draw_strokes(e.path(), kPxPerMm, mask);
  }
  return mask;
}

// The stock's pieces of one job on one sheet, rasterised at 4 px/mm.
cv::Mat pieces_mask(const json& pieces, const std::string& job) {
  cv::Mat m(160 * 4, 160 * 4, CV_8U, cv::Scalar(0));
  for (const auto& p : pieces) {
    if (p["job"] != job) continue;
    std::vector<cv::Point> pts;
    for (const auto& pt : p["polygon"]) pts.emplace_back(cvRound(pt[0].get<double>() * 4), cvRound(pt[1].get<double>() * 4));
    cv::fillPoly(m, std::vector<std::vector<cv::Point>>{pts}, cv::Scalar(255));
  }
  return m;
}

}  // namespace

TEST(E2EParquetry, APhotoIsCutSheetBySheetWithPausesAndASecondPlansOnFreeWood) {
  ParquetryRig rig;
  atelier::test::drop_file(atelier::test::test_image("HappyFish.jpg"), rig.daemon->incoming("parquetry") / "fish.jpg");
  ASSERT_TRUE(rig.wait_state("fish.jpg", "ready")) << rig.job("fish.jpg").dump() << rig.daemon->log();
  const json id = rig.job("fish.jpg")["id"];
  const fs::path done = rig.job("fish.jpg")["output_dir"].get<std::string>();
  ASSERT_TRUE(fs::exists(done / "cuts.gcode"));
  const json plan = json::parse(std::ifstream(done / "plan.json"));
  std::set<std::string> used_sheets;
  for (const auto& e : fs::directory_iterator(done))
    if (e.path().filename().string().rfind("cuts-", 0) == 0) used_sheets.insert(e.path().stem().string().substr(5));
  ASSERT_GE(used_sheets.size(), 1u);

  // The wood verb sees the job's pieces on the sheets it used.
  json list = rig.daemon->request("wood", {{"action", "list"}});
  ASSERT_TRUE(list["ok"]) << list.dump();
  size_t listed_pieces = 0;
  for (const auto& s : list["result"]["sheets"]) {
    listed_pieces += s["pieces"].get<size_t>();
    if (s["pieces"].get<int>() > 0) {
      EXPECT_TRUE(used_sheets.count(s["id"])) << s.dump();
      EXPECT_EQ(s["jobs"], json::array({id.dump()}));
      EXPECT_GT(s["used_pct"].get<double>(), 0);
      EXPECT_LT(s["free_mm2"].get<double>(), s["usable_mm2"].get<double>());
    }
  }
  EXPECT_GT(listed_pieces, 0u);

  // Started, it stops at a program pause before each further sheet and says what to do.
  ASSERT_TRUE(rig.daemon->request("start", {{"id", id}})["ok"]);
  size_t pauses = 0;
  for (;;) {
    std::string reason;
    ASSERT_TRUE(rig.daemon->wait_for([&] {
      auto j = rig.job("fish.jpg");
      reason = j["reason"].get<std::string>();
      return j["state"] == "completed" || j["state"] == "failed" ||
             reason.find("paused by the program (M0)") != std::string::npos;
    }, std::chrono::seconds(60))) << rig.job("fish.jpg").dump() << rig.daemon->log();
    if (rig.job("fish.jpg")["state"] != "running") break;
    ++pauses;
    EXPECT_NE(reason.find("place it face down at the origin"), std::string::npos) << reason;
    EXPECT_NE(reason.find("atelierctl resume " + id.dump()), std::string::npos) << reason;
    const auto dev = rig.daemon->request("devices")["result"][0];
    EXPECT_NE(dev["detail"].get<std::string>().find("paused by the program"), std::string::npos) << dev.dump();
    // Still paused a moment later: nothing resumes a sheet swap but the operator.
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    ASSERT_NE(rig.job("fish.jpg")["reason"].get<std::string>().find("paused by the program"), std::string::npos);
    ASSERT_TRUE(rig.daemon->request("resume", {{"id", id}})["ok"]);
    ASSERT_TRUE(rig.daemon->wait_for([&] {
      return rig.job("fish.jpg")["reason"].get<std::string>().find("paused by the program") == std::string::npos;
    }, std::chrono::seconds(10)));
    ASSERT_LE(pauses, used_sheets.size());
  }
  ASSERT_EQ(rig.job("fish.jpg")["state"], "completed") << rig.job("fish.jpg").dump() << rig.daemon->log();
  EXPECT_EQ(pauses, used_sheets.size() - 1);
  // Each sheet swap is in the job's story: the pause, the operator's resume, the run going on.
  size_t paused_lines = 0, resume_lines = 0, resumed_lines = 0;
  for (const std::string& line : rig.daemon->job_log(id.get<int>())) {
    paused_lines += line.find("): running: paused by the program (M0): ") != std::string::npos;
    resume_lines += line.find(", laser): resume asked by atelierctl resume") != std::string::npos;
    resumed_lines += line.find("): running: resumed after the program pause") != std::string::npos;
  }
  EXPECT_EQ(paused_lines, pauses) << rig.daemon->log();
  EXPECT_EQ(resume_lines, pauses) << rig.daemon->log();
  EXPECT_EQ(resumed_lines, pauses) << rig.daemon->log();

  // What burned is what the cut files show, all sheets at the origin.
  rig.emulator->stop();
  const json rec = json::parse(std::ifstream(rig.record));
  EXPECT_EQ(rec["rx_overflows"], 0);
  EXPECT_EQ(rec["errors"], 0);
  cv::Mat render = cv::imread(rig.render.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(render.empty());
  cv::Mat burnt = render < 200;
  cv::Mat intended = intended_burn(done);
  ASSERT_GT(cv::countNonZero(intended), 500);
  EXPECT_GT(atelier::test::covered(burnt, intended, 2), 0.95) << "burned where no cut file has a stroke";
  EXPECT_GT(atelier::test::covered(intended, burnt, 2), 0.95) << "a stroke of the cut files was not burned";

  // A second photo plans on the wood the first left free.
  atelier::test::drop_file(atelier::test::test_image("LinuxLogo.jpg"), rig.daemon->incoming("parquetry") / "logo.jpg");
  ASSERT_TRUE(rig.wait_state("logo.jpg", "ready")) << rig.job("logo.jpg").dump() << rig.daemon->log();
  const json id2 = rig.job("logo.jpg")["id"];
  const json stock = rig.stock();
  ASSERT_TRUE(stock.contains("sheets")) << stock.dump();
  std::set<std::string> jobs;
  for (const auto& [sheet, pieces] : stock["sheets"].items()) {
    for (const auto& p : pieces) jobs.insert(p["job"].get<std::string>());
    cv::Mat first = pieces_mask(pieces, id.dump()), second = pieces_mask(pieces, id2.dump());
    EXPECT_EQ(cv::countNonZero(first & second), 0) << "both jobs use the same wood on " << sheet;
  }
  EXPECT_EQ(jobs, (std::set<std::string>{id.dump(), id2.dump()}));

  // `wood reset --job` frees the first job's wood and nothing else.
  json reset = rig.daemon->request("wood", {{"action", "reset"}, {"job", id}});
  ASSERT_TRUE(reset["ok"]) << reset.dump();
  // (The stock is kept in a variable: items() of a temporary would dangle.)
  const json after_reset = rig.stock();
  for (const auto& [sheet, pieces] : after_reset["sheets"].items())
    for (const auto& p : pieces) EXPECT_EQ(p["job"], id2.dump());
  // A sheet with pieces on it is not removed without --force.
  std::string busy_sheet;
  for (const auto& [sheet, pieces] : after_reset["sheets"].items())
    if (!pieces.empty()) busy_sheet = sheet;
  ASSERT_FALSE(busy_sheet.empty());
  json refused = rig.daemon->request("wood", {{"action", "remove"}, {"id", busy_sheet}});
  EXPECT_FALSE(refused["ok"]);
  EXPECT_NE(refused.dump().find("--force"), std::string::npos) << refused.dump();
}

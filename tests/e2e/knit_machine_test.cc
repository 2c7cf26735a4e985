// End to end: atelierd knits real images on the AYAB emulator (a pseudo-terminal), and the
// emulator's record of what the needles did is compared with pattern.png.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <signal.h>

#include <algorithm>
#include <fstream>

#include <opencv2/imgcodecs.hpp>

#include "tests/e2e/daemon_harness.h"

namespace fs = std::filesystem;
using atelier::test::DaemonProcess;
using atelier::test::TempDir;

namespace {

struct Rig {
  TempDir tmp;
  atelier::test::KnitEmulator emulator;
  std::unique_ptr<DaemonProcess> daemon;

  Rig(std::vector<std::string> faults, const std::string& knit_toml, int row_ms = 3,
      const std::string& device_extra = "")
      : emulator(row_ms, fault_options(faults)) {
    daemon = std::make_unique<DaemonProcess>(
        tmp.path(), knit_toml + "[[device]]\nname = \"knitter\"\ndriver = \"ayab\"\nport = \"" +
                        emulator.link().string() + "\"\nmachine = \"kh930\"\nautostart = true\n" + device_extra);
    daemon->start();
  }
  // The emulated knitter waits for the beep of an accepted line before each pass, as a knitter
  // does; one who hears none pushes after knitter-patience-ms - by default here long enough
  // that a loaded test machine's slow answer never makes a pass start before its line came.
  static std::vector<std::string> fault_options(const std::vector<std::string>& faults) {
    std::vector<std::string> out;
    bool patience = false;
    for (const auto& f : faults) {
      out.insert(out.end(), {"--fault", f});
      patience = patience || f.rfind("knitter-patience-ms=", 0) == 0;
    }
    if (!patience) out.insert(out.end(), {"--fault", "knitter-patience-ms=5000"});
    return out;
  }

  nlohmann::json job(const std::string& name) { return daemon->job_named(name); }
  bool wait_state(const std::string& name, const std::string& state,
                  std::chrono::milliseconds timeout = std::chrono::seconds(120)) {
    return daemon->wait_job_state(name, state, timeout);
  }
  std::vector<std::string> recorded() const { return emulator.recorded(); }
};

// pattern.png's rows as the picture shows them, top row first; '1' = contrast (black).
std::vector<std::string> pattern_rows(const nlohmann::json& job) {
  cv::Mat p = cv::imread(job["output_dir"].get<std::string>() + "/pattern.png", cv::IMREAD_GRAYSCALE);
  std::vector<std::string> rows;
  for (int r = 0; r < p.rows; ++r) {
    std::string line;
    for (int c = 0; c < p.cols; ++c) line.push_back(p.at<uchar>(r, c) < 128 ? '1' : '0');
    rows.push_back(line);
  }
  return rows;
}

// pattern.png as the needles should knit it, in the job's knitting order: its report.json's
// first_row, "bottom" (the default: the last row of pattern.png first) or "top".
std::vector<std::string> expected_rows(const nlohmann::json& job) {
  std::vector<std::string> rows = pattern_rows(job);
  std::ifstream report(job["output_dir"].get<std::string>() + "/report.json");
  if (nlohmann::json::parse(report).value("first_row", "bottom") != "top") std::reverse(rows.begin(), rows.end());
  return rows;
}

}  // namespace

TEST(E2EKnitMachine, ADroppedImageIsKnittedExactlyAsThePatternSays) {
  Rig rig({}, "[knit]\nwidth = 60\n");
  auto devices = rig.daemon->request("devices");
  ASSERT_TRUE(devices["ok"]);
  ASSERT_EQ(devices["result"].size(), 1u);
  EXPECT_EQ(devices["result"][0]["name"], "knitter");
  ASSERT_TRUE(rig.daemon->wait_for([&] {
    return rig.daemon->request("devices")["result"][0]["state"] == "online";
  }, std::chrono::seconds(10)));

  atelier::test::drop_file(atelier::test::test_image("pic3.png"), rig.daemon->incoming("knit") / "pic3.png");
  ASSERT_TRUE(rig.wait_state("pic3.png", "completed")) << rig.daemon->log();
  auto job = rig.job("pic3.png");
  EXPECT_EQ(job["device"], "knitter");
  auto expected = expected_rows(job);
  EXPECT_EQ(job["progress"]["done"], static_cast<int>(expected.size()));
  EXPECT_EQ(job["progress"]["total"], static_cast<int>(expected.size()));
  EXPECT_EQ(rig.recorded(), expected);
  std::vector<std::string> states;
  auto show = rig.daemon->request("show", {{"id", job["id"]}});
  for (const auto& h : show["result"]["history"]) states.push_back(h["to"]);
  EXPECT_EQ(states, (std::vector<std::string>{"queued", "converting", "ready", "running", "completed"}));
  // The daemon's stderr (no journal here) tells the job's story, one line per state and a
  // few progress lines, each naming the job with its kind and, once it runs, the machine.
  const std::string tag = "job " + std::to_string(job["id"].get<int>()) + " (";
  const std::vector<std::string> story = rig.daemon->job_log(job["id"].get<int>());
  const std::string rows = std::to_string(expected.size());
  ASSERT_GE(story.size(), 5u) << rig.daemon->log();
  EXPECT_EQ(story.front(), tag + "knit): queued: pic3.png, dropped into the hot folder");
  EXPECT_EQ(story[1], tag + "knit): converting");
  EXPECT_EQ(story[2], tag + "knit): ready: converted; waiting for knitter");
  EXPECT_EQ(story[3], tag + "knit, knitter): running: knitting on knitter");
  EXPECT_EQ(story.back(), tag + "knit, knitter): completed: knitted " + rows + " rows on knitter");
  EXPECT_LE(story.size(), 5u + 9u) << "progress at most every 10 %:\n" << rig.daemon->log();
}

TEST(E2EKnitMachine, LinkDropInterruptsAndResumeFromRowFinishesThePattern) {
  Rig rig({"drop-after-row=12"}, "[knit]\nwidth = 50\n");
  atelier::test::drop_file(atelier::test::test_image("HappyFish.jpg"), rig.daemon->incoming("knit") / "fish.jpg");
  ASSERT_TRUE(rig.wait_state("fish.jpg", "interrupted")) << rig.daemon->log();
  auto job = rig.job("fish.jpg");
  EXPECT_NE(job["reason"].get<std::string>().find("device disconnected after row 12"), std::string::npos)
      << job["reason"];
  // The device went offline with the link and comes back when the emulator is replugged.
  ASSERT_TRUE(rig.daemon->wait_for([&] {
    return rig.daemon->request("devices")["result"][0]["state"] == "online";
  }, std::chrono::seconds(20))) << rig.daemon->log();

  auto ctl = atelier::test::run_command({atelier::test::binary("atelierctl").string(), "--socket",
                                         rig.daemon->socket().string(), "resume",
                                         std::to_string(job["id"].get<int>()), "--from-row", "13"});
  ASSERT_EQ(ctl.exit_code, 0) << ctl.err;
  ASSERT_TRUE(rig.wait_state("fish.jpg", "completed")) << rig.daemon->log();
  EXPECT_EQ(rig.recorded(), expected_rows(rig.job("fish.jpg")));
}

TEST(E2EKnitMachine, CorruptedBytesNeverCountAWrongRowAsKnitted) {
  // Bytes the firmware receives are garbled at random. The real firmware knits a garbled line
  // (it copies it before checking the CRC, and never asks again), so the job may stop: what
  // the daemon counts as knitted must be exactly the pattern, and a stop must name the row.
  Rig rig({"corrupt=0.02", "seed=7", "knitter-patience-ms=100"}, "[knit]\nwidth = 40\n", /*row_ms=*/3);
  atelier::test::drop_file(atelier::test::test_image("pic1.png"), rig.daemon->incoming("knit") / "pic1.png");
  ASSERT_TRUE(rig.daemon->wait_for([&] {
    auto j = rig.job("pic1.png");
    return !j.is_null() && (j["state"] == "completed" || j["state"] == "interrupted");
  }, std::chrono::seconds(120))) << rig.daemon->log();
  auto job = rig.job("pic1.png");
  const auto expected = expected_rows(job);
  const auto record = rig.recorded();
  const int counted = job["progress"]["done"];
  ASSERT_LE(static_cast<size_t>(counted), record.size()) << "rows counted that the needles never knitted";
  EXPECT_EQ(std::vector<std::string>(record.begin(), record.begin() + counted),
            std::vector<std::string>(expected.begin(), expected.begin() + counted))
      << "a row counted as knitted differs from the pattern";
  if (job["state"] == "completed") {
    // Every row of the pattern; after them only the empty last pass may have stray stitches
    // (a garbled blank line is the one garbling the host cannot see: host_session.h).
    ASSERT_GE(record.size(), expected.size());
    EXPECT_EQ(std::vector<std::string>(record.begin(), record.begin() + static_cast<long>(expected.size())), expected);
  } else {
    const std::string reason = job["reason"];
    EXPECT_NE(reason.find("--from-row " + std::to_string(counted + 1)), std::string::npos) << reason;
  }
}

TEST(E2EKnitMachine, AGarbledLineInterruptsNamingTheRowAndResumeCompletesTheFabric) {
  // The 5th line (row 5) reaches the firmware garbled; the knitter pushes on regardless.
  Rig rig({"corrupt-line=5", "knitter-patience-ms=100"}, "[knit]\nwidth = 40\n", /*row_ms=*/20);
  atelier::test::drop_file(atelier::test::test_image("pic1.png"), rig.daemon->incoming("knit") / "pic1.png");
  ASSERT_TRUE(rig.wait_state("pic1.png", "interrupted")) << rig.daemon->log();
  auto job = rig.job("pic1.png");
  const std::string id = std::to_string(job["id"].get<int>());
  const std::string reason = job["reason"];
  EXPECT_EQ(reason.rfind("row 5 was knitted from a line garbled on the cable", 0), 0u) << reason;
  EXPECT_NE(reason.find("unravel that row, then continue with: atelierctl resume " + id + " --from-row 5"),
            std::string::npos) << reason;
  EXPECT_EQ(job["progress"]["done"], 4) << "the garbled row was counted as knitted";
  const auto expected = expected_rows(job);
  const auto garbled = rig.recorded();
  ASSERT_GE(garbled.size(), 5u);
  EXPECT_EQ(std::vector<std::string>(garbled.begin(), garbled.begin() + 4),
            std::vector<std::string>(expected.begin(), expected.begin() + 4));
  EXPECT_NE(garbled[4], expected[4]) << "the emulator did not knit the garbled line";

  // The knitter unravels the wrong row(s) and resumes from row 5: the rest is exact.
  auto ctl = atelier::test::run_command({atelier::test::binary("atelierctl").string(), "--socket",
                                         rig.daemon->socket().string(), "resume", id, "--from-row", "5"});
  ASSERT_EQ(ctl.exit_code, 0) << ctl.err;
  ASSERT_TRUE(rig.wait_state("pic1.png", "completed")) << rig.daemon->log();
  const auto all = rig.recorded();
  ASSERT_EQ(all.size(), garbled.size() + expected.size() - 4);
  EXPECT_EQ(std::vector<std::string>(all.begin() + static_cast<long>(garbled.size()), all.end()),
            std::vector<std::string>(expected.begin() + 4, expected.end()));
}

TEST(E2EKnitMachine, AHungBoardIsResetByTheDaemonAndResumeCompletesWithoutAReplug) {
  // After row 6 a garbled SLIP escape hangs the firmware (it answers nothing until reset).
  Rig rig({"bad-escape-after-row=6"}, "[knit]\nwidth = 40\n", /*row_ms=*/3);
  atelier::test::drop_file(atelier::test::test_image("pic1.png"), rig.daemon->incoming("knit") / "pic1.png");
  ASSERT_TRUE(rig.wait_state("pic1.png", "interrupted")) << rig.daemon->log();
  auto job = rig.job("pic1.png");
  const std::string id = std::to_string(job["id"].get<int>());
  const std::string reason = job["reason"];
  EXPECT_EQ(reason, "the knitting machine stopped answering after row 6 (its firmware hung, e.g. on a byte garbled "
                    "on the cable); atelier reset it; continue with: atelierctl resume " + id + " --from-row 7");
  auto ctl = atelier::test::run_command({atelier::test::binary("atelierctl").string(), "--socket",
                                         rig.daemon->socket().string(), "resume", id, "--from-row", "7"});
  ASSERT_EQ(ctl.exit_code, 0) << ctl.err;
  ASSERT_TRUE(rig.wait_state("pic1.png", "completed")) << rig.daemon->log();
  EXPECT_EQ(rig.recorded(), expected_rows(rig.job("pic1.png")));
}

TEST(E2EKnitMachine, TheKnitterIsToldWhatToDoInOrderInShowAndDevices) {
  // The knitter takes 150 ms before each pass, so every prompt lasts long enough to be seen.
  Rig rig({"knitter-pause-ms=150"}, "[knit]\nwidth = 10\n", /*row_ms=*/3);
  atelier::test::drop_file(atelier::test::test_image("pic1.png"), rig.daemon->incoming("knit") / "p.png");
  std::vector<std::string> reasons, details;
  auto note = [](std::vector<std::string>& seen, const std::string& what) {
    if (!what.empty() && (seen.empty() || seen.back() != what)) seen.push_back(what);
  };
  ASSERT_TRUE(rig.daemon->wait_for([&] {
    auto j = rig.job("p.png");
    if (j.is_null()) return false;
    if (j["state"] == "running" || j["state"] == "completed") {
      note(reasons, rig.daemon->request("show", {{"id", j["id"]}})["result"]["reason"].get<std::string>());
      note(details, rig.daemon->request("devices")["result"][0]["detail"].get<std::string>());
    }
    return j["state"] == "completed";
  }, std::chrono::seconds(60))) << rig.daemon->log();
  const auto job = rig.job("p.png");
  const int rows = static_cast<int>(expected_rows(job).size());
  const std::string turn_mark = "move the carriage over the left turn mark (set it to KC-I or KC-II)";
  const std::string one_more = "all " + std::to_string(rows) +
                               " rows knitted; one more pass to finish: move the carriage across once more (the "
                               "machine beeps twice)";
  const std::string done = "knitted " + std::to_string(rows) + " rows on knitter";
  auto at = [&](const std::string& what) {
    return std::find(reasons.begin(), reasons.end(), what) - reasons.begin();
  };
  const auto knitting = std::find_if(reasons.begin(), reasons.end(),
                                     [](const std::string& r) { return r.rfind("knitting row ", 0) == 0; });
  ASSERT_NE(knitting, reasons.end()) << ::testing::PrintToString(reasons);
  EXPECT_LT(at(turn_mark), knitting - reasons.begin()) << ::testing::PrintToString(reasons);
  EXPECT_LT(knitting - reasons.begin(), at(one_more)) << ::testing::PrintToString(reasons);
  EXPECT_LT(at(one_more), at(done)) << ::testing::PrintToString(reasons);
  EXPECT_EQ(reasons.back(), done);
  // "knitting row N of M" counts up, and the device says the same.
  int last = 0;
  for (const auto& r : reasons) {
    int n = 0, m = 0;
    if (std::sscanf(r.c_str(), "knitting row %d of %d", &n, &m) == 2) {
      EXPECT_GE(n, last) << r;
      EXPECT_EQ(m, rows) << r;
      last = n;
    }
  }
  const std::string tag = "job " + std::to_string(job["id"].get<int>()) + ": ";
  EXPECT_NE(std::find(details.begin(), details.end(), tag + turn_mark), details.end())
      << ::testing::PrintToString(details);
  EXPECT_NE(std::find(details.begin(), details.end(), tag + one_more), details.end())
      << ::testing::PrintToString(details);
  EXPECT_EQ(rig.recorded(), expected_rows(job));
}

TEST(E2EKnitMachine, OldFirmwareFailsWithAClearReason) {
  Rig rig({"api=5"}, "[knit]\nwidth = 40\n");
  atelier::test::drop_file(atelier::test::test_image("pic1.png"), rig.daemon->incoming("knit") / "pic1.png");
  ASSERT_TRUE(rig.wait_state("pic1.png", "failed")) << rig.daemon->log();
  const std::string reason = rig.job("pic1.png")["reason"];
  EXPECT_NE(reason.find("API"), std::string::npos) << reason;
  EXPECT_NE(reason.find("5"), std::string::npos) << reason;
  EXPECT_TRUE(rig.recorded().empty());
}

TEST(E2EKnitMachine, APatternWiderThanTheBedFailsBeforeAnyRowIsSent) {
  Rig rig({}, "[knit]\nwidth = 230\n");
  atelier::test::drop_file(atelier::test::test_image("pic1.png"), rig.daemon->incoming("knit") / "wide.png");
  ASSERT_TRUE(rig.wait_state("wide.png", "failed")) << rig.daemon->log();
  const std::string reason = rig.job("wide.png")["reason"];
  EXPECT_NE(reason.find("230"), std::string::npos) << reason;
  EXPECT_NE(reason.find("200"), std::string::npos) << reason;
  EXPECT_TRUE(rig.recorded().empty());
}

TEST(E2EKnitMachine, CancelStopsAfterTheCurrentRowAndTheMachineKnitsTheNextJob) {
  Rig rig({}, "[knit]\nwidth = 40\n", /*row_ms=*/40);
  atelier::test::drop_file(atelier::test::test_image("fruits.jpg"), rig.daemon->incoming("knit") / "a.jpg");
  ASSERT_TRUE(rig.daemon->wait_for([&] {
    auto j = rig.job("a.jpg");
    return !j.is_null() && j["state"] == "running" && j["progress"]["done"].get<int>() >= 3;
  })) << rig.daemon->log();
  // The device shows the job it is knitting and how far it got.
  auto busy = rig.daemon->request("devices")["result"][0];
  EXPECT_EQ(busy["state"], "busy");
  EXPECT_EQ(busy["job"]["id"], rig.job("a.jpg")["id"]);
  EXPECT_GE(busy["job"]["progress"]["done"].get<int>(), 3);
  auto r = rig.daemon->request("cancel", {{"id", rig.job("a.jpg")["id"]}});
  ASSERT_TRUE(r["ok"]) << r;
  ASSERT_TRUE(rig.wait_state("a.jpg", "canceled")) << rig.daemon->log();
  const auto knitted = rig.recorded();
  const auto full = expected_rows(rig.job("a.jpg"));
  ASSERT_LT(knitted.size(), full.size());
  EXPECT_EQ(knitted, std::vector<std::string>(full.begin(), full.begin() + knitted.size()));

  atelier::test::drop_file(atelier::test::test_image("pic1.png"), rig.daemon->incoming("knit") / "b.png");
  ASSERT_TRUE(rig.wait_state("b.png", "completed")) << rig.daemon->log();
  auto all = rig.recorded();
  auto b = expected_rows(rig.job("b.png"));
  ASSERT_EQ(all.size(), knitted.size() + b.size());
  EXPECT_EQ(std::vector<std::string>(all.begin() + knitted.size(), all.end()), b);
}

// Issue 19 point 1: as AYAB desktop, the bottom row of the picture is knitted first, so the
// fabric, read as it hangs with the cast-on edge at the bottom (the first knitted row lowest),
// is pattern.png upright.
TEST(E2EKnitMachine, TheFabricCastOnEdgeDownIsThePatternUpright) {
  Rig rig({}, "[knit]\nwidth = 40\n");
  atelier::test::drop_file(atelier::test::test_image("pic3.png"), rig.daemon->incoming("knit") / "pic3.png");
  ASSERT_TRUE(rig.wait_state("pic3.png", "completed")) << rig.daemon->log();
  const std::vector<std::string> picture = pattern_rows(rig.job("pic3.png"));  // top row first
  ASSERT_GT(picture.size(), 2u);
  ASSERT_NE(picture, std::vector<std::string>(picture.rbegin(), picture.rend())) << "pic3 is no test of the order";
  const std::vector<std::string> knitted = rig.recorded();  // first knitted first
  ASSERT_EQ(knitted.size(), picture.size());
  EXPECT_EQ(knitted.front(), picture.back()) << "the first row knitted is pattern.png's bottom row";
  // The fabric from its top edge (the last row knitted) down to the cast-on edge.
  const std::vector<std::string> fabric(knitted.rbegin(), knitted.rend());
  EXPECT_EQ(fabric, picture);
}

// first_row = "top", here from the job's sidecar: knitted top-down, pattern.png's top row first,
// so the fabric, cast-on edge down, is the picture upside down.
TEST(E2EKnitMachine, FirstRowTopFromTheSidecarKnitsThePictureTopDown) {
  Rig rig({}, "[knit]\nwidth = 40\n");
  atelier::test::write_file(rig.daemon->incoming("knit") / "pic3.png.toml", "first_row = \"top\"\n");
  atelier::test::drop_file(atelier::test::test_image("pic3.png"), rig.daemon->incoming("knit") / "pic3.png");
  ASSERT_TRUE(rig.wait_state("pic3.png", "completed")) << rig.daemon->log();
  const std::vector<std::string> picture = pattern_rows(rig.job("pic3.png"));
  ASSERT_GT(picture.size(), 2u);
  ASSERT_NE(picture, std::vector<std::string>(picture.rbegin(), picture.rend()));
  const std::vector<std::string> knitted = rig.recorded();
  EXPECT_EQ(knitted, picture) << "pattern.png's rows in order, top row first";
}

// A device may no longer choose the row order (the job's chart was drawn for one): atelierd
// refuses the old key at startup, naming the file, the line and the new place.
TEST(E2EKnitMachine, TheOldDeviceFirstRowKeyIsRefusedNamingTheKnitSection) {
  TempDir tmp;
  const fs::path cfg = tmp.path() / "old.toml";
  atelier::test::write_file(cfg, "[spool]\ndir = \"spool\"\n[[device]]\nname = \"knitter\"\ndriver = \"ayab\"\n"
                                 "port = \"/dev/ttyACM0\"\nfirst_row = \"top\"\n");
  auto r = atelier::test::run_command({atelier::test::binary("atelierd").string(), "--check-config", "--config", cfg.string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(cfg.string() + ":7"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("first_row"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("[knit]"), std::string::npos) << r.err;
}

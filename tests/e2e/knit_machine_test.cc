// End to end: atelierd knits real images on the AYAB emulator (a pseudo-terminal), and the
// emulator's record of what the needles did is compared with pattern.png.
#include <gtest/gtest.h>
#include <signal.h>

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
  static std::vector<std::string> fault_options(const std::vector<std::string>& faults) {
    std::vector<std::string> out;
    for (const auto& f : faults) out.insert(out.end(), {"--fault", f});
    return out;
  }

  nlohmann::json job(const std::string& name) { return daemon->job_named(name); }
  bool wait_state(const std::string& name, const std::string& state,
                  std::chrono::milliseconds timeout = std::chrono::seconds(120)) {
    return daemon->wait_job_state(name, state, timeout);
  }
  std::vector<std::string> recorded() const { return emulator.recorded(); }
};

// pattern.png as the needles should knit it: row 0 first, '1' = contrast (black).
std::vector<std::string> expected_rows(const nlohmann::json& job) {
  cv::Mat p = cv::imread(job["output_dir"].get<std::string>() + "/pattern.png", cv::IMREAD_GRAYSCALE);
  std::vector<std::string> rows;
  for (int r = 0; r < p.rows; ++r) {
    std::string line;
    for (int c = 0; c < p.cols; ++c) line.push_back(p.at<uchar>(r, c) < 128 ? '1' : '0');
    rows.push_back(line);
  }
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

TEST(E2EKnitMachine, CorruptedBytesAreResentAndTheRecordIsStillExact) {
  Rig rig({"corrupt=0.02"}, "[knit]\nwidth = 40\n");
  atelier::test::drop_file(atelier::test::test_image("pic1.png"), rig.daemon->incoming("knit") / "pic1.png");
  ASSERT_TRUE(rig.wait_state("pic1.png", "completed")) << rig.daemon->log();
  EXPECT_EQ(rig.recorded(), expected_rows(rig.job("pic1.png")));
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

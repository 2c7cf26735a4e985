// End to end: the real atelierd on a temporary spool, real images dropped into the hot folder.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>

#include "tests/e2e/daemon_harness.h"

namespace fs = std::filesystem;
using atelier::test::DaemonProcess;
using atelier::test::TempDir;

namespace {

const std::vector<std::string> kImages = {"HappyFish.jpg", "LinuxLogo.jpg", "butterfly.jpg",
                                          "fruits.jpg",    "opencv-logo.png", "pic1.png",
                                          "pic3.png",      "pic5.png",        "starry_night.jpg"};

int longest_run(const cv::Mat& pattern) {
  int longest = 0;
  for (int r = 0; r < pattern.rows; ++r) {
    int run = 0;
    for (int c = 0; c < pattern.cols; ++c) {
      run = (c > 0 && pattern.at<uchar>(r, c) == pattern.at<uchar>(r, c - 1)) ? run + 1 : 1;
      longest = std::max(longest, run);
    }
  }
  return longest;
}

std::map<std::string, nlohmann::json> by_name(const nlohmann::json& jobs) {
  std::map<std::string, nlohmann::json> out;
  for (const auto& j : jobs) out[j["name"]] = j;
  return out;
}

}  // namespace

TEST(E2EKnit, RealImagesBecomePatternsWithShortFloats) {
  TempDir tmp;
  DaemonProcess daemon(tmp.path(), "[knit]\nwidth = 80\n");
  daemon.start();
  for (const auto& name : kImages)
    atelier::test::drop_file(atelier::test::test_image(name), daemon.incoming("knit") / name);
  ASSERT_TRUE(daemon.wait_settled(kImages.size())) << daemon.log();

  // What a user sees: atelierctl list --json.
  auto ctl = atelier::test::run_command({atelier::test::binary("atelierctl").string(), "--socket",
                                         daemon.socket().string(), "list", "--json"});
  ASSERT_EQ(ctl.exit_code, 0) << ctl.err;
  auto jobs = by_name(nlohmann::json::parse(ctl.out));
  ASSERT_EQ(jobs.size(), kImages.size());
  for (const auto& name : kImages) {
    const auto& job = jobs.at(name);
    EXPECT_EQ(job["state"], "completed") << name << ": " << job["reason"];
    EXPECT_EQ(job["kind"], "knit");
    fs::path out = job["output_dir"].get<std::string>();
    EXPECT_EQ(out, daemon.spool() / "done" / std::to_string(job["id"].get<int>()));
    for (const char* file : {"pattern.png", "preview.png", "chart.pdf", "pattern.k", "report.json"})
      EXPECT_TRUE(fs::exists(out / file)) << name << ": missing " << file;
    EXPECT_TRUE(fs::exists(out / name)) << name << ": the input copy is missing";
    cv::Mat pattern = cv::imread((out / "pattern.png").string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(pattern.empty()) << name;
    EXPECT_EQ(pattern.cols, 80) << name;
    EXPECT_LE(longest_run(pattern), 4) << name << ": a float longer than max_float";
  }
  // Nothing is left behind in the hot folder or the work area.
  EXPECT_TRUE(fs::is_empty(daemon.incoming("knit")));
  EXPECT_TRUE(fs::is_empty(daemon.spool() / "work"));
  EXPECT_EQ(daemon.stop(SIGTERM), 0);
}

TEST(E2EKnit, SidecarOverridesTheConfigForOneJob) {
  TempDir tmp;
  DaemonProcess daemon(tmp.path(), "[knit]\nwidth = 60\n");
  daemon.start();
  atelier::test::write_file(daemon.incoming("knit") / "pic3.png.toml",
                            "width = 90\nmax_float = 3\nsolver = \"gsat\"\n");
  atelier::test::drop_file(atelier::test::test_image("pic3.png"), daemon.incoming("knit") / "pic3.png");
  ASSERT_TRUE(daemon.wait_settled(1)) << daemon.log();
  auto job = daemon.jobs().at(0);
  ASSERT_EQ(job["state"], "completed") << job["reason"];
  fs::path out = job["output_dir"].get<std::string>();
  cv::Mat pattern = cv::imread((out / "pattern.png").string(), cv::IMREAD_GRAYSCALE);
  EXPECT_EQ(pattern.cols, 90);
  EXPECT_LE(longest_run(pattern), 3);
  std::ifstream in(out / "report.json");
  auto report = nlohmann::json::parse(in);
  EXPECT_EQ(report["solver"], "gsat");
  EXPECT_EQ(report["conflicts_after"], 0);
}

TEST(E2EKnit, BadInputsFailWithAReasonAndTheDaemonKeepsServing) {
  TempDir tmp;
  DaemonProcess daemon(tmp.path(), "[limits]\nmax_pixels = 40000000\n");
  daemon.start();
  const fs::path in = daemon.incoming("knit");
  const fs::path staging = tmp.path() / "staging";
  fs::create_directories(staging);

  // Truncated JPEG: the first half of a real photograph.
  {
    std::ifstream src(atelier::test::test_image("fruits.jpg"), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(src)), {});
    atelier::test::write_file(staging / "truncated.jpg", bytes.substr(0, bytes.size() / 2));
  }
  atelier::test::write_file(staging / "text.png", "this is not a picture\n");
  // A PNG header that claims 100000 x 100000 pixels (10^10, far over max_pixels).
  {
    std::string png = "\x89PNG\r\n\x1a\n";
    png += std::string("\0\0\0\x0dIHDR", 8);
    png += std::string("\x00\x01\x86\xa0\x00\x01\x86\xa0\x08\x02\x00\x00\x00", 13);
    png += std::string("\0\0\0\0", 4);  // CRC (not checked before the size is)
    atelier::test::write_file(staging / "huge.png", png);
  }
  atelier::test::write_file(staging / "empty.jpg", "");
  for (const char* name : {"truncated.jpg", "text.png", "huge.png", "empty.jpg"})
    atelier::test::drop_file(staging / name, in / name);
  fs::create_symlink(atelier::test::test_image("pic1.png"), in / "link.png");
  // A good image with a bad sidecar: a typo'd key.
  atelier::test::write_file(in / "pic5.png.toml", "widht = 50\n");
  atelier::test::drop_file(atelier::test::test_image("pic5.png"), in / "pic5.png");
  // A file outside any kind folder, and one in a folder of an unknown kind.
  atelier::test::drop_file(atelier::test::test_image("pic1.png"), daemon.spool() / "incoming" / "loose.png");
  fs::create_directories(daemon.spool() / "incoming" / "pottery");
  atelier::test::drop_file(atelier::test::test_image("pic1.png"),
                           daemon.spool() / "incoming" / "pottery" / "vase.png");

  ASSERT_TRUE(daemon.wait_settled(8)) << daemon.log();
  auto jobs = by_name(daemon.jobs());
  const std::map<std::string, std::vector<std::string>> expected = {
      {"truncated.jpg", {"truncated.jpg", "truncated"}},
      {"text.png", {"text.png", "not an image"}},
      {"huge.png", {"huge.png", "100000x100000"}},
      {"empty.jpg", {"empty.jpg", "empty"}},
      {"link.png", {"link.png", "symbolic link"}},
      {"pic5.png", {"pic5.png.toml", "widht"}},
      {"loose.png", {"loose.png", "incoming/<kind>/"}},
      {"vase.png", {"vase.png", "unknown kind 'pottery'"}},
  };
  for (const auto& [name, needles] : expected) {
    ASSERT_TRUE(jobs.count(name)) << name << " has no job";
    const auto& job = jobs.at(name);
    EXPECT_EQ(job["state"], "failed") << name;
    const std::string reason = job["reason"];
    for (const auto& needle : needles)
      EXPECT_NE(reason.find(needle), std::string::npos) << name << ": reason '" << reason
                                                        << "' lacks '" << needle << "'";
    // The input is kept, with reason.txt beside it.
    fs::path failed = job["output_dir"].get<std::string>();
    EXPECT_TRUE(fs::exists(failed / "reason.txt")) << name;
    EXPECT_TRUE(fs::exists(fs::symlink_status(failed / name))) << name << ": input lost";
  }
  // Still serving: a good image after all that completes.
  atelier::test::drop_file(atelier::test::test_image("pic1.png"), in / "pic1.png");
  ASSERT_TRUE(daemon.wait_settled(9)) << daemon.log();
  EXPECT_EQ(by_name(daemon.jobs()).at("pic1.png")["state"], "completed");
  EXPECT_EQ(daemon.stop(SIGTERM), 0);
}

TEST(E2EKnit, KillNineMidwayLosesAndDoublesNothing) {
  TempDir tmp;
  DaemonProcess daemon(tmp.path(), "[limits]\nworkers = 2\n[knit]\nwidth = 200\n");
  daemon.start();
  const std::vector<std::string> sources = {"butterfly.jpg", "fruits.jpg", "starry_night.jpg",
                                            "HappyFish.jpg"};
  for (int i = 0; i < 20; ++i) {
    fs::path src = atelier::test::test_image(sources[i % sources.size()]);
    atelier::test::drop_file(src, daemon.incoming("knit") /
                                      ("file" + std::to_string(i) + src.extension().string()));
  }
  // Kill while some jobs are done and others are still waiting or converting.
  ASSERT_TRUE(daemon.wait_for([&] {
    int done = 0;
    for (const auto& j : daemon.jobs()) done += j["state"] == "completed";
    return done >= 3;
  })) << daemon.log();
  EXPECT_EQ(daemon.stop(SIGKILL), -SIGKILL);

  daemon.start();
  ASSERT_TRUE(daemon.wait_settled(20)) << daemon.log();
  auto jobs = daemon.jobs();
  std::map<std::string, int> seen;
  for (const auto& j : jobs) {
    seen[j["name"]]++;
    EXPECT_EQ(j["state"], "completed") << j["name"] << ": " << j["reason"];
  }
  EXPECT_EQ(jobs.size(), 20u);
  for (int i = 0; i < 20; ++i) {
    std::string ext = fs::path(sources[i % sources.size()]).extension().string();
    EXPECT_EQ(seen["file" + std::to_string(i) + ext], 1) << "file" << i;
  }
  EXPECT_TRUE(fs::is_empty(daemon.incoming("knit")));
  EXPECT_TRUE(fs::is_empty(daemon.spool() / "work"));
}

TEST(E2EKnit, PollModePicksUpFilesOnNetworkShares) {
  TempDir tmp;
  DaemonProcess daemon(tmp.path(), "");
  // The harness writes [spool] first; poll mode is switched on by rewriting the file.
  {
    std::ifstream in(daemon.config());
    std::string cfg((std::istreambuf_iterator<char>(in)), {});
    cfg.replace(cfg.find("dir = \"spool\"\n"), 14, "dir = \"spool\"\nwatch = \"poll\"\nsettle_ms = 200\n");
    atelier::test::write_file(daemon.config(), cfg);
  }
  daemon.start();
  // Written in place, slowly, without a rename: only the settle time tells it is complete.
  {
    std::ifstream src(atelier::test::test_image("pic1.png"), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(src)), {});
    std::ofstream out(daemon.incoming("knit") / "slow.png", std::ios::binary);
    out.write(bytes.data(), 1000);
    out.flush();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    out.write(bytes.data() + 1000, static_cast<std::streamsize>(bytes.size() - 1000));
  }
  ASSERT_TRUE(daemon.wait_settled(1)) << daemon.log();
  EXPECT_EQ(daemon.jobs().at(0)["state"], "completed") << daemon.jobs().at(0)["reason"];
}

TEST(E2EKnit, SubmitCancelRetryAndStatusOverTheControlSocket) {
  TempDir tmp;
  DaemonProcess daemon(tmp.path(), "[limits]\nworkers = 1\n[knit]\nwidth = 400\n");
  daemon.start();
  auto status = daemon.request("status");
  ASSERT_TRUE(status["ok"]);
  EXPECT_EQ(status["result"]["devices"].size(), 0u);
  auto devices = daemon.request("devices");
  EXPECT_TRUE(devices["ok"]);
  EXPECT_TRUE(devices["result"].empty());

  // Bad parameters are refused at once, naming the key.
  auto bad = daemon.request("submit", {{"path", atelier::test::test_image("pic1.png").string()},
                                       {"kind", "knit"}, {"set", {"max_float=banana"}}});
  EXPECT_FALSE(bad["ok"]);
  EXPECT_NE(bad["error"].get<std::string>().find("max_float"), std::string::npos);

  // Three jobs on one worker: the last is still queued when we cancel it.
  std::vector<int> ids;
  for (const char* img : {"starry_night.jpg", "fruits.jpg", "butterfly.jpg"}) {
    auto r = daemon.request("submit", {{"path", atelier::test::test_image(img).string()},
                                       {"kind", "knit"}, {"set", {"solver=gsat"}}});
    ASSERT_TRUE(r["ok"]) << r;
    ids.push_back(r["result"]["id"]);
  }
  auto canceled = daemon.request("cancel", {{"id", ids[2]}});
  ASSERT_TRUE(canceled["ok"]) << canceled;
  EXPECT_EQ(canceled["result"]["state"], "canceled");
  ASSERT_TRUE(daemon.wait_settled(3)) << daemon.log();
  auto retried = daemon.request("retry", {{"id", ids[2]}});
  ASSERT_TRUE(retried["ok"]) << retried;
  ASSERT_TRUE(daemon.wait_settled(3)) << daemon.log();
  auto show = daemon.request("show", {{"id", ids[2]}});
  ASSERT_TRUE(show["ok"]);
  EXPECT_EQ(show["result"]["state"], "completed");
  std::vector<std::string> path;
  for (const auto& h : show["result"]["history"]) path.push_back(h["to"]);
  EXPECT_EQ(path, (std::vector<std::string>{"queued", "canceled", "queued", "converting", "completed"}));
  // The user's own file is never moved by submit.
  EXPECT_TRUE(fs::exists(atelier::test::test_image("butterfly.jpg")));
  // Nothing to start: no device is configured.
  auto start = daemon.request("start", {{"id", ids[0]}});
  EXPECT_FALSE(start["ok"]);
  EXPECT_EQ(daemon.stop(SIGTERM), 0);
}

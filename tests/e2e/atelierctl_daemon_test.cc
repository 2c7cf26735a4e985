// End to end: the built atelierctl against the real atelierd (and the laser emulator), for what
// an operator sees: a cut list that says so, cancel --all, confirmations that show the job
// after the command took effect, devices and show while a laser job runs, watch lines stamped
// with their own time, and a watch that outlives a daemon restart.
#include <gtest/gtest.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/e2e/daemon_harness.h"

namespace fs = std::filesystem;
using atelier::test::BackgroundProcess;
using atelier::test::CommandResult;
using atelier::test::DaemonProcess;
using atelier::test::TempDir;
using nlohmann::json;

namespace {

fs::path svg(const std::string& name) { return atelier::test::test_image("svg/" + name); }

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

CommandResult ctl(const DaemonProcess& daemon, std::vector<std::string> args) {
  args.insert(args.begin(), {atelier::test::binary("atelierctl").string(), "--socket", daemon.socket().string()});
  return atelier::test::run_command(args);
}

std::unique_ptr<BackgroundProcess> watch(const DaemonProcess& daemon, const fs::path& log) {
  return std::make_unique<BackgroundProcess>(
      std::vector<std::string>{atelier::test::binary("atelierctl").string(), "--socket",
                               daemon.socket().string(), "watch"},
      log);
}

// The device section of a laser on `port`, which takes cut jobs and waits for `start`.
std::string laser_device(const fs::path& port) {
  return "[[device]]\nname = \"laser\"\ndriver = \"grbl\"\nport = \"" + port.string() +
         "\"\nkinds = [\"cut\"]\n";
}

}  // namespace

TEST(E2EAtelierctl, AListCutShortSaysSoAndCancelAllCancelsEveryUnfinishedJob) {
  TempDir tmp;
  // A laser that is not plugged in: converted cut jobs wait in `ready`.
  DaemonProcess daemon(tmp.path(), laser_device(tmp.path() / "no-laser"));
  daemon.start();
  for (const char* name : {"a.svg", "b.svg", "c.svg"})
    atelier::test::drop_file(svg("sample-box.svg"), daemon.incoming("cut") / name);
  ASSERT_TRUE(daemon.wait_for([&] {
    const json jobs = daemon.jobs();
    return jobs.size() == 3 &&
           std::all_of(jobs.begin(), jobs.end(), [](const json& j) { return j["state"] == "ready"; });
  })) << daemon.log();

  CommandResult r = ctl(daemon, {"list", "--limit", "2"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(lines_of(r.out).size(), 3u) << r.out;  // the title and the 2 newest
  EXPECT_NE(r.out.find("c.svg"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("a.svg"), std::string::npos) << r.out;
  EXPECT_EQ(r.err, "showing 2 of 3 jobs; --all for every job\n");
  r = ctl(daemon, {"list", "--all"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(lines_of(r.out).size(), 4u) << r.out;
  EXPECT_EQ(r.err, "");

  r = ctl(daemon, {"list", "--kind", "bogus"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("cut"), std::string::npos) << r.err;  // the kinds this daemon converts

  r = ctl(daemon, {"cancel", "--all"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("canceled 3 jobs"), std::string::npos) << r.out;
  for (const json& j : daemon.jobs()) EXPECT_EQ(j["state"], "canceled") << j.dump();
  r = ctl(daemon, {"cancel", "--all"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "no unfinished jobs to cancel\n");
}

TEST(E2EAtelierctl, ALaserJobTellsTheOperatorWhatHappensAsItHappens) {
  TempDir tmp;
  const fs::path link = tmp.path() / "laser";
  // Slowed down so that the burn lasts a few seconds.
  BackgroundProcess emulator({atelier::test::binary("atelier-laser-emu").string(), "--link", link.string(),
                              "--time-scale", "0.3"},
                             tmp.path() / "emu.log");
  for (int i = 0; i < 100 && !fs::exists(link); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  DaemonProcess daemon(tmp.path(), laser_device(link));
  daemon.start();
  auto device = [&] { return daemon.request("devices")["result"][0]; };
  ASSERT_TRUE(daemon.wait_for([&] { return device()["state"] == "online"; }, std::chrono::seconds(10)));
  atelier::test::drop_file(svg("sample-box.svg"), daemon.incoming("cut") / "box.svg");
  ASSERT_TRUE(daemon.wait_job_state("box.svg", "ready")) << daemon.log();
  const std::string id = std::to_string(daemon.job_named("box.svg")["id"].get<int>());

  CommandResult r = ctl(daemon, {"show", id});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("estimated:"), std::string::npos) << r.out;  // from its report.json

  // The knitting options are refused clearly, and the job stays ready for a plain start.
  r = ctl(daemon, {"start", id, "--from-row", "3"});
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.err.find("job " + id + ": laser is not a knitting machine; --from-row and --start-needle are for knit"),
            std::string::npos) << r.err;
  EXPECT_EQ(daemon.job_named("box.svg")["state"], "ready");

  auto watcher = watch(daemon, tmp.path() / "watch.log");
  // Confirmed as it is after the start: running, not the waiting reason from before.
  r = ctl(daemon, {"start", id});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("job " + id + " box.svg: running", 0), 0u) << r.out;
  EXPECT_EQ(r.out.find("waiting for"), std::string::npos) << r.out;

  ASSERT_TRUE(daemon.wait_for([&] {
    const json j = device()["job"];
    return j.is_object() && j["progress"]["done"].get<int>() > 0;
  }, std::chrono::seconds(20))) << daemon.log();
  r = ctl(daemon, {"devices"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("lines)"), std::string::npos) << r.out;  // lines of G-code, not rows
  EXPECT_EQ(r.out.find("rows"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("DETAIL"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" left"), std::string::npos) << r.out;  // the time left, in DETAIL
  r = ctl(daemon, {"show", id});
  EXPECT_NE(r.out.find("time left:"), std::string::npos) << r.out;

  r = ctl(daemon, {"hold", id});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("running (held at line "), std::string::npos) << r.out;
  r = ctl(daemon, {"devices"});
  EXPECT_NE(r.out.find("held"), std::string::npos) << r.out;
  // Held long enough that the progress after it comes in a later second than the one before.
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  r = ctl(daemon, {"resume", id});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("running, resumed"), std::string::npos) << r.out;
  ASSERT_TRUE(daemon.wait_job_state("box.svg", "completed")) << daemon.log();
  r = ctl(daemon, {"devices"});
  EXPECT_NE(r.out.find("ran "), std::string::npos) << r.out;  // LAST: how the job ended

  // Each progress line carries the time of its own step, not the job's last state change.
  ASSERT_TRUE(daemon.wait_for([&] {
    return atelier::test::read_file(tmp.path() / "watch.log").find("-> completed") != std::string::npos;
  }, std::chrono::seconds(10)));
  watcher->stop();
  std::set<std::string> stamps;
  for (const std::string& line : lines_of(atelier::test::read_file(tmp.path() / "watch.log")))
    if (line.find(": running, line ") != std::string::npos) stamps.insert(line.substr(0, 19));
  EXPECT_GE(stamps.size(), 2u) << atelier::test::read_file(tmp.path() / "watch.log");
}

TEST(E2EAtelierctl, WatchCarriesOnAcrossADaemonRestart) {
  TempDir tmp;
  DaemonProcess daemon(tmp.path());
  daemon.start();
  const fs::path log = tmp.path() / "watch.log";
  auto watcher = watch(daemon, log);
  atelier::test::drop_file(svg("sample-box.svg"), daemon.incoming("cut") / "before.svg");
  ASSERT_TRUE(daemon.wait_for([&] { return atelier::test::read_file(log).find("before.svg") != std::string::npos; },
                              std::chrono::seconds(30)))
      << atelier::test::read_file(log);
  ASSERT_EQ(daemon.stop(), 0);
  daemon.start();
  ASSERT_TRUE(daemon.wait_for([&] { return atelier::test::read_file(log).find("reconnected") != std::string::npos; },
                              std::chrono::seconds(30)))
      << atelier::test::read_file(log);
  atelier::test::drop_file(svg("sample-box.svg"), daemon.incoming("cut") / "after.svg");
  EXPECT_TRUE(daemon.wait_for([&] { return atelier::test::read_file(log).find("after.svg") != std::string::npos; },
                              std::chrono::seconds(30)))
      << atelier::test::read_file(log);
  const std::string text = atelier::test::read_file(log);
  EXPECT_NE(text.find("daemon gone, reconnecting"), std::string::npos) << text;
  watcher->stop();
}

// End to end: atelierd cuts SVGs on the GRBL laser emulator (a pseudo-terminal), and the
// emulator's record of what the beam did is compared with what the SVG asked for.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>

#include <algorithm>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "drivers/serial_transport.h"
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

double now_s() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

fs::path svg(const std::string& name) { return atelier::test::test_image("svg/" + name); }

struct LaserRig {
  TempDir tmp;
  fs::path link = tmp.path() / "laser";
  fs::path record = tmp.path() / "record.json";
  fs::path render = tmp.path() / "burn.png";
  std::unique_ptr<BackgroundProcess> emulator;
  std::unique_ptr<DaemonProcess> daemon;

  LaserRig(std::vector<std::string> emu_args, const std::string& toml = "", double time_scale = 0.02) {
    std::vector<std::string> argv = {atelier::test::binary("atelier-laser-emu").string(),
                                     "--link", link.string(), "--record", record.string(),
                                     "--render", render.string(), "--px-per-mm", "5",
                                     "--time-scale", std::to_string(time_scale)};
    argv.insert(argv.end(), emu_args.begin(), emu_args.end());
    emulator = std::make_unique<BackgroundProcess>(argv, tmp.path() / "emu.log");
    for (int i = 0; i < 100 && !fs::exists(link); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    daemon = std::make_unique<DaemonProcess>(
        tmp.path(), toml + "[[device]]\nname = \"laser\"\ndriver = \"grbl\"\nport = \"" + link.string() +
                        "\"\nkinds = [\"cut\"]\n");
    daemon->start();
  }

  json job(const std::string& name) {
    for (const auto& j : daemon->jobs())
      if (j["name"] == name) return j;
    return nullptr;
  }
  bool wait_state(const std::string& name, const std::string& state,
                  std::chrono::milliseconds timeout = std::chrono::seconds(60)) {
    return daemon->wait_for([&] {
      auto j = job(name);
      return !j.is_null() && j["state"] == state;
    }, timeout);
  }
  json device() { return daemon->request("devices")["result"][0]; }
  // Sends `$n=v` settings to the controller as its owner would at the machine (before the
  // daemon's first job or command: it opens the port on first need and keeps it).
  void configure_controller(const std::vector<std::string>& settings) {
    auto port = atelier::SerialTransport::open(link.string());
    std::string got;
    uint8_t buf[256];
    auto read_until = [&](const std::string& what) {
      const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
      while (got.find(what) == std::string::npos && std::chrono::steady_clock::now() < until) {
        size_t n = port->read(buf, sizeof buf, std::chrono::milliseconds(50));
        got.append(reinterpret_cast<char*>(buf), n);
      }
      ASSERT_NE(got.find(what), std::string::npos) << got;
      got.erase(0, got.find(what) + what.size());
    };
    port->write(reinterpret_cast<const uint8_t*>("\x18"), 1);
    read_until("Grbl 1.1");
    for (const auto& s : settings) {
      const std::string line = s + "\n";
      port->write(reinterpret_cast<const uint8_t*>(line.data()), line.size());
      read_until("ok\r\n");
    }
    port->close();
  }
  json ctl(const std::string& verb, const json& id) { return daemon->request(verb, {{"id", id}}); }
  // Runs `atelierctl ARGS...` against the daemon, as an operator at the terminal would.
  atelier::test::CommandResult atelierctl(std::vector<std::string> args) {
    args.insert(args.begin(), {atelier::test::binary("atelierctl").string(), "--socket", daemon->socket().string()});
    return atelier::test::run_command(args);
  }
  // Stops the emulator (it writes its record and render on SIGTERM) and reads the record.
  json finish() {
    emulator->stop();
    std::ifstream in(record);
    return json::parse(in);
  }
};

// Whether a record segment burned (beam on while moving).
bool burned(const json& s) { return s["power"].get<double>() > 0; }

// The drawing's strokes as the render draws them: machine X = x, Y = 400 - y (front-left
// origin), pixel (X * ppm, (400 - Y) * ppm), i.e. the SVG's own coordinates scaled.
cv::Mat intended_mask(const fs::path& file) {
  cv::Mat mask(static_cast<int>(kWorkMm * kPxPerMm), static_cast<int>(kWorkMm * kPxPerMm), CV_8U, cv::Scalar(0));
  atelier::test::draw_strokes(file, kPxPerMm, mask);
  return mask;
}

}  // namespace

TEST(E2ELaser, ACutJobWaitsForTheOperatorFramesThenBurnsWhatTheSvgShows) {
  LaserRig rig({}, "[laser]\ncheck_first = true\n");
  ASSERT_TRUE(rig.daemon->wait_for([&] { return rig.device()["state"] == "online"; }, std::chrono::seconds(10)));
  atelier::test::drop_file(svg("sample-box.svg"), rig.daemon->incoming("cut") / "box.svg");
  ASSERT_TRUE(rig.wait_state("box.svg", "ready")) << rig.daemon->log();
  const json id = rig.job("box.svg")["id"];

  // A laser job never starts without the operator: still ready a second later, saying how.
  std::this_thread::sleep_for(std::chrono::seconds(1));
  EXPECT_EQ(rig.job("box.svg")["state"], "ready");
  EXPECT_NE(rig.job("box.svg")["reason"].get<std::string>().find("atelierctl start " + id.dump()),
            std::string::npos) << rig.job("box.svg")["reason"];

  // Framing traces the outline with the beam off and leaves the job ready.
  ASSERT_TRUE(rig.ctl("frame", id)["ok"]);
  ASSERT_TRUE(rig.daemon->wait_for([&] {
    return rig.device()["last"].get<std::string>().find("framed") != std::string::npos;
  }, std::chrono::seconds(30))) << rig.device().dump() << rig.daemon->log();
  EXPECT_EQ(rig.job("box.svg")["state"], "ready");

  ASSERT_TRUE(rig.ctl("start", id)["ok"]);
  ASSERT_TRUE(rig.wait_state("box.svg", "completed")) << rig.job("box.svg").dump() << rig.daemon->log();
  auto job = rig.job("box.svg");
  EXPECT_EQ(job["progress"]["done"], job["progress"]["total"]);
  EXPECT_GT(job["progress"]["total"].get<int>(), 10);
  // The job's story in the log: waiting for the operator, framed, armed, run, done; the
  // burn's progress in at most nine lines.
  const std::string tag = "job " + id.dump() + " (cut";
  const std::vector<std::string> story = rig.daemon->job_log(id.get<int>());
  auto told = [&](const std::string& line) { return std::find(story.begin(), story.end(), line) != story.end(); };
  EXPECT_TRUE(told(tag + "): ready: converted; waiting for laser and `atelierctl start " + id.dump() + "`"))
      << rig.daemon->log();
  EXPECT_TRUE(told(tag + ", laser): framed with the beam off")) << rig.daemon->log();
  EXPECT_TRUE(told(tag + ", laser): armed by atelierctl start")) << rig.daemon->log();
  EXPECT_TRUE(told(tag + ", laser): running on laser")) << rig.daemon->log();
  ASSERT_FALSE(story.empty());
  EXPECT_EQ(story.back().rfind(tag + ", laser): completed: ran " + job["progress"]["total"].dump() + " G-code lines on laser", 0), 0u)
      << story.back();
  const auto progress = std::count_if(story.begin(), story.end(), [&](const std::string& l) {
    return l.find(", laser): ") != std::string::npos && l.find(" %: line ") != std::string::npos;
  });
  EXPECT_GE(progress, 1);
  EXPECT_LE(progress, 9) << rig.daemon->log();

  const json rec = rig.finish();
  EXPECT_EQ(rec["rx_overflows"], 0) << "the receive buffer overflowed: a real job would be corrupted";
  EXPECT_LE(rec["max_rx_bytes"].get<int>(), 128);
  EXPECT_EQ(rec["errors"], 0);
  // The frame moved with the beam off: its segments came before the first burn.
  size_t travel_before_burn = 0;
  for (const auto& s : rec["segments"]) {
    if (burned(s)) break;
    ++travel_before_burn;
  }
  EXPECT_GE(travel_before_burn, 4u);

  cv::Mat render = cv::imread(rig.render.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(render.empty());
  ASSERT_EQ(render.cols, static_cast<int>(kWorkMm * kPxPerMm));
  cv::Mat burnt = render < 200;
  cv::Mat intended = intended_mask(svg("sample-box.svg"));
  ASSERT_GT(cv::countNonZero(intended), 500);
  EXPECT_GT(atelier::test::covered(burnt, intended, 2), 0.95) << "burned where the drawing has no stroke";
  EXPECT_GT(atelier::test::covered(intended, burnt, 2), 0.95) << "a stroke of the drawing was not burned";
}

// Cancels the job `name` once `min_done` lines are acknowledged and it has burned a little
// longer; returns how long after the request the beam still burned (seconds) and leaves the
// job's reason in `reason`.
double cancel_mid_job(LaserRig& rig, const std::string& name, int min_done, std::string& reason) {
  const json id = rig.job(name)["id"];
  EXPECT_TRUE(rig.ctl("start", id)["ok"]);
  EXPECT_TRUE(rig.daemon->wait_for([&] {
    auto j = rig.job(name);
    return j["state"] == "running" && j["progress"]["done"].get<int>() >= min_done;
  }, std::chrono::seconds(30))) << rig.job(name).dump();
  // Lines are acknowledged as the planner takes them, long before the head gets there (a
  // travel at 10 mm/s^2 takes seconds): wait for the emulator's record (saved every 0.5 s
  // while it moves) to show the beam burning.
  EXPECT_TRUE(rig.daemon->wait_for([&] {
    std::ifstream in(rig.record);
    const json rec = json::parse(in, nullptr, false);
    if (rec.is_discarded()) return false;
    for (const auto& s : rec["segments"])
      if (burned(s)) return true;
    return false;
  }, std::chrono::seconds(30))) << rig.job(name).dump();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));

  const double asked = now_s();
  EXPECT_TRUE(rig.ctl("cancel", id)["ok"]);
  EXPECT_TRUE(rig.wait_state(name, "canceled", std::chrono::seconds(10))) << rig.job(name).dump();
  reason = rig.job(name)["reason"];

  const json rec = rig.finish();
  double last_burn = 0;
  size_t burns_before = 0;
  for (const auto& s : rec["segments"]) {
    if (!burned(s)) continue;
    last_burn = std::max(last_burn, s["t1"].get<double>());
    if (s["t0"].get<double>() < asked) ++burns_before;
  }
  EXPECT_GT(burns_before, 0u) << "the job had not started burning when it was canceled";
  EXPECT_EQ(rec["rx_overflows"], 0);
  std::cout << "beam off " << (last_burn - asked) * 1000 << " ms after the cancel request\n";
  return last_burn - asked;
}

const char* kSlowCutLayers =
    "[[laser.layer]]\ncolor = \"#000000\"\nmode = \"cut\"\nspeed_mm_min = 300\npower_pct = 60\n"
    "[[laser.layer]]\ncolor = \"#ff0000\"\nmode = \"cut\"\n"
    "[[laser.layer]]\ncolor = \"#0000ff\"\nmode = \"engrave\"\nspeed_mm_min = 600\npower_pct = 20\n";

TEST(E2ELaser, CancelMidJobTurnsTheBeamOffWithin100MillisecondsAndKeepsThePosition) {
  // A laser's brisk acceleration (500 mm/s^2): the feed hold brings the head to rest in time,
  // and the reset at rest keeps the position.
  LaserRig rig({}, kSlowCutLayers, 0.25);
  atelier::test::drop_file(svg("sample-box.svg"), rig.daemon->incoming("cut") / "box.svg");
  ASSERT_TRUE(rig.wait_state("box.svg", "ready")) << rig.daemon->log();
  std::string reason;
  EXPECT_LT(cancel_mid_job(rig, "box.svg", 20, reason), 0.1);
  EXPECT_NE(reason.find("beam is off and the position kept"), std::string::npos) << reason;
}

TEST(E2ELaser, CancelAtGrblsStockAccelerationStillTurnsTheBeamOffWithin100Milliseconds) {
  // GRBL's stock 10 mm/s^2 would take a second to stop: the driver resets mid-motion instead,
  // and says the position may be lost.
  LaserRig rig({}, kSlowCutLayers, 1.0);
  rig.configure_controller({"$120=10", "$121=10"});
  // One long cut near the origin (76 s at 300 mm/min): the cancel always finds the head
  // mid-block at 5 mm/s, half a second from rest at 10 mm/s^2.
  const fs::path line = rig.tmp.path() / "line.svg";
  atelier::test::write_file(line, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"400mm\" height=\"400mm\" "
                                  "viewBox=\"0 0 400 400\"><path d=\"M 10 390 L 390 390\" stroke=\"#000000\" "
                                  "fill=\"none\"/></svg>\n");
  atelier::test::drop_file(line, rig.daemon->incoming("cut") / "line.svg");
  ASSERT_TRUE(rig.wait_state("line.svg", "ready")) << rig.daemon->log();
  std::string reason;
  EXPECT_LT(cancel_mid_job(rig, "line.svg", 3, reason), 0.1);
  EXPECT_NE(reason.find("position may be lost"), std::string::npos) << reason;
}

TEST(E2ELaser, KillingTheDaemonMidJobTurnsTheBeamOffWithin50Milliseconds) {
  // The daemon dies (kill -9) while the laser burns one long cut (76 s at 300 mm/min, all of
  // it queued in the controller): the kernel closes the port, which drops DTR, and the board
  // restarts - beam off - instead of burning out its queue unattended.
  LaserRig rig({}, kSlowCutLayers, 1.0);
  const fs::path line = rig.tmp.path() / "line.svg";
  atelier::test::write_file(line, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"400mm\" height=\"400mm\" "
                                  "viewBox=\"0 0 400 400\"><path d=\"M 10 390 L 390 390\" stroke=\"#000000\" "
                                  "fill=\"none\"/></svg>\n");
  atelier::test::drop_file(line, rig.daemon->incoming("cut") / "line.svg");
  ASSERT_TRUE(rig.wait_state("line.svg", "ready")) << rig.daemon->log();
  ASSERT_TRUE(rig.ctl("start", rig.job("line.svg")["id"])["ok"]);
  // Burning: the emulator's record (saved every 0.5 s while it moves) shows the beam on.
  ASSERT_TRUE(rig.daemon->wait_for([&] {
    std::ifstream in(rig.record);
    const json rec = json::parse(in, nullptr, false);
    if (rec.is_discarded()) return false;
    for (const auto& s : rec["segments"])
      if (burned(s)) return true;
    return false;
  }, std::chrono::seconds(30))) << rig.job("line.svg").dump() << rig.daemon->log();

  // The box is shared: give the processes under test priority (where allowed), so what is
  // measured is the daemon's death and the emulator's answer to it, not other load.
  for (const pid_t pid : {rig.daemon->pid(), rig.emulator->pid()})
    for (const auto& task : fs::directory_iterator("/proc/" + std::to_string(pid) + "/task"))
      ::setpriority(PRIO_PROCESS, static_cast<id_t>(std::stoi(task.path().filename().string())), -10);
  const double killed = now_s();
  rig.daemon->stop(SIGKILL);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // what the beam does next is recorded
  const json rec = rig.finish();

  double last_burn = 0, hangup = 0;
  for (const auto& s : rec["segments"])
    if (burned(s)) last_burn = std::max(last_burn, s["t1"].get<double>());
  for (const auto& e : rec["events"])
    if (e["event"] == "hangup") hangup = e["t"].get<double>();
  ASSERT_GT(hangup, 0) << "the emulator never saw the port close: " << rec["events"].dump();
  EXPECT_GE(hangup, killed - 0.001);
  EXPECT_GE(last_burn, killed - 0.001) << "the beam was not burning when the daemon was killed";
  std::cout << "beam off " << (last_burn - killed) * 1000 << " ms after kill -9 (hangup seen after "
            << (hangup - killed) * 1000 << " ms)\n";
  EXPECT_LT(last_burn - killed, 0.050);
}

TEST(E2ELaser, AnAlarmFailsTheJobWithItsMeaning) {
  LaserRig rig({"--fault", "alarm-at-line=15:1"});
  atelier::test::drop_file(svg("sample-box.svg"), rig.daemon->incoming("cut") / "box.svg");
  ASSERT_TRUE(rig.wait_state("box.svg", "ready")) << rig.daemon->log();
  ASSERT_TRUE(rig.ctl("start", rig.job("box.svg")["id"])["ok"]);
  ASSERT_TRUE(rig.wait_state("box.svg", "failed")) << rig.job("box.svg").dump();
  const std::string reason = rig.job("box.svg")["reason"];
  EXPECT_NE(reason.find("ALARM:1"), std::string::npos) << reason;
  EXPECT_NE(reason.find("imit"), std::string::npos) << reason;  // "Hard limit"
}

TEST(E2ELaser, AGcodeErrorFailsTheJobNamingTheLineAndTheMeaning) {
  LaserRig rig({});
  atelier::test::drop_file(svg("sample-box.svg"), rig.daemon->incoming("cut") / "box.svg");
  ASSERT_TRUE(rig.wait_state("box.svg", "ready")) << rig.daemon->log();
  auto job = rig.job("box.svg");
  // Someone edits the ready job's G-code by hand and leaves a bad line in it.
  const fs::path gcode = fs::path(job["output_dir"].get<std::string>()) / "job.gcode";
  std::ifstream in(gcode);
  std::stringstream text;
  text << in.rdbuf();
  std::string edited = text.str();
  const size_t at = edited.find("\nG1");
  ASSERT_NE(at, std::string::npos);
  edited.insert(at + 1, "G1 X10 Y10 Q5\n");
  atelier::test::write_file(gcode, edited);

  ASSERT_TRUE(rig.ctl("start", job["id"])["ok"]);
  ASSERT_TRUE(rig.wait_state("box.svg", "failed")) << rig.job("box.svg").dump();
  const std::string reason = rig.job("box.svg")["reason"];
  EXPECT_NE(reason.find("error:20"), std::string::npos) << reason;
  EXPECT_NE(reason.find("Q5"), std::string::npos) << reason;
  const json rec = rig.finish();
  EXPECT_EQ(rec["rx_overflows"], 0);
}

TEST(E2ELaser, ALostLinkInterruptsTheJobAndNothingMovesAgainUntilAnOperatorActs) {
  LaserRig rig({"--fault", "drop-at-line=25", "--replug-ms", "800"});
  atelier::test::drop_file(svg("sample-box.svg"), rig.daemon->incoming("cut") / "box.svg");
  ASSERT_TRUE(rig.wait_state("box.svg", "ready")) << rig.daemon->log();
  ASSERT_TRUE(rig.ctl("start", rig.job("box.svg")["id"])["ok"]);
  ASSERT_TRUE(rig.wait_state("box.svg", "interrupted")) << rig.job("box.svg").dump();
  const std::string reason = rig.job("box.svg")["reason"];
  EXPECT_NE(reason.find("retry"), std::string::npos) << reason;

  // The controller comes back: the device is online again, and the job stays interrupted.
  ASSERT_TRUE(rig.daemon->wait_for([&] { return rig.device()["state"] == "online"; }, std::chrono::seconds(15)))
      << rig.device().dump();
  const double back = now_s();
  std::this_thread::sleep_for(std::chrono::seconds(2));
  EXPECT_EQ(rig.job("box.svg")["state"], "interrupted");
  const json rec = rig.finish();
  for (const auto& s : rec["segments"]) EXPECT_LT(s["t0"].get<double>(), back) << s.dump();
}

TEST(E2ELaser, AJobBeyondTheMachinesTravelFailsBeforeAnythingIsSent) {
  // The config believes in a 400 mm bed; the controller's travel is 100 x 100 mm.
  LaserRig rig({"--work-area", "100x100"});
  atelier::test::drop_file(svg("sample-box.svg"), rig.daemon->incoming("cut") / "box.svg");
  ASSERT_TRUE(rig.wait_state("box.svg", "ready")) << rig.daemon->log();
  ASSERT_TRUE(rig.ctl("start", rig.job("box.svg")["id"])["ok"]);
  ASSERT_TRUE(rig.wait_state("box.svg", "failed")) << rig.job("box.svg").dump();
  const std::string reason = rig.job("box.svg")["reason"];
  EXPECT_NE(reason.find("travel"), std::string::npos) << reason;
  const json rec = rig.finish();
  EXPECT_TRUE(rec["segments"].empty()) << rec["segments"].dump();
}

TEST(E2ELaser, ASilentControllerInterruptsTheJobWithoutHangingTheDevice) {
  LaserRig rig({"--fault", "stall-at-line=30"});
  atelier::test::drop_file(svg("sample-box.svg"), rig.daemon->incoming("cut") / "box.svg");
  ASSERT_TRUE(rig.wait_state("box.svg", "ready")) << rig.daemon->log();
  ASSERT_TRUE(rig.ctl("start", rig.job("box.svg")["id"])["ok"]);
  // The driver gives a controller 10 s of silence before it gives up on it.
  ASSERT_TRUE(rig.wait_state("box.svg", "interrupted", std::chrono::seconds(40))) << rig.job("box.svg").dump();
  const std::string reason = rig.job("box.svg")["reason"];
  EXPECT_NE(reason.find("stopped answering"), std::string::npos) << reason;
  EXPECT_NE(reason.find("retry"), std::string::npos) << reason;
  EXPECT_TRUE(rig.daemon->wait_for([&] { return rig.device()["job"].is_null(); }, std::chrono::seconds(5)))
      << rig.device().dump();
}

// A small square cut near the bed's front-left corner (x 10..30, y 10..30 mm in bed coordinates).
void write_square(const fs::path& file) {
  atelier::test::write_file(file, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"400mm\" height=\"400mm\" "
                                  "viewBox=\"0 0 400 400\"><path d=\"M 10 370 L 30 370 L 30 390 L 10 390 Z\" "
                                  "stroke=\"#ff0000\" fill=\"none\"/></svg>\n");
}

TEST(E2ELaser, AfterACancelInMotionLaserUnlockLetsTheNextJobComplete) {
  // GRBL's stock 10 mm/s^2: the cancel resets a moving head, which leaves the ALARM:3 lock
  // (the position may be lost). The operator unlocks it from atelierctl, and the next job runs.
  LaserRig rig({}, kSlowCutLayers, 0.25);
  rig.configure_controller({"$120=10", "$121=10"});
  const fs::path line = rig.tmp.path() / "line.svg";
  atelier::test::write_file(line, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"400mm\" height=\"400mm\" "
                                  "viewBox=\"0 0 400 400\"><path d=\"M 10 390 L 390 390\" stroke=\"#000000\" "
                                  "fill=\"none\"/></svg>\n");
  atelier::test::drop_file(line, rig.daemon->incoming("cut") / "line.svg");
  ASSERT_TRUE(rig.wait_state("line.svg", "ready")) << rig.daemon->log();
  const json id = rig.job("line.svg")["id"];
  ASSERT_TRUE(rig.ctl("start", id)["ok"]);
  ASSERT_TRUE(rig.daemon->wait_for([&] {
    auto j = rig.job("line.svg");
    return j["state"] == "running" && j["progress"]["done"].get<int>() >= 3;
  }, std::chrono::seconds(30))) << rig.job("line.svg").dump();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ASSERT_TRUE(rig.ctl("cancel", id)["ok"]);
  ASSERT_TRUE(rig.wait_state("line.svg", "canceled", std::chrono::seconds(10))) << rig.job("line.svg").dump();
  ASSERT_NE(rig.job("line.svg")["reason"].get<std::string>().find("position may be lost"), std::string::npos)
      << rig.job("line.svg")["reason"];

  const auto unlock = rig.atelierctl({"laser", "unlock"});
  ASSERT_EQ(unlock.exit_code, 0) << unlock.out << unlock.err;
  EXPECT_NE(unlock.out.find("> $X"), std::string::npos) << unlock.out;
  EXPECT_NE(unlock.out.find("[MSG:Caution: Unlocked]"), std::string::npos) << unlock.out;
  EXPECT_NE(unlock.out.find("ok"), std::string::npos) << unlock.out;
  // The console log in the job store has it, with its reply.
  const auto log = rig.atelierctl({"laser", "log", "--lines", "5"});
  ASSERT_EQ(log.exit_code, 0) << log.err;
  EXPECT_NE(log.out.find("laser  uid " + std::to_string(::getuid()) + "> $X"), std::string::npos) << log.out;
  EXPECT_NE(log.out.find("  [MSG:Caution: Unlocked]"), std::string::npos) << log.out;

  const fs::path square = rig.tmp.path() / "square.svg";
  write_square(square);
  atelier::test::drop_file(square, rig.daemon->incoming("cut") / "square.svg");
  ASSERT_TRUE(rig.wait_state("square.svg", "ready")) << rig.daemon->log();
  ASSERT_TRUE(rig.ctl("start", rig.job("square.svg")["id"])["ok"]);
  ASSERT_TRUE(rig.wait_state("square.svg", "completed")) << rig.job("square.svg").dump() << rig.daemon->log();
}

TEST(E2ELaser, StartFromHereAfterAJogBurnsTheJobOffsetByTheJog) {
  // Homing and soft limits off (as the test needs them, whatever the emulator's stock): the
  // power-up position is the bed's corner, and the head is jogged from there.
  LaserRig rig({});
  rig.configure_controller({"$20=0", "$22=0"});
  const fs::path square = rig.tmp.path() / "square.svg";
  write_square(square);
  atelier::test::drop_file(square, rig.daemon->incoming("cut") / "square.svg");
  ASSERT_TRUE(rig.wait_state("square.svg", "ready")) << rig.daemon->log();
  const json id = rig.job("square.svg")["id"];

  const auto jog = rig.atelierctl({"laser", "jog", "--x", "50", "--y", "30", "--feed", "3000"});
  ASSERT_EQ(jog.exit_code, 0) << jog.out << jog.err;
  EXPECT_NE(jog.out.find("> $J=G91G21X50.000Y30.000F3000"), std::string::npos) << jog.out;
  // The console refuses a real-time byte and several lines, with nothing sent.
  const auto realtime = rig.atelierctl({"laser", "send", "!"});
  EXPECT_EQ(realtime.exit_code, 1);
  EXPECT_NE(realtime.err.find("real-time"), std::string::npos) << realtime.err;
  const auto two = rig.atelierctl({"laser", "send", "G0X1\nG0X2"});
  EXPECT_EQ(two.exit_code, 1);
  EXPECT_NE(two.err.find("several lines"), std::string::npos) << two.err;

  const json started = rig.daemon->request("start", {{"id", id}, {"start_from", "here"}});
  ASSERT_TRUE(started["ok"]) << started.dump();
  ASSERT_TRUE(rig.wait_state("square.svg", "completed")) << rig.job("square.svg").dump() << rig.daemon->log();
  const json shown = rig.daemon->request("show", {{"id", id}})["result"];
  bool placed = false;
  for (const auto& e : shown["history"])
    placed = placed || e["reason"].get<std::string>().find("start from here") != std::string::npos;
  EXPECT_TRUE(placed) << shown["history"].dump();

  // The square is burned at bed x 10..30, y 10..30 plus the jog (50, 30) in machine space.
  const json rec = rig.finish();
  double min_x = 1e9, max_x = -1e9, min_y = 1e9, max_y = -1e9;
  for (const auto& s : rec["segments"]) {
    if (!burned(s)) continue;
    for (const char* k : {"x0", "x1"}) min_x = std::min(min_x, s[k].get<double>()), max_x = std::max(max_x, s[k].get<double>());
    for (const char* k : {"y0", "y1"}) min_y = std::min(min_y, s[k].get<double>()), max_y = std::max(max_y, s[k].get<double>());
  }
  EXPECT_NEAR(min_x, 60, 0.5) << rec["segments"].dump();
  EXPECT_NEAR(max_x, 80, 0.5);
  EXPECT_NEAR(min_y, 40, 0.5);
  EXPECT_NEAR(max_y, 60, 0.5);
}

TEST(E2ELaser, AHeldJobShowsHeldAtLineNOfMEverywhereUntilResumed) {
  LaserRig rig({}, kSlowCutLayers, 0.25);
  atelier::test::drop_file(svg("sample-box.svg"), rig.daemon->incoming("cut") / "box.svg");
  ASSERT_TRUE(rig.wait_state("box.svg", "ready")) << rig.daemon->log();
  const json id = rig.job("box.svg")["id"];
  ASSERT_TRUE(rig.ctl("start", id)["ok"]);
  ASSERT_TRUE(rig.daemon->wait_for([&] {
    auto j = rig.job("box.svg");
    return j["state"] == "running" && j["progress"]["done"].get<int>() >= 10;
  }, std::chrono::seconds(30))) << rig.job("box.svg").dump();
  ASSERT_TRUE(rig.ctl("hold", id)["ok"]);
  const std::string total = rig.job("box.svg")["progress"]["total"].dump();
  // A second later (progress reports have come and gone) every view still says held.
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const std::string reason = rig.job("box.svg")["reason"];
  EXPECT_NE(reason.find("held at line "), std::string::npos) << reason;
  EXPECT_NE(reason.find(" of " + total), std::string::npos) << reason;
  const auto list = rig.atelierctl({"list"});
  EXPECT_NE(list.out.find("held at line"), std::string::npos) << list.out;
  const auto devices = rig.atelierctl({"devices"});
  EXPECT_NE(devices.out.find("held at line"), std::string::npos) << devices.out;
  // The console is refused while the job is held; nothing is sent.
  const auto send = rig.atelierctl({"laser", "send", "$$"});
  EXPECT_EQ(send.exit_code, 1);
  EXPECT_NE(send.err.find("holding job " + id.dump()), std::string::npos) << send.err;

  ASSERT_TRUE(rig.ctl("resume", id)["ok"]);
  EXPECT_TRUE(rig.daemon->wait_for([&] {
    return rig.job("box.svg")["reason"].get<std::string>().find("held") == std::string::npos;
  }, std::chrono::seconds(10))) << rig.job("box.svg").dump();
  ASSERT_TRUE(rig.wait_state("box.svg", "completed")) << rig.job("box.svg").dump();
}

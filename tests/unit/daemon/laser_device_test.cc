// The laser device against the emulator's controller model on a simulated link and a FakeClock:
// one connection kept across jobs, frames and commands (the model restarts on a reopened port,
// as an Uno does); operator commands between jobs (the console, unlock, jog) run on the
// device's worker and are logged in the store; a held job says where it is held; a sidecar's [laser] keys are the job's
// (check_first, start_from); an alarm's reason names the line and what to do.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <memory>
#include <regex>
#include <thread>

#include "base/fake_clock.h"
#include "daemon/job_service.h"
#include "daemon/laser_device.h"
#include "daemon/store.h"
#include "drivers/grbl/codes.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/laser_emu_rig.h"

namespace atelier {
namespace {

using laser_emu::testing::EmulatedLaserPeer;
using namespace std::chrono_literals;

// A short square in bed coordinates, as the converters write it.
constexpr const char* kSquare =
    "; atelier laser job\n; s_max=1000\n; bounds=10,10,30,30\nG21 G90\nM4 S0\nG0 X10 Y10\n"
    "G1 X30 Y10 F600 S800\nG1 X30 Y30\nG1 X10 Y30\nG1 X10 Y10\nM5\n";

struct LaserRig {
  test::TempDir tmp;
  SpoolLayout layout{tmp.path() / "spool"};
  Store store{tmp.path() / "jobs.sqlite"};
  FakeClock clock;
  JobService jobs{store, layout, [](const JobChange&) {}};
  laser_emu::ControllerOptions emu;
  std::shared_ptr<EmulatedLaserPeer> laser;  // one controller for the device's whole life
  std::atomic<int> opens{0};                 // times the device opened the port
  // The link opened last (valid while the device keeps it; a test may close() it).
  std::atomic<SimulatedTransport*> last_link{nullptr};
  std::unique_ptr<LaserDevice> device;

  // Like an Uno, the controller restarts whenever the port is opened again (DTR auto-reset).
  explicit LaserRig(laser_emu::ControllerOptions o = {}, LaserOptions options = {}) : emu(o) {
    jobs.ensure_layout();
    laser = std::make_shared<EmulatedLaserPeer>(clock.now(), emu);
    DeviceConfig d;
    d.name = "laser";
    d.driver = "grbl";
    d.port = "/dev/ttyLASER";
    d.kinds = {"cut"};
    device = std::make_unique<LaserDevice>(
        d, jobs,
        [this](const std::string&) {
          if (opens++ > 0) laser->reopened(clock.now());
          auto link = std::make_unique<SimulatedTransport>(laser, clock);
          last_link = link.get();
          return link;
        },
        [port = d.port]() -> std::optional<std::string> { return port; }, options, clock);
    device->start_worker();
    for (int i = 0; i < 500 && device->describe().value("state", "") != "online"; ++i)
      std::this_thread::sleep_for(2ms);
  }
  ~LaserRig() { device->stop(); }

  // A ready cut job with `gcode` as its job.gcode and, if given, `sidecar` as box.svg.toml.
  int64_t ready_job(const std::string& gcode = kSquare, const std::string& sidecar = "") {
    Job job;
    job.id = store.reserve_id();
    job.kind = "cut";
    job.name = "box.svg";
    job.state = JobState::ready;
    job.output_dir = (tmp.path() / "done" / std::to_string(job.id)).string();
    std::filesystem::create_directories(job.output_dir);
    std::ofstream(job.output_dir + "/job.gcode") << gcode;
    if (!sidecar.empty()) std::ofstream(job.output_dir + "/box.svg.toml") << sidecar;
    store.insert_job(job);
    return job.id;
  }
  // Starts `id` and waits (real time, the worker moves the fake clock) until it is no longer
  // ready or running.
  Job run(int64_t id, const StartOptions& options = {}) {
    device->start(id, options);
    for (int i = 0; i < 5000; ++i) {
      const Job j = *store.get(id);
      if (j.state != JobState::ready && j.state != JobState::running) return j;
      std::this_thread::sleep_for(2ms);
    }
    ADD_FAILURE() << "job " << id << " did not end: " << store.get(id)->reason;
    return *store.get(id);
  }
  nlohmann::json send(const std::string& line) {
    MachineCommand c;
    c.op = MachineCommand::Op::send;
    c.line = line;
    c.uid = 1000;
    return device->machine_command(c);
  }
};

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(LaserDeviceConsole, ALineSentGetsEveryReplyLineAndIsLoggedWithItsReply) {
  LaserRig rig;
  const nlohmann::json answer = rig.send("$I");
  ASSERT_EQ(answer["lines"].size(), 1u) << answer.dump();
  EXPECT_EQ(answer["lines"][0]["sent"], "$I");
  const auto reply = answer["lines"][0]["reply"];
  ASSERT_GE(reply.size(), 2u) << answer.dump();
  EXPECT_EQ(reply[0].get<std::string>().rfind("[VER:1.1h", 0), 0u) << reply.dump();
  EXPECT_EQ(reply.back(), "ok");
  // A refused line comes back with its error, and is logged all the same.
  const nlohmann::json refused = rig.send("G1 X10 Q5");
  EXPECT_EQ(refused["lines"][0]["reply"].back().get<std::string>().rfind("error:", 0), 0u) << refused.dump();

  const auto log = rig.store.console_lines("laser", 10);
  ASSERT_EQ(log.size(), 2u);
  EXPECT_EQ(log[0].line, "$I");
  EXPECT_EQ(log[0].uid, 1000);
  EXPECT_NE(log[0].reply.find("[VER:1.1h"), std::string::npos) << log[0].reply;
  EXPECT_EQ(log[1].line, "G1 X10 Q5");
  EXPECT_EQ(log[1].reply.rfind("error:", 0), 0u) << log[1].reply;
}

TEST(LaserDeviceConsole, RealTimeBytesSeveralLinesAndLongLinesAreRefusedWithNothingSent) {
  LaserRig rig;
  const std::string before = rig.laser->received();
  EXPECT_NE(error_of([&] { rig.send("!"); }).find("real-time"), std::string::npos);
  EXPECT_NE(error_of([&] { rig.send("G0 X1 ?"); }).find("real-time"), std::string::npos);
  EXPECT_NE(error_of([&] { rig.send(std::string("\x18")); }).find("real-time"), std::string::npos);
  EXPECT_NE(error_of([&] { rig.send("G0X1\nG0X2"); }).find("several lines"), std::string::npos);
  EXPECT_NE(error_of([&] { rig.send(std::string(81, 'G')); }).find("80-character"), std::string::npos);
  EXPECT_NE(error_of([&] { rig.send(""); }).find("empty"), std::string::npos);
  EXPECT_EQ(rig.laser->received(), before);
  EXPECT_TRUE(rig.store.console_lines("laser", 10).empty());
}

TEST(LaserDeviceJog, AJogMovesTheHeadAndOneLeavingTheMachinesSpaceIsRefused) {
  LaserRig rig;  // homing off: the power-up position is the corner of a 400 x 400 mm space
  MachineCommand jog;
  jog.op = MachineCommand::Op::jog;
  jog.dx_mm = 25;
  jog.dy_mm = 15;
  jog.feed_mm_min = 3000;
  const nlohmann::json answer = rig.device->machine_command(jog);
  EXPECT_EQ(answer["lines"][0]["sent"], "$J=G91G21X25.000Y15.000F3000") << answer.dump();
  EXPECT_NEAR(rig.laser->position()[0], 25, 0.01);
  EXPECT_NEAR(rig.laser->position()[1], 15, 0.01);

  jog.dx_mm = 500;  // X would be 525 mm
  const std::string why = error_of([&] { rig.device->machine_command(jog); });
  EXPECT_NE(why.find("outside the machine's X"), std::string::npos) << why;
  EXPECT_NE(why.find("nothing was sent"), std::string::npos) << why;
  EXPECT_NEAR(rig.laser->position()[0], 25, 0.01);
  EXPECT_EQ(rig.store.console_lines("laser", 10).size(), 1u);
}

TEST(LaserDeviceSidecar, CheckFirstInTheSidecarRunsTheDryRunOverTheDevicesDefault) {
  LaserRig rig;  // the device's default: no dry run
  const Job plain = rig.run(rig.ready_job());
  ASSERT_EQ(plain.state, JobState::completed) << plain.reason;
  EXPECT_EQ(rig.laser->received().find("$C\n"), std::string::npos);

  const Job checked = rig.run(rig.ready_job(kSquare, "[laser]\ncheck_first = true\n"));
  ASSERT_EQ(checked.state, JobState::completed) << checked.reason;
  EXPECT_NE(rig.laser->received().find("$C\n"), std::string::npos) << "the sidecar's check_first was ignored";
}

TEST(LaserDeviceSidecar, ABadStartFromInTheSidecarFailsTheJobNamingTheFileAndKey) {
  LaserRig rig;
  const Job j = rig.run(rig.ready_job(kSquare, "[laser]\nstart_from = \"corner\"\n"));
  EXPECT_EQ(j.state, JobState::failed);
  EXPECT_NE(j.reason.find("box.svg.toml:2: key 'laser.start_from'"), std::string::npos) << j.reason;
  EXPECT_TRUE(rig.laser->segments().empty());
}

TEST(LaserDeviceStartFrom, HereFromTheSidecarOrTheStartCommandPlacesTheJobAtTheHead) {
  LaserRig rig;
  MachineCommand jog;
  jog.op = MachineCommand::Op::jog;
  jog.dx_mm = 100;
  jog.dy_mm = 50;
  rig.device->machine_command(jog);
  StartOptions here;
  here.start_from = "here";  // over the sidecar's origin
  const Job j = rig.run(rig.ready_job(kSquare, "[laser]\nstart_from = \"origin\"\n"), here);
  ASSERT_EQ(j.state, JobState::completed) << j.reason;
  EXPECT_NE(j.reason.find("start from here"), std::string::npos) << j.reason;
  double min_x = 1e9, min_y = 1e9;
  for (const auto& s : rig.laser->segments())
    if (s.power > 0) min_x = std::min({min_x, s.x0, s.x1}), min_y = std::min({min_y, s.y0, s.y1});
  EXPECT_NEAR(min_x, 110, 0.05);  // bed x 10 + the jog's 100
  EXPECT_NEAR(min_y, 60, 0.05);
  // And an unknown --start-from is refused when the job is started.
  const int64_t next = rig.ready_job();
  StartOptions corner;
  corner.start_from = "corner";
  EXPECT_NE(error_of([&] { rig.device->start(next, corner); }).find("--start-from 'corner'"),
            std::string::npos);
}

TEST(LaserDeviceAlarm, TheReasonNamesTheLineGrblWasAtAndWhatToDoNeverSafelyUnlock) {
  // 206 job lines; the emulator counts every line of its life, the session's setup too, so
  // line 120 of its life is well inside the job.
  std::string gcode = "; atelier laser job\n; s_max=1000\nG21 G90\nM4 S0\n";
  for (int i = 0; i < 100; ++i) gcode += "G1 X" + std::to_string(10 + i % 2) + " Y10 F600 S800\nG1 X20 Y" + std::to_string(10 + i % 3) + "\n";
  gcode += "M5\nG0 X0 Y0\n";
  laser_emu::ControllerOptions o;
  o.alarm_at_line = 120;
  o.alarm_code = 2;
  LaserRig rig(o);
  const Job j = rig.run(rig.ready_job(gcode));
  ASSERT_EQ(j.state, JobState::failed) << j.reason;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(j.reason, m, std::regex("ALARM:2 soft limit at line ([0-9]+) of ([0-9]+): ")))
      << j.reason;
  EXPECT_GT(std::stoi(m[1].str()), 20) << j.reason;   // not the last one acknowledged at setup
  EXPECT_LT(std::stoi(m[1].str()), 120) << j.reason;
  EXPECT_EQ(m[2].str(), "204") << j.reason;  // the program's lines, comments aside
  EXPECT_NE(j.reason.find(grbl::alarm_advice(2)), std::string::npos) << j.reason;
  EXPECT_EQ(j.reason.find("safely"), std::string::npos) << j.reason;
}

TEST(LaserDeviceLink, JobsAFrameAndCommandsShareOneConnectionAndNothingResetsAMachineAtRest) {
  LaserRig rig;
  ASSERT_EQ(rig.run(rig.ready_job()).state, JobState::completed);
  rig.send("$I");
  const int64_t framed = rig.ready_job();
  rig.device->frame(framed);
  for (int i = 0; i < 5000 && rig.device->describe().value("last", "").find("framed") == std::string::npos; ++i)
    std::this_thread::sleep_for(2ms);
  EXPECT_NE(rig.device->describe().value("last", "").find("framed"), std::string::npos) << rig.device->describe().dump();
  const Job second = rig.run(framed);
  ASSERT_EQ(second.state, JobState::completed) << second.reason;
  EXPECT_EQ(rig.opens.load(), 1);
  // A soft reset re-runs the user's $N startup lines: none at a job's start on a machine at rest.
  EXPECT_EQ(rig.laser->received().find('\x18'), std::string::npos);
}

TEST(LaserDeviceLink, ALinkLostBetweenJobsIsOpenedAnewForTheNextJob) {
  LaserRig rig;
  ASSERT_EQ(rig.run(rig.ready_job()).state, JobState::completed);
  rig.last_link.load()->disconnect();  // the cable, pulled and plugged back while idle
  const Job next = rig.run(rig.ready_job());
  EXPECT_EQ(next.state, JobState::completed) << next.reason;
  EXPECT_EQ(rig.opens.load(), 2);
}

TEST(LaserDeviceLink, AnAlarmLockRaisedInOneCommandIsStillThereForTheNextJobAndCommand) {
  laser_emu::ControllerOptions o;
  o.alarm_at_line = 4;  // $I, $$ and $# at connect, then the console's line
  o.alarm_code = 1;     // a hard limit: GRBL comes back from the reset locked
  LaserRig rig(o);
  EXPECT_NE(error_of([&] { rig.send("G0X5"); }).find("ALARM:1"), std::string::npos);
  // A reopened port would have restarted the board and lost the lock; the kept link has it.
  const Job locked = rig.run(rig.ready_job());
  EXPECT_EQ(locked.state, JobState::failed);
  EXPECT_NE(locked.reason.find("locked by an alarm"), std::string::npos) << locked.reason;
  EXPECT_TRUE(rig.laser->segments().empty());
  const nlohmann::json unlock = rig.send("$X");
  EXPECT_NE(unlock["lines"][0]["reply"].dump().find("[MSG:Caution: Unlocked]"), std::string::npos) << unlock.dump();
  const Job after = rig.run(rig.ready_job());
  EXPECT_EQ(after.state, JobState::completed) << after.reason;
  EXPECT_EQ(rig.opens.load(), 1);
}

}  // namespace
}  // namespace atelier

// A program pause (M0) between veneer sheets, end to end between the host session and the
// GRBL 1.1h controller model: GRBL finishes the cut before the M0, holds (Hold:0) with the M0
// line unanswered, and goes on only after a cycle start. The host must neither resume on its
// own (as it does for a feed hold whose '~' was dropped) nor take the long wait for a lost ok,
// and it must tell the operator what to do (the comment before the M0).
#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <thread>

#include "drivers/grbl/program.h"
#include "drivers/grbl/session.h"
#include "drivers/memory_transport.h"
#include "tools/laser_emu/controller.h"

namespace atelier::grbl {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// The controller model on one end of a memory pair, driven in real time (motion 20 times
// faster than programmed, so the test stays short).
class EmulatedLaser {
 public:
  explicit EmulatedLaser(MemoryTransport& link) : link_(link), start_(Clock::now()) {
    laser_emu::ControllerOptions o;
    o.time_scale = 0.05;
    ctl_ = std::make_unique<laser_emu::Controller>(o, record_, 0);
    thread_ = std::thread([this] { run(); });
  }
  ~EmulatedLaser() {
    stop_ = true;
    thread_.join();
  }
  std::string state() {
    std::lock_guard lock(mu_);
    return ctl_->state_name();
  }
  double x() {
    std::lock_guard lock(mu_);
    return ctl_->position()[0];
  }
  long lines_acknowledged() {
    std::lock_guard lock(mu_);
    return ctl_->lines_acknowledged();
  }

 private:
  int64_t now_us() const {
    return std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start_).count();
  }
  void run() {
    uint8_t buf[256];
    while (!stop_) {
      size_t n = 0;
      try {
        n = link_.read(buf, sizeof buf, 1ms);
      } catch (const LinkLost&) {
        return;
      }
      std::string out;
      {
        std::lock_guard lock(mu_);
        const int64_t t = now_us();
        if (n > 0) ctl_->host_write(std::string_view(reinterpret_cast<const char*>(buf), n), t);
        ctl_->advance_to(t);
        out = ctl_->take_output();
      }
      if (!out.empty()) {
        try {
          link_.write(reinterpret_cast<const uint8_t*>(out.data()), out.size());
        } catch (const LinkLost&) {
          return;
        }
      }
    }
  }

  MemoryTransport& link_;
  Clock::time_point start_;
  laser_emu::Record record_;
  std::mutex mu_;
  std::unique_ptr<laser_emu::Controller> ctl_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

constexpr const char* kTwoSheets =
    "; s_max=1000\n"
    "G21 G90\n"
    "M4 S0\n"
    "G1 X10 Y0 F3000 S800\n"
    "; sheet walnut-2: place it face down at the origin, then resume\n"
    "M0\n"
    "G1 X20 Y0 S800\n"
    "M5\n";

TEST(GrblProgramPause, ProgramNotesEachPauseWithTheCommentBeforeIt) {
  const Program p = parse_program(kTwoSheets, 6000);
  ASSERT_EQ(p.pauses.size(), 1u);
  const size_t m0 = p.pauses.begin()->first;
  EXPECT_EQ(p.lines[m0], "M0");
  EXPECT_EQ(p.pauses.begin()->second, "sheet walnut-2: place it face down at the origin, then resume");
  // M05 (beam off) is not a pause; "M00" is.
  EXPECT_TRUE(parse_program("G1 X1 F100\nM05\n", 6000).pauses.empty());
  EXPECT_EQ(parse_program("G1 X1 F100\nM00\n", 6000).pauses.size(), 1u);
}

TEST(GrblProgramPause, SessionWaitsAtTheM0ForTheOperatorAndSaysWhy) {
  auto [host, ctl] = make_memory_pair();
  EmulatedLaser laser(*ctl);
  Session session(*host);
  session.connect();
  const Program program = parse_program(kTwoSheets, 6000);

  Controls controls;
  std::mutex mu;
  std::vector<std::string> notes;  // every change of Progress::paused, in order
  std::string last_note;
  std::exception_ptr failure;
  std::atomic<bool> done{false};
  std::thread streamer([&] {
    try {
      session.stream(program, StreamMode::character_counting, controls, [&](const Progress& p) {
        std::lock_guard lock(mu);
        if (p.paused != last_note) notes.push_back(p.paused);
        last_note = p.paused;
      });
    } catch (...) {
      failure = std::current_exception();
    }
    done = true;
  });
  const auto paused = [&] {
    std::lock_guard lock(mu);
    return !last_note.empty();
  };
  for (auto until = Clock::now() + 5s; !paused() && !done && Clock::now() < until;)
    std::this_thread::sleep_for(5ms);
  ASSERT_TRUE(paused()) << "no program pause reported";
  // The first sheet's cut is finished and the head waits there, beam off, in Hold:0 ...
  EXPECT_EQ(laser.state(), "Hold:0");
  EXPECT_NEAR(laser.x(), 10.0, 1e-6);
  // ... for longer than the session's lost-ok limit (5 s), and it is still a pause, not a
  // fault, and the host did not resume by itself.
  std::this_thread::sleep_for(5500ms);
  EXPECT_FALSE(done) << "the stream ended during the pause";
  EXPECT_EQ(laser.state(), "Hold:0");
  EXPECT_NEAR(laser.x(), 10.0, 1e-6);

  controls.release_pause = true;
  for (auto until = Clock::now() + 5s; !done && Clock::now() < until;) std::this_thread::sleep_for(5ms);
  ASSERT_TRUE(done) << "the job did not finish after the resume";
  streamer.join();
  if (failure) std::rethrow_exception(failure);
  EXPECT_NEAR(laser.x(), 20.0, 1e-6);  // the second sheet was cut
  EXPECT_EQ(laser.state(), "Idle");
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_EQ(notes[0], "sheet walnut-2: place it face down at the origin, then resume");
  EXPECT_EQ(notes[1], "");
  EXPECT_FALSE(controls.release_pause.load());
}

TEST(GrblProgramPause, AnOperatorHoldIsStillResumedAsBefore) {
  // A feed hold and resume of the operator's own around a program with no M0 still works.
  auto [host, ctl] = make_memory_pair();
  EmulatedLaser laser(*ctl);
  Session session(*host);
  session.connect();
  const Program program = parse_program("G21 G90\nM4 S0\nG1 X100 F3000 S500\nM5\n", 6000);
  Controls controls;
  controls.hold = true;  // held from the start
  std::atomic<bool> done{false};
  std::thread streamer([&] {
    session.stream(program, StreamMode::character_counting, controls, {});
    done = true;
  });
  std::this_thread::sleep_for(300ms);
  EXPECT_FALSE(done);
  controls.hold = false;
  for (auto until = Clock::now() + 5s; !done && Clock::now() < until;) std::this_thread::sleep_for(5ms);
  EXPECT_TRUE(done);
  streamer.join();
  EXPECT_NEAR(laser.x(), 100.0, 1e-6);
}

}  // namespace
}  // namespace atelier::grbl

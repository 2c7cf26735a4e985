// A program pause (M0) between veneer sheets, end to end between the host session and the
// GRBL 1.1h controller model: GRBL finishes the cut before the M0, holds (Hold:0) with the M0
// line unanswered, and goes on only after a cycle start. The host must neither resume on its
// own (as it does for a feed hold whose '~' was dropped) nor take the long wait for a lost ok,
// and it must tell the operator what to do (the comment before the M0).
#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

#include "base/fake_clock.h"
#include "drivers/grbl/program.h"
#include "drivers/grbl/session.h"
#include "drivers/simulated_transport.h"
#include "tools/laser_emu/controller.h"

namespace atelier::grbl {
namespace {

using namespace std::chrono_literals;

// The controller model as the far end of a simulated link, on the link's fake clock
// (microseconds since the peer was made). Its accessors lock, so the test thread may look at
// the machine while the session streams on another thread.
class EmulatedLaser : public SimulatedPeer {
 public:
  explicit EmulatedLaser(Clock::time_point now) : epoch_(now), ctl_(laser_emu::ControllerOptions{}, record_, 0) {}

  std::string state() const {
    std::lock_guard lock(mu_);
    return ctl_.state_name();
  }
  double x() const {
    std::lock_guard lock(mu_);
    return ctl_.position()[0];
  }

  void receive(const uint8_t* data, size_t size, Clock::time_point now) override {
    std::lock_guard lock(mu_);
    ctl_.host_write(std::string_view(reinterpret_cast<const char*>(data), size), us(now));
    ctl_.advance_to(us(now));
  }
  std::vector<uint8_t> take_output(Clock::time_point now) override {
    std::lock_guard lock(mu_);
    ctl_.advance_to(us(now));
    const std::string out = ctl_.take_output();
    return {out.begin(), out.end()};
  }
  std::optional<Clock::time_point> next_event() const override {
    std::lock_guard lock(mu_);
    const auto next = ctl_.next_event_us();
    if (!next) return std::nullopt;
    return epoch_ + std::chrono::microseconds(*next);
  }

 private:
  int64_t us(Clock::time_point t) const {
    return std::chrono::duration_cast<std::chrono::microseconds>(t - epoch_).count();
  }

  const Clock::time_point epoch_;  // the controller's clock 0
  mutable std::mutex mu_;
  laser_emu::Record record_;
  laser_emu::Controller ctl_;
};

// A stream on its own thread, with what the test waits for. Whatever happens to the test, the
// stream is canceled and joined when this goes.
struct Streamer {
  Controls controls;
  std::mutex mu;
  std::condition_variable_any changed;
  std::vector<std::string> notes;  // every change of Progress::paused, in order
  std::string last_note;
  std::optional<Clock::time_point> paused_at;  // when the first pause was reported
  std::exception_ptr failure;
  bool done = false;
  std::thread thread;

  void start(Session& session, const Program& program, Clock& clock) {
    thread = std::thread([this, &session, &program, &clock] {
      try {
        session.stream(program, StreamMode::character_counting, controls, [&](const Progress& p) {
          {
            std::lock_guard lock(mu);
            if (p.paused != last_note) notes.push_back(p.paused);
            last_note = p.paused;
            if (!p.paused.empty() && !paused_at) paused_at = clock.now();
          }
          changed.notify_all();
        });
      } catch (...) {
        failure = std::current_exception();
      }
      {
        std::lock_guard lock(mu);
        done = true;
      }
      changed.notify_all();
    });
  }
  // Waits until `what` holds or a minute of the clock has passed (the stream moves it).
  bool wait(Clock& clock, const std::function<bool()>& what) {
    std::unique_lock lock(mu);
    return clock.wait_for(changed, lock, 60s, what);
  }
  // Waits until the clock reaches `t` (the stream moves it) or the stream ends: whether it
  // ended.
  bool ends_before(Clock& clock, Clock::time_point t) {
    std::unique_lock lock(mu);
    return clock.wait_until(changed, lock, t, [&] { return done; });
  }
  bool is_done() {
    std::lock_guard lock(mu);
    return done;
  }
  ~Streamer() {
    if (!thread.joinable()) return;
    controls.cancel = true;
    thread.join();
  }
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
  FakeClock clock;
  auto laser = std::make_shared<EmulatedLaser>(clock.now());
  SimulatedTransport host(laser, clock);
  Session session(host, {}, clock);
  session.connect();
  const Program program = parse_program(kTwoSheets, 6000);

  Streamer streamer;
  streamer.start(session, program, clock);
  ASSERT_TRUE(streamer.wait(clock, [&] { return !streamer.last_note.empty() || streamer.done; }))
      << "no program pause reported";
  ASSERT_FALSE(streamer.is_done()) << "the stream ended instead of pausing";
  // The first sheet's cut is finished and the head waits there, beam off, in Hold:0 ...
  EXPECT_EQ(laser->state(), "Hold:0");
  EXPECT_NEAR(laser->x(), 10.0, 1e-6);
  // ... for longer than the session's lost-ok limit (5 s), and it is still a pause, not a
  // fault, and the host did not resume by itself. (The stream's reads move the clock.)
  EXPECT_FALSE(streamer.ends_before(clock, *streamer.paused_at + 5500ms)) << "the stream ended during the pause";
  EXPECT_EQ(laser->state(), "Hold:0");
  EXPECT_NEAR(laser->x(), 10.0, 1e-6);

  streamer.controls.release_pause = true;
  ASSERT_TRUE(streamer.wait(clock, [&] { return streamer.done; })) << "the job did not finish after the resume";
  streamer.thread.join();
  if (streamer.failure) std::rethrow_exception(streamer.failure);
  EXPECT_NEAR(laser->x(), 20.0, 1e-6);  // the second sheet was cut
  EXPECT_EQ(laser->state(), "Idle");
  ASSERT_EQ(streamer.notes.size(), 2u);
  EXPECT_EQ(streamer.notes[0], "sheet walnut-2: place it face down at the origin, then resume");
  EXPECT_EQ(streamer.notes[1], "");
  EXPECT_FALSE(streamer.controls.release_pause.load());
}

TEST(GrblProgramPause, AnOperatorHoldIsStillResumedAsBefore) {
  // A feed hold and resume of the operator's own around a program with no M0 still works.
  FakeClock clock;
  auto laser = std::make_shared<EmulatedLaser>(clock.now());
  SimulatedTransport host(laser, clock);
  Session session(host, {}, clock);
  session.connect();
  const Program program = parse_program("G21 G90\nM4 S0\nG1 X100 F3000 S500\nM5\n", 6000);
  Streamer streamer;
  streamer.controls.hold = true;  // held from the start
  const auto t0 = clock.now();
  streamer.start(session, program, clock);
  EXPECT_FALSE(streamer.ends_before(clock, t0 + 300ms));  // the stream's reads move the clock
  streamer.controls.hold = false;
  EXPECT_TRUE(streamer.wait(clock, [&] { return streamer.done; }));
  streamer.thread.join();
  if (streamer.failure) std::rethrow_exception(streamer.failure);
  EXPECT_NEAR(laser->x(), 100.0, 1e-6);
}

}  // namespace
}  // namespace atelier::grbl

// The GRBL host session against a scripted controller on a simulated link: the controller
// plays GRBL 1.1h (banner, $I, $$, receive buffer with a 15-block planner, real-time bytes,
// check mode, alarms) in lock step with the session on a fake clock, and records what the
// host sent, so the tests assert what a user of a real laser would notice: nothing overflows,
// errors name the line, cancel stops the beam.
//
// A session kept open between jobs (revalidate) and program pauses (M0) on the laser
// emulator's controller model. Program pauses: the session waits at the M0 for
// the operator and says why; an operator's own hold is still resumed as before.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include "base/fake_clock.h"
#include "drivers/grbl/program.h"
#include "drivers/grbl/session.h"
#include "drivers/simulated_transport.h"
#include "tests/support/laser_emu_rig.h"
#include "tools/laser_emu/controller.h"

namespace atelier::grbl {
namespace {

using namespace std::chrono_literals;

struct FakeScript {
  bool banner_at_start = true;  // false: the board printed it before we opened the port
  bool start_in_alarm = false;  // homing lock after power-up
  int laser_mode = 1;           // $32
  int error_at = -1;            // 0-based G-code line answered error:33
  int alarm_at = -1;            // G-code line that raises ALARM:2 (soft limit)
  int silent_at = -1;           // from this G-code line on, answer nothing at all
  int disconnect_at = -1;       // unplug when this G-code line arrives
  bool hold_never_settles = false;         // stays Hold:1 (the host must reset anyway)
  std::chrono::milliseconds motion{3};     // time each G-code motion line takes
  std::string startup_line;                // $N0: run (">line:ok") after every banner when set
};

// Plays GRBL 1.1h as the far end of a SimulatedTransport, on the test's FakeClock: real-time
// bytes act at once, lines wait in a 128-byte receive buffer and are parsed while the 15-block
// planner has room, and motion drains the planner as the clock moves (looked at every 1 ms
// while anything moves, as a controller's main loop would).
class FakeGrbl : public SimulatedPeer {
 public:
  FakeGrbl(FakeScript script, Clock::time_point now) : s_(script), now_(now) {
    if (s_.start_in_alarm) alarm_ = true;
    if (s_.banner_at_start) banner();
  }

  // What the host sent, in order: "line:TEXT" when a line's newline arrived, "!", "~",
  // "reset" (0x18). Status requests are counted, not listed.
  const std::vector<std::string>& events() const { return events_; }
  const std::vector<std::string>& executed() const { return executed_; }  // G-code lines parsed, in order
  size_t max_buffered() const { return max_buffered_; }     // most bytes in the receive buffer
  size_t max_lines_buffered() const { return max_lines_; }  // most complete lines waiting there
  int status_requests() const { return status_requests_; }
  bool overflowed() const { return overflowed_; }
  std::string state_name() const { return state(); }  // as of the last time the host looked

  void receive(const uint8_t* data, size_t size, Clock::time_point now) override {
    if (silent_) return;
    run_until(now);
    for (size_t i = 0; i < size && !unplugged_; ++i) {
      const uint8_t b = data[i];
      if (b == '?' || b == '!' || b == '~' || b == 0x18) {
        realtime(b);
        continue;
      }
      buffer_.push_back(static_cast<char>(b));
      if (buffer_.size() > 128) overflowed_ = true;
      max_buffered_ = std::max(max_buffered_, buffer_.size());
      if (b == '\n') {
        events_.push_back("line:" + partial_);
        partial_.clear();
        max_lines_ = std::max<size_t>(max_lines_, std::count(buffer_.begin(), buffer_.end(), '\n'));
      } else {
        partial_.push_back(static_cast<char>(b));
      }
    }
    parse_lines();
  }
  std::vector<uint8_t> take_output(Clock::time_point now) override {
    if (!silent_) run_until(now);
    return std::exchange(out_, {});
  }
  std::optional<Clock::time_point> next_event() const override {
    if (silent_ || unplugged_) return std::nullopt;
    const bool moving = !held_ && motion_left_ > 0;
    const bool settling = held_ && motion_left_ > 0 && now_ - hold_since_ < 30ms;
    if (moving || settling) return now_ + 1ms;
    if (critical_ && !reset_heard_) return alarm_since_ + 500ms;
    return std::nullopt;
  }
  bool unplugged() const override { return unplugged_; }

 private:
  void send(const std::string& line) {
    const std::string wire = line + "\r\n";
    out_.insert(out_.end(), wire.begin(), wire.end());
  }
  void banner() {
    send("");
    send("Grbl 1.1h ['$' for help]");
    if (alarm_) send("[MSG:'$H'|'$X' to unlock]");
    else if (!s_.startup_line.empty()) {
      ++startup_runs_;
      send(">" + s_.startup_line + ":ok");
    }
  }

 public:
  int startup_runs() const { return startup_runs_; }  // times the $N0 line ran
  int lost_resets() const { return lost_resets_; }    // 0x18 that GRBL's critical loop dropped
  const std::vector<std::string>& commands() const { return commands_; }  // '$' lines, in order

 private:

  // Motion up to `now`, then whatever the freed planner blocks let the parser take.
  void run_until(Clock::time_point now) {
    if (now <= now_) return;
    const double elapsed = std::chrono::duration<double, std::milli>(now - now_).count();
    now_ = now;
    // report.c: delay_ms(500) after "ALARM:N", then the critical-event message.
    if (critical_ && !reset_heard_ && now_ - alarm_since_ >= 500ms) {
      send("[MSG:Reset to continue]");
      reset_heard_ = true;
    }
    if (!held_ && motion_left_ > 0) motion_left_ = std::max(0.0, motion_left_ - elapsed);
    parse_lines();
  }
  // Parse lines while the planner has room (GRBL stops reading when it is full).
  void parse_lines() {
    while (!critical_ && !silent_ && !unplugged_ && blocks() < 15) {
      const size_t nl = buffer_.find('\n');
      if (nl == std::string::npos) break;
      std::string line = buffer_.substr(0, nl);
      buffer_.erase(0, nl + 1);
      execute(line);
    }
  }

  std::string state() const {
    if (alarm_) return "Alarm";
    if (check_) return "Check";
    if (held_) {
      const bool stopping = s_.hold_never_settles || (motion_left_ > 0 && now_ - hold_since_ < 30ms);
      return stopping ? "Hold:1" : "Hold:0";
    }
    if (motion_left_ > 0) return jog_ ? "Jog" : "Run";
    return "Idle";
  }
  int blocks() const {
    return static_cast<int>(std::ceil(motion_left_ / static_cast<double>(s_.motion.count())));
  }

  void reset() {
    if (critical_ && !reset_heard_) {  // protocol.c clears EXEC_RESET after the message
      ++lost_resets_;
      events_.push_back("reset(lost)");
      return;
    }
    if (critical_) send("ok");  // the struck line's answer comes after the reset
    events_.push_back("reset");
    buffer_.clear();
    partial_.clear();
    const bool moving = !alarm_ && (state() == "Run" || state() == "Hold:1");
    motion_left_ = 0;
    held_ = false;
    check_ = false;
    critical_ = false;
    if (moving) {
      send("ALARM:3");
      alarm_ = true;
    }
    banner();
  }

  void realtime(uint8_t b) {
    switch (b) {
      case '?':
        if (critical_) break;  // the critical-event loop answers nothing
        ++status_requests_;
        if (motion_left_ <= 0) jog_ = false;
        send("<" + state() + "|MPos:1.000,2.000,0.000|Bf:" + std::to_string(15 - blocks()) + "," +
             std::to_string(128 - buffer_.size()) + "|FS:600,300" + (wco_once_ ? "|WCO:" + g54_ : "") + ">");
        wco_once_ = false;
        break;
      case '!':
        events_.push_back("!");
        if (!alarm_ && !check_ && !held_) {
          held_ = true;
          hold_since_ = now_;
        }
        break;
      case '~':
        events_.push_back("~");
        held_ = false;
        break;
      case 0x18:
        reset();
        break;
    }
  }

  void execute(const std::string& line) {
    if (line.empty()) return send("ok");
    if (line == "$I") {
      send("[VER:1.1h.20190830:]");
      send("[OPT:V,15,128]");
      return send("ok");
    }
    if (line == "$$") {
      const char* settings[] = {"$0=10", "$1=25", "$10=1", "$20=1", "$21=0", "$22=0", "$30=1000", "$31=0",
                                "$100=80.000", "$110=6000.000", "$130=400.000", "$131=300.000", "$132=0.000"};
      for (const char* st : settings) send(st);
      send("$32=" + std::to_string(s_.laser_mode));
      return send("ok");
    }
    if (line == "$C") {
      if (check_) {
        send("[MSG:Disabled]");
        send("ok");
        return reset();  // GRBL resets itself when check mode is turned off
      }
      if (alarm_ || state() != "Idle") return send("error:8");
      check_ = true;
      send("[MSG:Enabled]");
      return send("ok");
    }
    if (line == "$X") {
      if (alarm_) send("[MSG:Caution: Unlocked]");
      alarm_ = false;
      return send("ok");
    }
    if (line[0] == '$') commands_.push_back(line);
    if (line == "$#") {
      send("[G54:" + g54_ + "]");
      send("[G92:0.000,0.000,0.000]");
      send("[TLO:0.000]");
      return send("ok");
    }
    if (line == "$H") {
      alarm_ = false;
      wco_once_ = true;
      return send("ok");
    }
    if (line == "$G") {
      send("[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]");
      return send("ok");
    }
    if (line.rfind("$J=", 0) == 0) {
      if (alarm_) return send("error:9");
      jog_ = true;
      motion_left_ += s_.motion.count();
      return send("ok");
    }
    if (line[0] == '$') return send("ok");
    if (line == "G10L20P1X0Y0") {
      g54_ = "1.000,2.000,0.000";  // MPos is always 1,2,0 here
      wco_once_ = true;
      return send("ok");
    }

    const int g = gcode_++;
    executed_.push_back(line);
    if (g == s_.silent_at) {
      silent_ = true;
      return;
    }
    if (g == s_.disconnect_at) {
      unplugged_ = true;
      out_.clear();  // what was still on its way is lost with the cable
      return;
    }
    if (alarm_) return send("error:9");
    if (g == s_.error_at) return send("error:33");
    if (g == s_.alarm_at) {
      motion_left_ = 0;
      alarm_ = true;
      critical_ = true;  // like hard/soft limits: nothing more until a reset
      reset_heard_ = false;
      alarm_since_ = now_;
      return send("ALARM:2");  // "[MSG:Reset to continue]" 500 ms later (run_until)
    }
    if (!check_ && line.find('X') != std::string::npos) motion_left_ += s_.motion.count();
    send("ok");
  }

  FakeScript s_;
  Clock::time_point now_;  // the clock when motion was last run
  std::vector<uint8_t> out_;
  std::string buffer_, partial_;
  double motion_left_ = 0;  // ms of motion queued
  bool held_ = false, check_ = false, alarm_ = false, critical_ = false, silent_ = false, unplugged_ = false;
  bool reset_heard_ = false, jog_ = false, wco_once_ = false;
  Clock::time_point alarm_since_;
  std::string g54_ = "0.000,0.000,0.000";
  int startup_runs_ = 0, lost_resets_ = 0;
  std::vector<std::string> commands_;
  Clock::time_point hold_since_;
  int gcode_ = 0;
  size_t max_buffered_ = 0, max_lines_ = 0;
  int status_requests_ = 0;
  bool overflowed_ = false;
  std::vector<std::string> events_, executed_;
};

Timeouts fast() {
  Timeouts t;
  t.banner = 300ms;
  t.reply = 1000ms;
  t.poll = 20ms;
  t.silent = 500ms;
  t.stop = 500ms;
  return t;
}

// Nothing at the other end: whatever the host sends goes unanswered.
struct NoController : SimulatedPeer {
  void receive(const uint8_t*, size_t, Clock::time_point) override {}
  std::vector<uint8_t> take_output(Clock::time_point) override { return {}; }
  std::optional<Clock::time_point> next_event() const override { return std::nullopt; }
};

// A session and its fake controller on one FakeClock: the session's reads move the clock, so
// every timeout, poll and motion below runs in simulated time only.
struct Rig {
  explicit Rig(FakeScript script = {})
      : fake(std::make_shared<FakeGrbl>(script, clock.now())), link(fake, clock), s(link, fast(), clock) {}

  FakeClock clock;
  std::shared_ptr<FakeGrbl> fake;
  SimulatedTransport link;
  Session s;
};

// A job of `n` moves with lines of varied length, behind a two-line header.
std::string job_text(int n) {
  std::string g = "; s_max=1000\n; bounds=0,0,400,300\nG21 G90\n";
  for (int i = 0; i < n; ++i) {
    g += "G1 X" + std::to_string(i % 400) + "." + std::to_string(i % 1000) + " Y" + std::to_string((i * 7) % 300) +
         " F600 S" + std::to_string(i % 1000);
    if (i % 5 == 0) g += " (a comment) " + std::string(static_cast<size_t>(i % 40), ' ');
    g += "\n";
  }
  return g + "M5\n";
}

std::vector<std::string> program_lines_in(const std::vector<std::string>& events, const Program& p) {
  std::vector<std::string> out;
  for (const auto& e : events)
    if (e.rfind("line:", 0) == 0 && std::find(p.lines.begin(), p.lines.end(), e.substr(5)) != p.lines.end())
      out.push_back(e.substr(5));
  return out;
}

size_t index_of(const std::vector<std::string>& v, const std::string& s, size_t from = 0) {
  for (size_t i = from; i < v.size(); ++i)
    if (v[i] == s) return i;
  return v.size();
}

TEST(GrblSession, ConnectReadsBuildInfoAndSettings) {
  Rig rig;
  const FakeGrbl& fake = *rig.fake;
  Session& s = rig.s;
  const MachineInfo info = s.connect();
  EXPECT_EQ(info.version, "1.1h.20190830");
  EXPECT_EQ(info.rx_buffer, 128);
  EXPECT_EQ(info.planner_blocks, 15);
  EXPECT_TRUE(info.laser_mode);
  EXPECT_DOUBLE_EQ(info.s_max, 1000);
  EXPECT_DOUBLE_EQ(info.max_travel_x, 400);
  EXPECT_DOUBLE_EQ(info.max_travel_y, 300);
  EXPECT_TRUE(info.soft_limits);
  EXPECT_FALSE(info.alarm_locked);
  EXPECT_DOUBLE_EQ(info.settings.at(110), 6000);
  EXPECT_EQ(index_of(fake.events(), "reset"), fake.events().size());  // the banner came: no reset needed
}

// Issue 20 point 6: a board at rest whose banner went before we opened the port is not reset
// (a reset would re-run the user's $N startup lines); it answers '?' Idle, which is enough.
TEST(GrblSession, ConnectDoesNotResetABoardAtRestThatPrintedItsBannerBeforeWeOpened) {
  FakeScript script;
  script.banner_at_start = false;
  Rig rig(script);
  const FakeGrbl& fake = *rig.fake;
  Session& s = rig.s;
  EXPECT_EQ(s.connect().version, "1.1h.20190830");
  EXPECT_EQ(index_of(fake.events(), "reset"), fake.events().size());
}

TEST(GrblSession, StartupLineRunsOnceAtPowerUpNotOncePerJob) {
  FakeScript script;
  script.startup_line = "G21G90";
  Rig rig(script);
  const FakeGrbl& fake = *rig.fake;
  EXPECT_EQ(fake.startup_runs(), 1);  // at power-up
  for (int job = 0; job < 3; ++job) {
    Session s(rig.link, fast(), rig.clock);  // the daemon connects anew for every job
    s.connect();
    Controls c;
    s.stream(parse_program(job_text(5), 6000), StreamMode::character_counting, c, {});
  }
  EXPECT_EQ(fake.startup_runs(), 1);
  EXPECT_EQ(index_of(fake.events(), "reset"), fake.events().size());
}

TEST(GrblSession, ConnectNotesTheAlarmLock) {
  FakeScript script;
  script.start_in_alarm = true;
  Rig rig(script);
  Session& s = rig.s;
  EXPECT_TRUE(s.connect().alarm_locked);
  s.unlock();
  EXPECT_FALSE(s.info().alarm_locked);
  EXPECT_EQ(s.query_status().state, "Idle");
}

TEST(GrblSession, LaserModeOffIsASetupErrorThatSaysWhatToDo) {
  FakeScript script;
  script.laser_mode = 0;
  Rig rig(script);
  Session& s = rig.s;
  try {
    s.connect();
    FAIL() << "expected SetupError";
  } catch (const SetupError& e) {
    EXPECT_STREQ(e.what(), "laser mode is off ($32=0); set $32=1 on the controller");
  }
}

TEST(GrblSession, NoControllerIsASetupError) {
  FakeClock clock;
  SimulatedTransport host(std::make_shared<NoController>(), clock);  // nothing answers
  Session s(host, fast(), clock);
  try {
    s.connect();
    FAIL() << "expected SetupError";
  } catch (const SetupError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("no GRBL banner within 0.3 s, nor after a soft reset", 0), 0u) << e.what();
  }
}

TEST(GrblSession, CharacterCountingFillsButNeverOverflowsTheReceiveBuffer) {
  Rig rig;
  const FakeGrbl& fake = *rig.fake;
  Session& s = rig.s;
  s.connect();
  const Program p = parse_program(job_text(400), 6000);
  Controls c;
  std::vector<Progress> progress;
  s.stream(p, StreamMode::character_counting, c, [&](const Progress& pr) { progress.push_back(pr); });

  EXPECT_FALSE(fake.overflowed());
  EXPECT_LE(fake.max_buffered(), 127u);
  EXPECT_GE(fake.max_buffered(), 100u);  // the window is used, not one line at a time
  EXPECT_GT(fake.max_lines_buffered(), 2u);
  // Every line arrived once, in order, and was executed.
  EXPECT_EQ(program_lines_in(fake.events(), p), p.lines);
  EXPECT_EQ(fake.executed(), p.lines);
  ASSERT_FALSE(progress.empty());
  EXPECT_EQ(progress.back().acked, p.lines.size());
  EXPECT_EQ(progress.back().total, p.lines.size());
  EXPECT_DOUBLE_EQ(progress.back().seconds_left, 0);
  EXPECT_EQ(progress.back().status.state, "Idle");  // returned once motion was done
  EXPECT_EQ(fake.state_name(), "Idle");
  for (size_t i = 1; i < progress.size(); ++i) EXPECT_GE(progress[i].acked, progress[i - 1].acked);
  // Status polls stayed within the configured rate (20 ms here; 5 Hz by default).
  EXPECT_GT(fake.status_requests(), 0);
}

TEST(GrblSession, SendResponseKeepsOneLineInFlight) {
  Rig rig;
  const FakeGrbl& fake = *rig.fake;
  Session& s = rig.s;
  s.connect();
  const Program p = parse_program(job_text(60), 6000);
  Controls c;
  s.stream(p, StreamMode::send_response, c, {});
  EXPECT_EQ(fake.max_lines_buffered(), 1u);
  EXPECT_EQ(fake.executed(), p.lines);
}

TEST(GrblSession, ErrorNamesTheSourceLineAndStopsSending) {
  FakeScript script;
  script.error_at = 20;  // G-code line 20 = the 20th move (line 0 is G21G90)
  script.motion = 20ms;  // slow motion, so the buffer is full when the error comes
  Rig rig(script);
  const FakeGrbl& fake = *rig.fake;
  Session& s = rig.s;
  s.connect();
  const Program p = parse_program(job_text(200), 6000);
  Controls c;
  try {
    s.stream(p, StreamMode::character_counting, c, {});
    FAIL() << "expected GrblError";
  } catch (const GrblError& e) {
    EXPECT_EQ(e.code, 33);
    // Lines 1-2 are header comments, line 3 "G21 G90" (G-code line 0): G-code line 20 is line 23.
    EXPECT_EQ(e.line_number, 23u);
    EXPECT_EQ(e.line, p.source_text[20]);
    EXPECT_EQ(std::string(e.what()),
              "line 23 (" + p.source_text[20] + "): error:33 invalid target: motion command target is invalid");
  }
  const auto ev = fake.events();
  const size_t hold = index_of(ev, "!");
  const size_t reset = index_of(ev, "reset", hold);
  ASSERT_LT(hold, ev.size());
  ASSERT_LT(reset, ev.size());
  // Once the host had seen the error (it then sent '!'), no job line followed.
  for (size_t i = hold; i < ev.size(); ++i)
    EXPECT_TRUE(ev[i].rfind("line:", 0) != 0 || ev[i] == "line:M5" || ev[i] == "line:$X") << ev[i];
  EXPECT_LT(index_of(ev, "line:M5", reset), ev.size());  // beam off after the reset
  // The lines queued behind the error never ran: the reset dropped them.
  EXPECT_LT(fake.executed().size(), 40u);
}

TEST(GrblSession, AlarmFailsTheJobWithItsMeaning) {
  FakeScript script;
  script.alarm_at = 10;
  Rig rig(script);
  const FakeGrbl& fake = *rig.fake;
  Session& s = rig.s;
  s.connect();
  const Program p = parse_program(job_text(100), 6000);
  Controls c;
  try {
    s.stream(p, StreamMode::character_counting, c, {});
    FAIL() << "expected GrblAlarm";
  } catch (const GrblAlarm& e) {
    EXPECT_EQ(e.code, 2);
    // G-code line 10 (0-based: G21G90, then G1 i=0..9) is source line 13.
    EXPECT_EQ(e.line_number, 13u);
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("ALARM:2 soft limit at line 13 (G1 X9.9 Y63 F600 S9): a move would have left", 0), 0u)
        << what;
    EXPECT_EQ(what.find("safely"), std::string::npos) << what;  // a limit alarm is never "safe to unlock"
    EXPECT_NE(what.find("home the machine ($H)"), std::string::npos) << what;
  }
  // GRBL drops a reset sent before "[MSG:Reset to continue]" (500 ms after the alarm): the
  // session waited for it, so its one reset was taken and GRBL restarted.
  EXPECT_EQ(fake.lost_resets(), 0);
  EXPECT_LT(index_of(fake.events(), "reset"), fake.events().size());
  EXPECT_TRUE(s.info().alarm_locked);  // left for the operator to unlock
}

TEST(GrblSession, CancelHoldsResetsAndTurnsTheBeamOff) {
  FakeScript script;
  script.motion = 10ms;
  Rig rig(script);
  const FakeGrbl& fake = *rig.fake;
  Session& s = rig.s;
  s.connect();
  const Program p = parse_program(job_text(300), 6000);
  Controls c;
  const auto t0 = rig.clock.now();
  EXPECT_THROW(s.stream(p, StreamMode::character_counting, c,
                        [&](const Progress& pr) {
                          if (pr.acked >= 30) c.cancel = true;
                        }),
               Canceled);
  EXPECT_LT(rig.clock.now() - t0, 5s);
  const auto ev = fake.events();
  const size_t hold = index_of(ev, "!");
  const size_t reset = index_of(ev, "reset", hold);
  const size_t m5 = index_of(ev, "line:M5", reset);
  ASSERT_LT(hold, ev.size());
  ASSERT_LT(reset, ev.size());
  ASSERT_LT(m5, ev.size());
  EXPECT_EQ(index_of(ev, "line:$X"), ev.size());  // the hold settled: no alarm to clear
  EXPECT_LT(fake.executed().size(), p.lines.size());
  EXPECT_EQ(fake.state_name(), "Idle");
}

TEST(GrblSession, CancelWhileStillMovingResetsAtOnceAndLeavesTheLockToTheOperator) {
  FakeScript script;
  script.motion = 10ms;
  script.hold_never_settles = true;  // a slow deceleration: the beam must not wait for it
  Rig rig(script);
  const FakeGrbl& fake = *rig.fake;
  Session& s = rig.s;
  s.connect();
  const Program p = parse_program(job_text(300), 6000);
  Controls c;
  std::string message;
  Clock::time_point asked;
  try {
    s.stream(p, StreamMode::character_counting, c, [&](const Progress& pr) {
      if (pr.acked >= 30 && !c.cancel) {
        asked = rig.clock.now();
        c.cancel = true;
      }
    });
  } catch (const Canceled& e) {
    message = e.what();
  }
  ASSERT_FALSE(message.empty()) << "the stream was not canceled";
  const auto ev = fake.events();
  const size_t hold = index_of(ev, "!");
  const size_t reset = index_of(ev, "reset", hold);
  ASSERT_LT(reset, ev.size());
  // The reset (beam off) came within the 80 ms hold budget plus a poll, not after timeouts.stop.
  EXPECT_LT(rig.clock.now() - asked, 1s);
  // Our reset in motion raised ALARM:3: the position may be lost, so no $X behind the
  // operator's back, and no M5 into the lock.
  EXPECT_EQ(index_of(ev, "line:$X", reset), ev.size());
  EXPECT_TRUE(s.info().alarm_locked);
  EXPECT_NE(message.find("position may be lost"), std::string::npos) << message;
}

TEST(GrblSession, HoldAndResumeSendTheRealTimeBytes) {
  FakeScript script;
  script.motion = 5ms;
  Rig rig(script);
  const FakeGrbl& fake = *rig.fake;
  Session& s = rig.s;
  s.connect();
  const Program p = parse_program(job_text(120), 6000);
  Controls c;
  std::optional<Clock::time_point> held_at;
  bool held_seen = false;
  s.stream(p, StreamMode::character_counting, c, [&](const Progress& pr) {
    if (pr.status.state == "Hold") held_seen = true;
    if (pr.acked >= 20 && !held_at) {
      c.hold = true;
      held_at = rig.clock.now();
    }
    // The operator lets go 300 ms (of the clock) after holding.
    if (held_at && c.hold && rig.clock.now() - *held_at >= 300ms) c.hold = false;
  });
  ASSERT_TRUE(held_at);
  EXPECT_FALSE(c.hold.load());
  EXPECT_TRUE(held_seen);
  const auto ev = fake.events();
  EXPECT_EQ(std::count(ev.begin(), ev.end(), "!"), 1);
  EXPECT_EQ(std::count(ev.begin(), ev.end(), "~"), 1);
  EXPECT_LT(index_of(ev, "!"), index_of(ev, "~"));
  EXPECT_EQ(fake.executed(), p.lines);  // resumed and finished
}

TEST(GrblSession, SilentControllerIsDetected) {
  FakeScript script;
  script.silent_at = 5;
  Rig rig(script);
  Session& s = rig.s;
  s.connect();
  const Program p = parse_program(job_text(50), 6000);
  Controls c;
  const auto t0 = rig.clock.now();
  EXPECT_THROW(s.stream(p, StreamMode::character_counting, c, {}), Silent);
  EXPECT_LT(rig.clock.now() - t0, 3s);
}

TEST(GrblSession, LostLinkPropagates) {
  FakeScript script;
  script.disconnect_at = 5;
  Rig rig(script);
  Session& s = rig.s;
  s.connect();
  const Program p = parse_program(job_text(50), 6000);
  Controls c;
  EXPECT_THROW(s.stream(p, StreamMode::character_counting, c, {}), LinkLost);
}

TEST(GrblSession, CheckModeRunsTheJobThenWaitsForTheResetThatEndsIt) {
  Rig rig;
  const FakeGrbl& fake = *rig.fake;
  Session& s = rig.s;
  s.connect();
  const Program p = parse_program(job_text(80), 6000);
  Controls c;
  size_t acked = 0;
  s.check(p, StreamMode::character_counting, c, [&](const Progress& pr) { acked = pr.acked; });
  EXPECT_EQ(acked, p.lines.size());
  const auto ev = fake.events();
  const size_t on = index_of(ev, "line:$C");
  const size_t off = index_of(ev, "line:$C", on + 1);
  ASSERT_LT(off, ev.size());
  std::vector<std::string> expected;
  for (const auto& l : p.lines) expected.push_back("line:" + l);
  EXPECT_EQ(std::vector<std::string>(ev.begin() + on + 1, ev.begin() + off), expected);
  EXPECT_LT(index_of(ev, "reset", off), ev.size());  // GRBL reset itself on leaving check mode
  // The session waited for the banner: the next command is answered normally.
  s.command("G0X0Y0");
  EXPECT_EQ(fake.executed().back(), "G0X0Y0");
}

TEST(GrblSession, CheckModeReportsTheFirstBadLine) {
  FakeScript script;
  script.error_at = 7;
  Rig rig(script);
  Session& s = rig.s;
  s.connect();
  const Program p = parse_program(job_text(80), 6000);
  Controls c;
  try {
    s.check(p, StreamMode::character_counting, c, {});
    FAIL() << "expected GrblError";
  } catch (const GrblError& e) {
    EXPECT_EQ(e.code, 33);
    EXPECT_EQ(e.line_number, static_cast<size_t>(p.source_line[7]));
  }
  EXPECT_EQ(s.query_status().state, "Idle");  // out of check mode again
}

TEST(GrblSession, FrameTracesTheBoundsAndWaitsForIdle) {
  Rig rig;
  const FakeGrbl& fake = *rig.fake;
  Session& s = rig.s;
  s.connect();
  Controls c;
  s.frame(Bounds{0, 0, 100, 50}, 3000, c);
  EXPECT_EQ(fake.executed(), frame_program(Bounds{0, 0, 100, 50}, 3000).lines);
  EXPECT_EQ(fake.state_name(), "Idle");
}

TEST(GrblSession, CommandErrorNamesTheCommand) {
  FakeScript script;
  script.start_in_alarm = true;
  Rig rig(script);
  Session& s = rig.s;
  s.connect();
  try {
    s.command("G0X10");
    FAIL() << "expected GrblError";
  } catch (const GrblError& e) {
    EXPECT_EQ(e.code, 9);
    EXPECT_EQ(e.line_number, 0u);
    EXPECT_STREQ(e.what(), "command 'G0X10': error:9 G-code lock: G-code commands are locked out during alarm or jog state");
  }
}

// ---- Time left, work offset and operator controls (issue 20) ----

// "45 s left" must not freeze while GRBL runs lines it acknowledged long ago: with three 3 s
// moves all acknowledged at once (the planner takes them), the reports in between count down.
TEST(GrblSession, TimeLeftCountsDownWhileGrblRunsAcknowledgedLines) {
  FakeScript script;
  script.motion = 3000ms;  // each G1 of 30 mm at 600 mm/min below
  Rig rig(script);
  Session& s = rig.s;
  s.connect();
  const Program p = parse_program("G21 G90\nG1 X30 F600\nG1 X60\nG1 X90\n", 6000);
  // 9 s at 10 mm/s, plus 0.02 s for the ramps at 500 mm/s^2 (GRBL's planner model).
  ASSERT_NEAR(p.total_seconds(), 9.02, 0.005);
  std::vector<std::pair<size_t, double>> seen;  // (acked, seconds_left) per report
  Controls c;
  s.stream(p, StreamMode::character_counting, c, [&](const Progress& pr) { seen.emplace_back(pr.acked, pr.seconds_left); });
  ASSERT_GT(seen.size(), 20u);
  int falls_with_all_acked = 0;
  for (size_t i = 1; i < seen.size(); ++i) {
    EXPECT_LE(seen[i].second, seen[i - 1].second + 1e-9) << "report " << i;  // never goes up
    if (seen[i].first == 4 && seen[i - 1].first == 4 && seen[i].second < seen[i - 1].second) ++falls_with_all_acked;
  }
  EXPECT_GE(falls_with_all_acked, 20);  // about every 200 ms poll over 9 s, not at 3 block ends only
  EXPECT_DOUBLE_EQ(seen.back().second, 0.0);
}

TEST(GrblSession, ConnectReadsTheWorkOffsetAndSetOriginHereMovesIt) {
  Rig rig;
  Session& s = rig.s;
  s.connect();
  EXPECT_NE(index_of(rig.fake->commands(), "$#"), rig.fake->commands().size());
  EXPECT_EQ(s.work_offset(), (std::array<double, 3>{0, 0, 0}));
  s.set_origin_here();  // the head is at machine (1, 2, 0)
  EXPECT_EQ(s.work_offset(), (std::array<double, 3>{1, 2, 0}));
}

TEST(GrblSession, HomeUnlocksAndJogWaitsForTheMoveToEnd) {
  FakeScript script;
  script.start_in_alarm = true;
  script.motion = 400ms;
  Rig rig(script);
  Session& s = rig.s;
  EXPECT_TRUE(s.connect().alarm_locked);
  s.home();
  EXPECT_FALSE(s.info().alarm_locked);
  const auto before = rig.clock.now();
  s.jog(10, -5, 1500);
  EXPECT_GE(rig.clock.now() - before, 400ms);  // returned only once the jog was over
  EXPECT_EQ(s.last_status().state, "Idle");
  EXPECT_NE(index_of(rig.fake->commands(), "$J=G91G21X10.000Y-5.000F1500"), rig.fake->commands().size());
}

TEST(GrblSession, AJogTurnsTheBeamOffFirstSoAModalM3CannotBurnAlongTheWay) {
  Rig rig;
  Session& s = rig.s;
  s.connect();
  s.console("M3 S1000");  // an operator's console line leaves the spindle modal on
  s.jog(5, 0, 1200);
  const auto& ev = rig.fake->events();
  const size_t m5 = index_of(ev, "line:M5", index_of(ev, "line:M3 S1000"));
  const size_t jog = index_of(ev, "line:$J=G91G21X5.000Y0.000F1200");
  ASSERT_LT(jog, ev.size());
  EXPECT_LT(m5, jog);  // the beam was off before the jog line reached GRBL
}

TEST(GrblSession, JogWhileLockedIsRefusedWithTheGrblError) {
  FakeScript script;
  script.start_in_alarm = true;
  Rig rig(script);
  rig.s.connect();
  try {
    rig.s.jog(1, 0, 600);
    FAIL() << "expected GrblError";
  } catch (const GrblError& e) {
    EXPECT_EQ(e.code, 9);
  }
}

TEST(GrblSession, ConsoleReturnsEveryLineUpToTheAnswerAndErrorsAreNotThrown) {
  Rig rig;
  Session& s = rig.s;
  s.connect();
  EXPECT_EQ(s.console("$G"), (std::vector<std::string>{"[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]", "ok"}));
  const auto status = s.console("?");
  ASSERT_EQ(status.size(), 1u);
  EXPECT_EQ(status[0].rfind("<Idle|MPos:1.000,2.000,0.000", 0), 0u);
  EXPECT_THROW(s.console("$RST=*"), std::invalid_argument);
  EXPECT_EQ(index_of(rig.fake->commands(), "$RST=*"), rig.fake->commands().size());  // never sent
}

TEST(GrblSession, ConsoleErrorIsTheLastLine) {
  FakeScript script;
  script.error_at = 0;
  Rig rig(script);
  rig.s.connect();
  EXPECT_EQ(rig.s.console("G1X1"), std::vector<std::string>{"error:33"});
}

// ---- Program pauses (M0) ----

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
  double laser_s() const {
    std::lock_guard lock(mu_);
    return ctl_.laser_s();
  }
  // Bytes an earlier host wrote at `now`, whose answers went with it (taken and dropped), and
  // the machine run on until `until`.
  void earlier_host_wrote(const std::string& bytes, Clock::time_point now, Clock::time_point until) {
    std::lock_guard lock(mu_);
    ctl_.host_write(bytes, us(now));
    ctl_.advance_to(us(until));
    ctl_.take_output();
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

// ---- A controller that was not reset ----

TEST(GrblReconnect, AControllerStillRunningAnEarlierJobIsSoftResetAndReportedLocked) {
  // A board whose auto-reset did not fire (the earlier host died; no DTR edge): it printed its
  // banner long ago and still burns the earlier job's queue. connect() must not wait for a
  // banner that never comes: no banner within `banner`, a soft reset stops it (beam off) and
  // its banner follows.
  FakeClock clock;
  auto laser = std::make_shared<EmulatedLaser>(clock.now());
  clock.advance(10ms);
  laser->earlier_host_wrote("G21 G90\nM3 S800\nG1 X100 F60\nG1 X0\nG1 X100\n", clock.now(), clock.now() + 1s);
  clock.advance(1s);
  ASSERT_EQ(laser->state(), "Run");
  ASSERT_GT(laser->laser_s(), 0);
  SimulatedTransport link(laser, clock);
  Session s(link, Timeouts{}, clock);
  const auto t0 = clock.now();
  const MachineInfo info = s.connect();
  EXPECT_EQ(laser->laser_s(), 0) << "the earlier job still burns";
  EXPECT_TRUE(info.alarm_locked) << "reset in motion: ALARM:3, the position may be lost";
  EXPECT_LE(clock.now() - t0, Timeouts{}.banner + Timeouts{}.stop + Timeouts{}.reply);
}

// ---- A session kept open between jobs (LaserDevice keeps its connection) ----

struct KeptSession {
  FakeClock clock;
  std::shared_ptr<laser_emu::testing::EmulatedLaserPeer> laser =
      std::make_shared<laser_emu::testing::EmulatedLaserPeer>(clock.now());
  SimulatedTransport link{laser, clock};
  Session s{link, Timeouts{}, clock};
};

TEST(GrblKeptSession, RevalidateReReadsSettingsAndOffsetsWithoutAResetOrTheBannerWait) {
  KeptSession k;
  k.s.connect();
  // A console line changes the travel and the work zero between two jobs.
  k.s.console("$130=250");
  k.s.console("G10L20P1X-5Y-7");
  const size_t mark = k.laser->received().size();
  const auto t0 = k.clock.now();
  const MachineInfo info = k.s.revalidate();
  EXPECT_DOUBLE_EQ(info.max_travel_x, 250);
  EXPECT_NEAR(k.s.work_offset()[0], 5, 1e-3);
  EXPECT_NEAR(k.s.work_offset()[1], 7, 1e-3);
  EXPECT_LT(k.clock.now() - t0, Timeouts{}.banner / 5) << "no banner wait on a kept link";
  const std::string sent = k.laser->received().substr(mark);
  EXPECT_NE(sent.find("$$\n"), std::string::npos) << sent;
  EXPECT_NE(sent.find("$#\n"), std::string::npos) << sent;
  EXPECT_EQ(sent.find("$I\n"), std::string::npos) << sent;
  EXPECT_EQ(k.laser->received().find('\x18'), std::string::npos) << "a reset re-runs the $N startup lines";
}

TEST(GrblKeptSession, ABannerSeenSinceTheLastUseMeansTheBoardRestartedAndIsSetUpAfresh) {
  KeptSession k;
  k.s.connect();
  k.s.jog(40, 0, 3000);
  ASSERT_NEAR(k.s.query_status().x, 40, 0.01);
  k.laser->reopened(k.clock.now());  // a reset button, a USB hiccup: the head's position is gone
  k.clock.advance(100ms);            // the next job comes later: the banner has arrived by then
  const size_t mark = k.laser->received().size();
  const MachineInfo info = k.s.revalidate();
  EXPECT_EQ(info.version, "1.1h.20190830");
  EXPECT_NE(k.laser->received().substr(mark).find("$I\n"), std::string::npos) << "not set up afresh";
  EXPECT_NEAR(k.s.last_status().x, 0, 0.01);
  EXPECT_EQ(k.laser->received().find('\x18'), std::string::npos);
}

TEST(GrblKeptSession, RevalidateOnALostLinkThrowsLinkLost) {
  KeptSession k;
  k.s.connect();
  k.link.disconnect();
  EXPECT_THROW(k.s.revalidate(), LinkLost);
}

}  // namespace
}  // namespace atelier::grbl

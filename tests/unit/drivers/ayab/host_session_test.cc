// The AYAB host session against scripted firmware peers on a simulated link: the firmware
// answers with canned replies and injected faults, in lock step with the session on a fake
// clock (no thread, no real time).
#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <optional>
#include <utility>

#include "base/fake_clock.h"
#include "drivers/ayab/host_session.h"
#include "drivers/ayab/pass_watch.h"
#include "drivers/simulated_transport.h"
#include "tests/support/carriage_firmware.h"

namespace atelier::ayab {
namespace {

using namespace std::chrono_literals;

struct PeerScript {
  uint8_t api = 6;
  std::chrono::milliseconds boot_delay{0};  // ignore reqInfo this long
  uint8_t start_error = 0;
  int drop_first_copy_of = -1;   // session line whose first cnfLine is "lost" (bad CRC)
  int wrong_request_after = -1;  // after this line, ask for line + 3 instead of line + 1
  int repeat_request_of = -1;    // ask for this line a second time (once)
  int disconnect_after = -1;     // unplug after receiving this line
  int silent_after = -1;         // stop answering after receiving this line
  int pause_after = -1;          // the knitter stops after this line (reqInfo still answered)
  std::chrono::milliseconds pause{0};
  std::chrono::milliseconds ready_after{0};  // the carriage crosses the turn mark this long after init
  bool silent_after_init = false;            // the firmware dies right after cnfInit
};

// Plays an AYAB v6 firmware as the far end of a SimulatedTransport, recording what the host
// sent: canned replies and injected faults, on the test's FakeClock.
class ScriptedFirmware : public SimulatedPeer {
 public:
  ScriptedFirmware(PeerScript script, int line_bytes, Clock::time_point born)
      : script_(script), line_bytes_(line_bytes), born_(born) {}

  std::vector<CnfLine> lines() const { return lines_; }
  std::vector<Message> received() const { return received_; }
  int count_received(MsgId id) const {
    int n = 0;
    for (const auto& m : received_)
      if (encode(m)[0] == static_cast<uint8_t>(id)) ++n;
    return n;
  }

  void receive(const uint8_t* data, size_t size, Clock::time_point now) override {
    resume_if_due(now);
    for (const Bytes& packet : dec_.feed(data, size)) {
      auto r = decode(packet, line_bytes_);
      if (!r.message) continue;
      received_.push_back(*r.message);
      if (silent_) continue;
      handle(*r.message, now);
      if (unplugged_) return;
    }
  }
  std::vector<uint8_t> take_output(Clock::time_point now) override {
    resume_if_due(now);
    return std::exchange(out_, {});
  }
  std::optional<Clock::time_point> next_event() const override {
    if (ready_at_ && (!paused_until_ || *ready_at_ < *paused_until_)) return ready_at_;
    return paused_until_;
  }
  bool unplugged() const override { return unplugged_; }

 private:
  void send(const Message& m) {
    const Bytes f = slip_encode(encode(m));
    out_.insert(out_.end(), f.begin(), f.end());
  }
  static IndState ready_state() {
    IndState s;
    s.state = FsmState::ready;
    return s;
  }
  // The knitter starts moving again: the request held back during the pause goes out.
  void resume_if_due(Clock::time_point now) {
    if (ready_at_ && now >= *ready_at_) {
      ready_at_.reset();
      if (!silent_) send(ready_state());
    }
    if (paused_until_ && now >= *paused_until_) {
      paused_until_.reset();
      send(ReqLine{paused_request_, 0});
    }
  }

  void handle(const Message& m, Clock::time_point now) {
    if (std::holds_alternative<ReqInfo>(m)) {
      if (now - born_ >= script_.boot_delay) send(CnfInfo{script_.api, 1, 0, 0, ""});
    } else if (std::holds_alternative<ReqInit>(m)) {
      send(CnfInit{0});
      send(Debug{"init"});  // noise the host must skip
      if (script_.silent_after_init) {
        silent_ = true;
      } else if (script_.ready_after.count() > 0) {
        ready_at_ = now + script_.ready_after;
      } else {
        send(ready_state());
      }
    } else if (std::holds_alternative<ReqStart>(m)) {
      send(CnfStart{script_.start_error});
      if (script_.start_error == 0) send(ReqLine{0, 0});
    } else if (const auto* c = std::get_if<CnfLine>(&m)) {
      // While the carriage stands still the firmware still holds the line it has: a
      // re-sent copy of it changes nothing.
      if (paused_until_ && c->line == static_cast<uint8_t>((expected_ - 1) & 0xFF)) return;
      if (c->line != static_cast<uint8_t>(expected_ & 0xFF)) {
        send(ReqLine{static_cast<uint8_t>(expected_ & 0xFF), 0});  // wrong line number
        return;
      }
      if (expected_ == script_.drop_first_copy_of) {
        script_.drop_first_copy_of = -1;  // as if its CRC were bad: silently dropped
        return;
      }
      lines_.push_back(*c);
      if (c->last_line) return;  // end of knitting: no more requests
      if (expected_ == script_.disconnect_after) {
        unplugged_ = true;
        return;
      }
      if (expected_ == script_.silent_after) {
        silent_ = true;
        return;
      }
      if (expected_ == script_.repeat_request_of) {
        script_.repeat_request_of = -1;
        send(ReqLine{static_cast<uint8_t>(expected_ & 0xFF), 0});
        return;
      }
      const int next = expected_ == script_.wrong_request_after ? expected_ + 3 : expected_ + 1;
      if (expected_ == script_.pause_after) {
        ++expected_;
        paused_until_ = now + script_.pause;
        paused_request_ = static_cast<uint8_t>(next & 0xFF);
        return;
      }
      ++expected_;
      send(ReqLine{static_cast<uint8_t>(next & 0xFF), 0});
    }
  }

  PeerScript script_;
  int line_bytes_;
  Clock::time_point born_;
  SlipDecoder dec_;
  std::vector<uint8_t> out_;
  int expected_ = 0;
  bool silent_ = false, unplugged_ = false;
  std::optional<Clock::time_point> paused_until_;
  uint8_t paused_request_ = 0;
  std::optional<Clock::time_point> ready_at_;  // the ready indState is due
  std::vector<CnfLine> lines_;
  std::vector<Message> received_;
};

// Nobody at the other end: whatever the host sends goes unanswered.
struct NoFirmware : SimulatedPeer {
  void receive(const uint8_t*, size_t, Clock::time_point) override {}
  std::vector<uint8_t> take_output(Clock::time_point) override { return {}; }
  std::optional<Clock::time_point> next_event() const override { return std::nullopt; }
};

SessionTimeouts fast() {
  SessionTimeouts t;
  t.boot = 5000ms;
  t.info_retry = 20ms;
  t.reply = 1000ms;
  t.ready = 5000ms;
  t.pass_end = 100ms;
  t.silent = 3000ms;
  return t;
}

// A host session and its scripted firmware on one FakeClock: the session's reads move the
// clock, so every timeout below passes in simulated time only.
struct Rig {
  explicit Rig(PeerScript script = {}, SessionTimeouts t = fast())
      : peer(std::make_shared<ScriptedFirmware>(script, 25, clock.now())), link(peer, clock), s(link, t, clock) {}

  FakeClock clock;
  std::shared_ptr<ScriptedFirmware> peer;
  SimulatedTransport link;
  HostSession s;
};


KnitPlan plan_of(int rows, int cols = 40) {
  cv::Mat pat(rows, cols, CV_8UC1, cv::Scalar(0));
  for (int r = 0; r < rows; ++r) pat.at<uint8_t>(r, (r * 7) % cols) = 1;
  return plan_knitting(pat, {});
}

struct KnitRun {
  std::vector<KnitProgress> progress;
  std::atomic<bool> cancel{false};
  int cancel_at = -1;
  std::function<void(const KnitProgress&)> callback() {
    return [this](const KnitProgress& p) {
      progress.push_back(p);
      if (p.passes_done == cancel_at) cancel = true;
    };
  }
};

TEST(AyabHostSession, KnitsThreeHundredRowsAcrossTheLineNumberWrap) {
  Rig rig;
  HostSession& s = rig.s;
  const ScriptedFirmware& peer = *rig.peer;
  EXPECT_EQ(s.connect().api, 6);
  s.init(MachineType::kh930);
  const KnitPlan plan = plan_of(300);
  KnitRun run;
  EXPECT_EQ(s.knit(plan, 0, run.callback(), run.cancel), 300);

  const auto lines = peer.lines();
  ASSERT_EQ(lines.size(), 301u);  // 300 rows + the blank last line
  for (int k = 0; k < 300; ++k) {
    EXPECT_EQ(lines[k].line, static_cast<uint8_t>(k & 0xFF));
    EXPECT_EQ(lines[k].needles, plan.passes[k]) << "row " << k;
    EXPECT_FALSE(lines[k].last_line);
  }
  EXPECT_TRUE(lines[300].last_line);
  EXPECT_EQ(lines[300].line, 300 & 0xFF);
  EXPECT_EQ(lines[300].needles, Bytes(25, 0));
  ASSERT_EQ(run.progress.size(), 300u);
  for (int k = 0; k < 300; ++k) {
    EXPECT_EQ(run.progress[k].passes_done, k + 1);
    EXPECT_EQ(run.progress[k].passes_total, 300);
  }
  // The start request carried the plan's needle range, and a reqInfo followed the last line.
  const auto rx = peer.received();
  bool start_seen = false;
  for (const auto& m : rx)
    if (const auto* r = std::get_if<ReqStart>(&m)) {
      start_seen = true;
      EXPECT_EQ(r->start_needle, plan.start_needle);
      EXPECT_EQ(r->stop_needle, plan.stop_needle);
      EXPECT_TRUE(r->continuous_reporting);  // the carriage is followed (indState at every step)
      EXPECT_TRUE(r->beeper);
    }
  EXPECT_TRUE(start_seen);
  ASSERT_FALSE(rx.empty());
  EXPECT_TRUE(std::holds_alternative<ReqInfo>(rx.back()));
}

TEST(AyabHostSession, RefusesApi5WithAClearMessage) {
  PeerScript script;
  script.api = 5;
  Rig rig(script);
  HostSession& s = rig.s;
  try {
    s.connect();
    FAIL() << "expected AyabError";
  } catch (const AyabError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("API v5"), std::string::npos) << what;
    EXPECT_NE(what.find("needs API v6"), std::string::npos) << what;
  }
}

TEST(AyabHostSession, ToleratesTheArduinoBootDelay) {
  PeerScript script;
  script.boot_delay = 1500ms;
  Rig rig(script);
  HostSession& s = rig.s;
  const ScriptedFirmware& peer = *rig.peer;
  EXPECT_EQ(s.connect().api, 6);
  EXPECT_GT(peer.count_received(MsgId::reqInfo), 1);  // asked again while the board booted
}

TEST(AyabHostSession, NoAnswerAtAllNamesTheCableAndFirmware) {
  FakeClock clock;
  SimulatedTransport host(std::make_shared<NoFirmware>(), clock);
  SessionTimeouts t = fast();
  t.boot = 300ms;
  HostSession s(host, t, clock);
  const auto t0 = clock.now();
  try {
    s.connect();
    FAIL() << "expected AyabError";
  } catch (const AyabError& e) {
    EXPECT_STREQ(e.what(),
                 "no answer from the knitting machine within 0.3 s: check the cable and that the AYAB firmware is "
                 "installed");
  }
  EXPECT_EQ(clock.now() - t0, 300ms);  // it gave up at the boot limit, not before or after
}

TEST(AyabHostSession, AnswersARepeatedRequestWithTheSameLine) {
  PeerScript script;
  script.repeat_request_of = 2;
  Rig rig(script);
  HostSession& s = rig.s;
  const ScriptedFirmware& peer = *rig.peer;
  s.connect();
  s.init(MachineType::kh930);
  const KnitPlan plan = plan_of(5);
  KnitRun run;
  EXPECT_EQ(s.knit(plan, 0, run.callback(), run.cancel), 5);
  const auto lines = peer.lines();
  ASSERT_EQ(lines.size(), 7u);  // line 2 twice, then 3, 4 and the blank line
  EXPECT_EQ(lines[2].needles, plan.passes[2]);
  EXPECT_EQ(lines[3].needles, plan.passes[2]);
  EXPECT_EQ(lines[4].needles, plan.passes[3]);
  EXPECT_EQ(run.progress.size(), 5u);  // the repeat confirmed nothing new
}

TEST(AyabHostSession, OutOfSequenceRequestAborts) {
  PeerScript script;
  script.wrong_request_after = 4;
  Rig rig(script);
  HostSession& s = rig.s;
  s.connect();
  s.init(MachineType::kh930);
  KnitRun run;
  try {
    s.knit(plan_of(20), 0, run.callback(), run.cancel);
    FAIL() << "expected AyabError";
  } catch (const AyabError& e) {
    EXPECT_STREQ(e.what(), "machine asked for line 7, expected 5");
  }
}

TEST(AyabHostSession, LinkLostMidKnitCountsExactlyThePassesDone) {
  PeerScript script;
  script.disconnect_after = 9;  // lines 0..8 confirmed by the request for 9; 9 itself not
  Rig rig(script);
  HostSession& s = rig.s;
  s.connect();
  s.init(MachineType::kh930);
  KnitRun run;
  EXPECT_THROW(s.knit(plan_of(20), 0, run.callback(), run.cancel), LinkLost);
  ASSERT_EQ(run.progress.size(), 9u);
  EXPECT_EQ(run.progress.back().passes_done, 9);
}

TEST(AyabHostSession, ResumeFromAPassNumbersLinesFromZero) {
  Rig rig;
  HostSession& s = rig.s;
  const ScriptedFirmware& peer = *rig.peer;
  s.connect();
  s.init(MachineType::kh930);
  const KnitPlan plan = plan_of(12);
  KnitRun run;
  EXPECT_EQ(s.knit(plan, 9, run.callback(), run.cancel), 12);
  const auto lines = peer.lines();
  ASSERT_EQ(lines.size(), 4u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(lines[k].line, k);
    EXPECT_EQ(lines[k].needles, plan.passes[9 + k]);
  }
  ASSERT_EQ(run.progress.size(), 3u);
  EXPECT_EQ(run.progress.front().passes_done, 10);
  EXPECT_EQ(run.progress.back().passes_done, 12);
}

TEST(AyabHostSession, CancelSendsTheBlankLastLineNextAndAFinalReqInfo) {
  Rig rig;
  HostSession& s = rig.s;
  const ScriptedFirmware& peer = *rig.peer;
  s.connect();
  s.init(MachineType::kh930);
  KnitRun run;
  run.cancel_at = 5;
  EXPECT_EQ(s.knit(plan_of(20), 0, run.callback(), run.cancel), 5);
  const auto lines = peer.lines();
  ASSERT_EQ(lines.size(), 6u);
  EXPECT_TRUE(lines[5].last_line);
  EXPECT_EQ(lines[5].line, 5);
  EXPECT_EQ(lines[5].needles, Bytes(25, 0));
  const auto rx = peer.received();
  EXPECT_TRUE(std::holds_alternative<ReqInfo>(rx.back()));
}

TEST(AyabHostSession, StartErrorIsReported) {
  PeerScript script;
  script.start_error = err::needle_value_invalid;  // what firmware 1.0 answers a bad range
  Rig rig(script);
  HostSession& s = rig.s;
  s.connect();
  s.init(MachineType::kh930);
  KnitRun run;
  try {
    s.knit(plan_of(3), 0, run.callback(), run.cancel);
    FAIL() << "expected AyabError";
  } catch (const AyabError& e) {
    EXPECT_NE(std::string(e.what()).find("invalid needle range (0x11)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("80..119"), std::string::npos) << e.what();
  }
}

TEST(AyabHostSession, AKnitterPausingLongerThanTheSilenceLimitIsNotASilentMachine) {
  PeerScript script;
  script.pause_after = 2;
  script.pause = 1500ms;  // well over `silent`: the machine answers reqInfo meanwhile
  SessionTimeouts t = fast();
  t.silent = 400ms;
  Rig rig(script, t);
  HostSession& s = rig.s;
  const ScriptedFirmware& peer = *rig.peer;
  s.connect();
  s.init(MachineType::kh930);
  KnitRun run;
  EXPECT_EQ(s.knit(plan_of(6), 0, run.callback(), run.cancel), 6);
  EXPECT_EQ(peer.lines().size(), 7u);  // 6 rows and the blank last line
}

TEST(AyabHostSession, SilentMachineFailsNamingTheRow) {
  PeerScript script;
  script.silent_after = 3;
  SessionTimeouts t = fast();
  t.silent = 400ms;
  Rig rig(script, t);
  HostSession& s = rig.s;
  s.connect();
  s.init(MachineType::kh930);
  KnitRun run;
  try {
    s.knit(plan_of(10), 0, run.callback(), run.cancel);
    FAIL() << "expected AyabError";
  } catch (const AyabError& e) {
    EXPECT_STREQ(e.what(), "the knitting machine went silent after row 3");
  }
}

TEST(AyabHostSession, AStartRefusedInTheWrongStateFailsAtOnceSayingToResetTheBoard) {
  // Firmware 1.0 answers reqStart outside its ready state with 0xEF, e.g. when it still knits
  // for a host that died. Nothing will make it ready by itself: no waiting for an indState.
  PeerScript script;
  script.start_error = err::wrong_machine_state;
  Rig rig(script);
  HostSession& s = rig.s;
  s.connect();
  s.init(MachineType::kh930);
  const auto t0 = rig.clock.now();
  KnitRun run;
  try {
    s.knit(plan_of(3), 0, run.callback(), run.cancel);
    FAIL() << "expected StartRefused";
  } catch (const StartRefused& e) {
    EXPECT_TRUE(e.wrong_state());
    EXPECT_EQ(std::string(e.what()).rfind("the knitting machine refused to start: wrong machine state (0xef)", 0), 0u)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("reset it"), std::string::npos) << e.what();
  }
  EXPECT_LE(rig.clock.now() - t0, fast().reply);
  EXPECT_TRUE(rig.peer->lines().empty());
}

TEST(AyabHostSession, WaitingForTheCarriageEndsWhenTheMachineStopsAnswering) {
  // The wait for the turn mark has no limit of its own (ready = 0: a person moves the
  // carriage), but a machine that no longer answers ends it.
  PeerScript script;
  script.silent_after_init = true;
  SessionTimeouts t = fast();
  t.ready = 0ms;
  t.silent = 400ms;
  Rig rig(script, t);
  HostSession& s = rig.s;
  s.connect();
  const auto t0 = rig.clock.now();
  try {
    s.init(MachineType::kh930);
    FAIL() << "expected AyabError";
  } catch (const AyabError& e) {
    EXPECT_NE(std::string(e.what()).find("stopped answering while waiting for the carriage"), std::string::npos)
        << e.what();
  }
  EXPECT_LE(rig.clock.now() - t0, t.silent + t.reply + 100ms);
}

TEST(AyabHostSession, AKnitterMayTakeLongerThanTheSilenceLimitToReachTheTurnMark) {
  PeerScript script;
  script.ready_after = 2000ms;  // five times `silent`; reqInfo is answered meanwhile
  SessionTimeouts t = fast();
  t.ready = 0ms;
  t.silent = 400ms;
  Rig rig(script, t);
  HostSession& s = rig.s;
  s.connect();
  s.init(MachineType::kh930);
  EXPECT_TRUE(s.was_reset());
  KnitRun run;
  EXPECT_EQ(s.knit(plan_of(2), 0, run.callback(), run.cancel), 2);
}

// A host session against the carriage-moving firmware (tests/support/carriage_firmware.h).
struct CarriageRig {
  explicit CarriageRig(test::CarriageScript script = {}, SessionTimeouts t = fast())
      : peer(std::make_shared<test::CarriageFirmware>(script)), link(peer, clock), s(link, t, clock) {}
  FakeClock clock;
  std::shared_ptr<test::CarriageFirmware> peer;
  SimulatedTransport link;
  HostSession s;
};

// The needles of the working range of `plan`'s pass `p`, as the firmware records them.
std::string pass_needles(const KnitPlan& plan, size_t p) {
  std::string out;
  for (int n = plan.start_needle; n <= plan.stop_needle; ++n) out.push_back(needle_selected(plan.passes[p], n) ? '1' : '0');
  return out;
}

TEST(AyabHostSession, EachLineGoesOutOnceEvenWhenTheCarriageIsSlowAndTheLastPassIsWaitedFor) {
  // A pass takes seconds here, far longer than any re-send window: a re-sent line could only
  // replace a good copy with a garbled one, so each line goes out once.
  test::CarriageScript script;
  script.step = 20ms;
  CarriageRig rig(script);
  rig.s.connect();
  rig.s.init(MachineType::kh930);
  const KnitPlan plan = plan_of(6);
  KnitRun run;
  EXPECT_EQ(rig.s.knit(plan, 0, run.callback(), run.cancel), 6);
  for (int k = 0; k <= 6; ++k) EXPECT_EQ(rig.peer->copies_of(k), 1) << "line " << k;
  // The knit ended after the carriage made the blank last line's pass, not before.
  const auto& passes = rig.peer->passes();
  ASSERT_EQ(passes.size(), 7u);
  for (size_t p = 0; p < 6; ++p) EXPECT_EQ(passes[p], pass_needles(plan, p)) << "pass " << p;
  EXPECT_EQ(passes[6], std::string(40, '0'));
  EXPECT_EQ(rig.peer->state(), FsmState::init);
}

TEST(AyabHostSession, AGarbledLineIsNeverCountedAsKnittedAndNamesThePass) {
  // Line 3 reaches the firmware garbled: it is in the needle buffer (copied before the CRC
  // check), the carriage knits it, and at the end of that pass the firmware asks for nothing.
  test::CarriageScript script;
  script.garble_first_copy_of = 3;
  CarriageRig rig(script);
  rig.s.connect();
  rig.s.init(MachineType::kh930);
  const KnitPlan plan = plan_of(8);
  KnitRun run;
  try {
    rig.s.knit(plan, 0, run.callback(), run.cancel);
    FAIL() << "expected LineGarbled";
  } catch (const LineGarbled& e) {
    EXPECT_EQ(e.pass, 3);
    EXPECT_NE(std::string(e.what()).find("pass 4 was knitted from a wrong line"), std::string::npos) << e.what();
  }
  ASSERT_FALSE(run.progress.empty());
  EXPECT_EQ(run.progress.back().passes_done, 3) << "the garbled pass was counted as knitted";
  const auto& passes = rig.peer->passes();
  ASSERT_GE(passes.size(), 4u);
  EXPECT_NE(passes[3], pass_needles(plan, 3)) << "the firmware model did not knit the garbled line";
  EXPECT_EQ(rig.peer->copies_of(3), 1) << "no blind re-send";
  EXPECT_EQ(passes.size(), 4u) << "the session stopped at the end of the garbled pass";
}

TEST(AyabHostSession, ACarriageOnTheNeedlesBeforeItsLineArrivedIsNeverCountedAsKnitted) {
  // The firmware reads line 2 only after the carriage is back on the needles: the pass knits the
  // old line's needles first, then the new one's, and the firmware asks on as if all were well.
  test::CarriageScript script;
  script.slow_line = 2;
  script.slow_for = 200ms;  // the carriage is back on the range after about 130 ms
  CarriageRig rig(script);
  rig.s.connect();
  rig.s.init(MachineType::kh930);
  const KnitPlan plan = plan_of(6);
  KnitRun run;
  try {
    rig.s.knit(plan, 0, run.callback(), run.cancel);
    FAIL() << "expected LineGarbled";
  } catch (const LineGarbled& e) {
    EXPECT_EQ(e.pass, 2);
    EXPECT_TRUE(e.early);
  }
  ASSERT_FALSE(run.progress.empty());
  EXPECT_EQ(run.progress.back().passes_done, 2);
}

TEST(AyabHostSession, AGarbledInitOrStartRequestIsAskedAgain) {
  // Firmware 1.0 answers a reqInit / reqStart whose CRC is bad with 0x04 and does nothing.
  test::CarriageScript script;
  script.init_garbled = 1;
  script.start_garbled = 2;
  CarriageRig rig(script);
  rig.s.connect();
  rig.s.init(MachineType::kh930);
  const KnitPlan plan = plan_of(3);
  KnitRun run;
  EXPECT_EQ(rig.s.knit(plan, 0, run.callback(), run.cancel), 3);
  EXPECT_EQ(rig.peer->passes().size(), 4u);
}

TEST(AyabHostSession, TellsWhenToMoveTheCarriageAndWhenOneMorePassIsLeft) {
  CarriageRig rig;
  std::vector<std::string> said;
  rig.s.set_events({[&] { said.push_back("turn mark (state " + state_name(rig.peer->state()) + ")"); },
                    [&] { said.push_back("last pass after " + std::to_string(rig.peer->passes().size())); }});
  rig.s.connect();
  rig.s.init(MachineType::kh930);
  const KnitPlan plan = plan_of(3);
  std::atomic<bool> cancel{false};
  rig.s.knit(plan, 0, [&](const KnitProgress& p) { said.push_back("pass " + std::to_string(p.passes_done)); },
             cancel);
  // The prompt comes while the firmware waits for the turn mark; the last pass is announced
  // when the last row is done and before the carriage makes it.
  EXPECT_EQ(said, (std::vector<std::string>{"turn mark (state init)", "pass 1", "pass 2", "pass 3", "last pass after 3"}));
  EXPECT_EQ(rig.peer->passes().size(), 4u);
}

TEST(AyabHostSession, AHungBoardIsReportedSilentWithThePassesDone) {
  test::CarriageScript script;
  script.hang_at_line = 4;
  SessionTimeouts t = fast();
  t.silent = 400ms;
  CarriageRig rig(script, t);
  rig.s.connect();
  rig.s.init(MachineType::kh930);
  KnitRun run;
  try {
    rig.s.knit(plan_of(8), 0, run.callback(), run.cancel);
    FAIL() << "expected MachineSilent";
  } catch (const MachineSilent& e) {
    EXPECT_EQ(e.passes_done, 4);
    EXPECT_STREQ(e.what(), "the knitting machine went silent after row 4");
  }
}

TEST(AyabHostSession, AKnitterPausingMidPatternWithTheCarriageReportedIsNotAGarbledLine) {
  test::CarriageScript script;
  script.pause_after_pass = 1;
  script.pause = 2000ms;
  SessionTimeouts t = fast();
  t.silent = 400ms;
  CarriageRig rig(script, t);
  rig.s.connect();
  rig.s.init(MachineType::kh930);
  const KnitPlan plan = plan_of(4);
  KnitRun run;
  EXPECT_EQ(rig.s.knit(plan, 0, run.callback(), run.cancel), 4);
  ASSERT_EQ(rig.peer->passes().size(), 5u);
  for (size_t p = 0; p < 4; ++p) EXPECT_EQ(rig.peer->passes()[p], pass_needles(plan, p));
}

TEST(AyabPassWatch, PixelsFollowFirmware10sOffsets) {
  // encoders.h START_OFFSET: moving right the left offset (K 42, L 32), moving left the right
  // one (K 16, L 24); below 0 it wraps by 256 (KH-270: 252, offsets 34 / 22).
  EXPECT_EQ(firmware_pixel(MachineType::kh930, 100, Direction::right, Carriage::knit), 58);
  EXPECT_EQ(firmware_pixel(MachineType::kh930, 100, Direction::left, Carriage::knit), 84);
  EXPECT_EQ(firmware_pixel(MachineType::kh930, 100, Direction::right, Carriage::lace), 68);
  EXPECT_EQ(firmware_pixel(MachineType::kh910, 100, Direction::left, Carriage::lace), 76);
  EXPECT_EQ(firmware_pixel(MachineType::kh930, 10, Direction::right, Carriage::knit), 224);
  EXPECT_EQ(firmware_pixel(MachineType::kh270, 10, Direction::right, Carriage::knit), 228);
  EXPECT_EQ(firmware_pixel(MachineType::kh270, 50, Direction::left, Carriage::knit), 28);
  EXPECT_FALSE(firmware_pixel(MachineType::kh930, 100, Direction::unknown, Carriage::knit).has_value());
  EXPECT_EQ(firmware_pixel(MachineType::kh930, 100, Direction::right, Carriage::none), 100);
}

TEST(AyabPassWatch, APassEndsThirteenNeedlesPastTheRangeOnEitherSide) {
  PassWatch w(MachineType::kh930, 80, 119);
  auto at = [](int pos, Direction d) {
    IndState s;
    s.state = FsmState::knit;
    s.carriage = Carriage::knit;
    s.position = static_cast<uint8_t>(pos);
    s.direction = d;
    return s;
  };
  // Moving right: needle = position - 42. Outside the range before working on it: no end.
  EXPECT_FALSE(w.on_state(at(60, Direction::right)));  // needle 18
  EXPECT_FALSE(w.on_state(at(122, Direction::right)));  // needle 80: in
  EXPECT_FALSE(w.on_state(at(173, Direction::right)));  // needle 131: 12 past
  EXPECT_TRUE(w.on_state(at(174, Direction::right)));   // needle 132: 13 past, the end
  EXPECT_FALSE(w.on_state(at(175, Direction::right)));  // once per pass
  w.line_requested();
  // Back to the left and out again on the side it came from: moving left, needle = position - 16.
  EXPECT_FALSE(w.on_state(at(130, Direction::left)));  // needle 114
  EXPECT_FALSE(w.on_state(at(84, Direction::left)));   // needle 68: 12 past
  EXPECT_TRUE(w.on_state(at(83, Direction::left)));    // needle 67
  EXPECT_TRUE(w.reporting());
}

}  // namespace
}  // namespace atelier::ayab

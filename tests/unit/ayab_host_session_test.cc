// The AYAB host session against scripted firmware peers on an in-memory link: a test thread
// plays the firmware with canned replies and injected faults.
#include <gtest/gtest.h>

#include <optional>

#include <atomic>
#include <mutex>
#include <thread>

#include "drivers/ayab/host_session.h"
#include "drivers/memory_transport.h"

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
};

// Plays an AYAB v6 firmware on one end of a memory pair, recording what the host sent.
class ScriptedFirmware {
 public:
  ScriptedFirmware(MemoryTransport& link, PeerScript script, int line_bytes)
      : link_(link), script_(script), line_bytes_(line_bytes), thread_([this] { run(); }) {}
  ~ScriptedFirmware() {
    stop_ = true;
    thread_.join();
  }

  std::vector<CnfLine> lines() {
    std::lock_guard lock(mutex_);
    return lines_;
  }
  std::vector<Message> received() {
    std::lock_guard lock(mutex_);
    return received_;
  }
  int count_received(MsgId id) {
    int n = 0;
    for (const auto& m : received())
      if (encode(m)[0] == static_cast<uint8_t>(id)) ++n;
    return n;
  }

 private:
  void send(const Message& m) {
    const Bytes f = slip_encode(encode(m));
    link_.write(f.data(), f.size());
  }

  void run() {
    const auto born = std::chrono::steady_clock::now();
    SlipDecoder dec;
    uint8_t buf[256];
    int expected = 0;
    bool silent = false;
    std::optional<std::chrono::steady_clock::time_point> paused_until;
    uint8_t paused_request = 0;
    try {
      while (!stop_) {
        if (paused_until && std::chrono::steady_clock::now() >= *paused_until) {
          paused_until.reset();
          send(ReqLine{paused_request, 0});
        }
        const size_t n = link_.read(buf, sizeof buf, 20ms);
        for (const Bytes& packet : dec.feed(buf, n)) {
          auto r = decode(packet, line_bytes_);
          if (!r.message) continue;
          {
            std::lock_guard lock(mutex_);
            received_.push_back(*r.message);
          }
          if (silent) continue;
          const Message& m = *r.message;
          if (std::holds_alternative<ReqInfo>(m)) {
            if (std::chrono::steady_clock::now() - born >= script_.boot_delay) send(CnfInfo{script_.api, 1, 0, 0, ""});
          } else if (std::holds_alternative<ReqInit>(m)) {
            send(CnfInit{0});
            send(Debug{"init"});  // noise the host must skip
            IndState s;
            s.state = FsmState::ready;
            send(s);
          } else if (std::holds_alternative<ReqStart>(m)) {
            send(CnfStart{script_.start_error});
            if (script_.start_error == 0) send(ReqLine{0, 0});
          } else if (const auto* c = std::get_if<CnfLine>(&m)) {
            // While the carriage stands still the firmware still holds the line it has: a
            // re-sent copy of it changes nothing.
            if (paused_until && c->line == static_cast<uint8_t>((expected - 1) & 0xFF)) continue;
            if (c->line != static_cast<uint8_t>(expected & 0xFF)) {
              send(ReqLine{static_cast<uint8_t>(expected & 0xFF), 0});  // wrong line number
              continue;
            }
            if (expected == script_.drop_first_copy_of) {
              script_.drop_first_copy_of = -1;  // as if its CRC were bad: silently dropped
              continue;
            }
            {
              std::lock_guard lock(mutex_);
              lines_.push_back(*c);
            }
            if (c->last_line) continue;  // end of knitting: no more requests
            if (expected == script_.disconnect_after) {
              link_.disconnect();
              return;
            }
            if (expected == script_.silent_after) {
              silent = true;
              continue;
            }
            if (expected == script_.repeat_request_of) {
              script_.repeat_request_of = -1;
              send(ReqLine{static_cast<uint8_t>(expected & 0xFF), 0});
              continue;
            }
            const int next = expected == script_.wrong_request_after ? expected + 3 : expected + 1;
            if (expected == script_.pause_after) {
              ++expected;
              paused_until = std::chrono::steady_clock::now() + script_.pause;
              paused_request = static_cast<uint8_t>(next & 0xFF);
              continue;
            }
            ++expected;
            send(ReqLine{static_cast<uint8_t>(next & 0xFF), 0});
          }
        }
      }
    } catch (const LinkLost&) {
    }
  }

  MemoryTransport& link_;
  PeerScript script_;
  int line_bytes_;
  std::atomic<bool> stop_{false};
  std::mutex mutex_;
  std::vector<CnfLine> lines_;
  std::vector<Message> received_;
  std::thread thread_;  // last: starts after everything above is ready
};

SessionTimeouts fast() {
  SessionTimeouts t;
  t.boot = 5000ms;
  t.info_retry = 20ms;
  t.reply = 1000ms;
  t.ready = 5000ms;
  t.line_resend = 100ms;
  t.silent = 3000ms;
  return t;
}

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
  auto [host, fw] = make_memory_pair();
  ScriptedFirmware peer(*fw, {}, 25);
  HostSession s(*host, fast());
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
      EXPECT_FALSE(r->continuous_reporting);
      EXPECT_TRUE(r->beeper);
    }
  EXPECT_TRUE(start_seen);
  ASSERT_FALSE(rx.empty());
  EXPECT_TRUE(std::holds_alternative<ReqInfo>(rx.back()));
}

TEST(AyabHostSession, RefusesApi5WithAClearMessage) {
  auto [host, fw] = make_memory_pair();
  PeerScript script;
  script.api = 5;
  ScriptedFirmware peer(*fw, script, 25);
  HostSession s(*host, fast());
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
  auto [host, fw] = make_memory_pair();
  PeerScript script;
  script.boot_delay = 1500ms;
  ScriptedFirmware peer(*fw, script, 25);
  HostSession s(*host, fast());
  EXPECT_EQ(s.connect().api, 6);
  EXPECT_GT(peer.count_received(MsgId::reqInfo), 1);  // asked again while the board booted
}

TEST(AyabHostSession, NoAnswerAtAllNamesTheCableAndFirmware) {
  auto [host, fw] = make_memory_pair();  // nobody plays the firmware
  SessionTimeouts t = fast();
  t.boot = 300ms;
  HostSession s(*host, t);
  try {
    s.connect();
    FAIL() << "expected AyabError";
  } catch (const AyabError& e) {
    EXPECT_STREQ(e.what(),
                 "no answer from the knitting machine within 0.3 s: check the cable and that the AYAB firmware is "
                 "installed");
  }
}

TEST(AyabHostSession, ResendsACnfLineTheFirmwareDropped) {
  auto [host, fw] = make_memory_pair();
  PeerScript script;
  script.drop_first_copy_of = 3;
  ScriptedFirmware peer(*fw, script, 25);
  HostSession s(*host, fast());
  s.connect();
  s.init(MachineType::kh930);
  const KnitPlan plan = plan_of(8);
  KnitRun run;
  EXPECT_EQ(s.knit(plan, 0, run.callback(), run.cancel), 8);
  const auto lines = peer.lines();
  ASSERT_EQ(lines.size(), 9u);
  for (int k = 0; k < 8; ++k) EXPECT_EQ(lines[k].needles, plan.passes[k]) << k;
  int copies_of_3 = 0;
  for (const auto& m : peer.received())
    if (const auto* c = std::get_if<CnfLine>(&m); c && c->line == 3) ++copies_of_3;
  EXPECT_GE(copies_of_3, 2);
}

TEST(AyabHostSession, AnswersARepeatedRequestWithTheSameLine) {
  auto [host, fw] = make_memory_pair();
  PeerScript script;
  script.repeat_request_of = 2;
  ScriptedFirmware peer(*fw, script, 25);
  HostSession s(*host, fast());
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
  auto [host, fw] = make_memory_pair();
  PeerScript script;
  script.wrong_request_after = 4;
  ScriptedFirmware peer(*fw, script, 25);
  HostSession s(*host, fast());
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
  auto [host, fw] = make_memory_pair();
  PeerScript script;
  script.disconnect_after = 9;  // lines 0..8 confirmed by the request for 9; 9 itself not
  ScriptedFirmware peer(*fw, script, 25);
  HostSession s(*host, fast());
  s.connect();
  s.init(MachineType::kh930);
  KnitRun run;
  EXPECT_THROW(s.knit(plan_of(20), 0, run.callback(), run.cancel), LinkLost);
  ASSERT_EQ(run.progress.size(), 9u);
  EXPECT_EQ(run.progress.back().passes_done, 9);
}

TEST(AyabHostSession, ResumeFromAPassNumbersLinesFromZero) {
  auto [host, fw] = make_memory_pair();
  ScriptedFirmware peer(*fw, {}, 25);
  HostSession s(*host, fast());
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
  auto [host, fw] = make_memory_pair();
  ScriptedFirmware peer(*fw, {}, 25);
  HostSession s(*host, fast());
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
  auto [host, fw] = make_memory_pair();
  PeerScript script;
  script.start_error = err::bad_argument;
  ScriptedFirmware peer(*fw, script, 25);
  HostSession s(*host, fast());
  s.connect();
  s.init(MachineType::kh930);
  KnitRun run;
  try {
    s.knit(plan_of(3), 0, run.callback(), run.cancel);
    FAIL() << "expected AyabError";
  } catch (const AyabError& e) {
    EXPECT_NE(std::string(e.what()).find("bad arguments"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("80..119"), std::string::npos) << e.what();
  }
}

TEST(AyabHostSession, AKnitterPausingLongerThanTheSilenceLimitIsNotASilentMachine) {
  auto [host, fw] = make_memory_pair();
  PeerScript script;
  script.pause_after = 2;
  script.pause = 1500ms;  // well over `silent`: the machine answers reqInfo meanwhile
  ScriptedFirmware peer(*fw, script, 25);
  SessionTimeouts t = fast();
  t.silent = 400ms;
  HostSession s(*host, t);
  s.connect();
  s.init(MachineType::kh930);
  KnitRun run;
  EXPECT_EQ(s.knit(plan_of(6), 0, run.callback(), run.cancel), 6);
  EXPECT_EQ(peer.lines().size(), 7u);  // 6 rows and the blank last line
}

TEST(AyabHostSession, SilentMachineFailsNamingTheRow) {
  auto [host, fw] = make_memory_pair();
  PeerScript script;
  script.silent_after = 3;
  ScriptedFirmware peer(*fw, script, 25);
  SessionTimeouts t = fast();
  t.silent = 400ms;
  HostSession s(*host, t);
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

}  // namespace
}  // namespace atelier::ayab

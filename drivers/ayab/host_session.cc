#include "drivers/ayab/host_session.h"

#include <optional>

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "drivers/ayab/line_tracker.h"
#include "drivers/ayab/pass_watch.h"

namespace atelier::ayab {
namespace {

using std::chrono::milliseconds;

// "5 s", "1.5 s".
std::string seconds_text(milliseconds ms) {
  char buf[32];
  if (ms.count() % 1000 == 0) std::snprintf(buf, sizeof buf, "%lld s", static_cast<long long>(ms.count() / 1000));
  else std::snprintf(buf, sizeof buf, "%.1f s", static_cast<double>(ms.count()) / 1000.0);
  return buf;
}

std::string version_text(const CnfInfo& c) {
  return std::to_string(c.fw_major) + "." + std::to_string(c.fw_minor) + "." + std::to_string(c.fw_patch);
}

// Upper bound of one blocking read, so "wait forever" never overflows a deadline.
constexpr milliseconds kReadSlice{1000};

// The firmware's answer to a request that reached it garbled (com.cpp: too short, bad CRC):
// nothing was done, so asking again is safe.
bool garbled_request(uint8_t error) { return error == err::too_short || error == err::bad_crc; }

// How often a cancel is looked at while the session waits for the last pass.
constexpr milliseconds kCancelPoll{500};

// Times a garbled reqStart is sent again before giving up.
constexpr int kStartAttempts = 3;

}  // namespace

HostSession::HostSession(Transport& link, SessionTimeouts timeouts, Clock& clock)
    : link_(link), timeouts_(timeouts), clock_(clock) {}

void HostSession::send(const Message& m) {
  const Bytes frame = slip_encode(encode(m));
  link_.write(frame.data(), frame.size());
}

std::optional<Message> HostSession::receive(Clock::time_point deadline) {
  uint8_t buf[256];
  for (;;) {
    if (!pending_.empty()) {
      Message m = std::move(pending_.front());
      pending_.pop_front();
      if (const auto* s = std::get_if<IndState>(&m)) {
        last_state_ = *s;
        state_seen_ = true;
      }
      return m;
    }
    const auto now = clock_.now();
    if (now >= deadline) return std::nullopt;
    const auto left = std::min<Clock::duration>(deadline - now, kReadSlice);
    const size_t n = link_.read(buf, sizeof buf, std::chrono::ceil<milliseconds>(left));
    for (const Bytes& packet : decoder_.feed(buf, n)) {
      // Garbled packets (line noise, bad CRC) are dropped; timeouts and re-sends recover.
      DecodeResult r = decode(packet, line_bytes_);
      if (r.message) pending_.push_back(std::move(*r.message));
    }
  }
}

CnfInfo HostSession::connect() {
  link_.flush_input();
  state_seen_ = false;
  decoder_ = SlipDecoder();
  pending_.clear();
  const auto deadline = clock_.now() + timeouts_.boot;
  // An Arduino resets when the port opens and ignores us for ~2 s: ask again and again.
  while (clock_.now() < deadline) {
    send(ReqInfo{});
    const auto retry = std::min(clock_.now() + timeouts_.info_retry, deadline);
    while (auto m = receive(retry)) {
      const auto* info = std::get_if<CnfInfo>(&*m);
      if (!info) continue;
      if (info->api < kApiVersion)
        throw AyabError("the knitting machine's AYAB firmware " + version_text(*info) + " speaks API v" +
                        std::to_string(info->api) + ", but atelier needs API v" + std::to_string(kApiVersion) +
                        " (AYAB firmware 1.0 or later): update the firmware");
      return *info;
    }
  }
  throw AyabError("no answer from the knitting machine within " + seconds_text(timeouts_.boot) +
                  ": check the cable and that the AYAB firmware is installed");
}

void HostSession::init(MachineType machine) {
  line_bytes_ = line_bytes(machine);
  started_ = false;
  const auto give_up = clock_.now() + timeouts_.silent;
  bool confirmed = false;
  while (!confirmed) {
    if (clock_.now() >= give_up)
      throw AyabError("the knitting machine did not confirm initialisation as " + machine_name(machine) +
                      " within " + seconds_text(timeouts_.silent));
    send(ReqInit{machine});
    const auto retry = std::min(clock_.now() + timeouts_.reply, give_up);
    while (auto m = receive(retry)) {
      const auto* c = std::get_if<CnfInit>(&*m);
      if (!c) continue;
      // Wrong state: the firmware is initialised already (the port was opened without
      // resetting the board, e.g. after a previous job). It knows its machine; go on to start.
      if (err::is_wrong_state(c->error)) {
        reset_ = false;
        return;
      }
      if (garbled_request(c->error)) break;  // it got our request garbled: ask again
      if (c->error != err::success)
        throw AyabError("the knitting machine refused initialisation as " + machine_name(machine) + ": " +
                        error_text(c->error));
      confirmed = true;
      break;
    }
  }
  reset_ = true;
  if (events_.waiting_for_carriage) events_.waiting_for_carriage();
  wait_ready();
}

void HostSession::wait_ready() {
  // The carriage must pass a turn mark; a person does that, so the wait may be long, but only
  // as long as the machine is there: after `silent` without a word, a reqInfo must be answered.
  // Firmware versions differ in the state they report with it (init or ready): error 0 counts.
  const auto deadline = timeouts_.ready.count() == 0 ? Clock::time_point::max() : clock_.now() + timeouts_.ready;
  auto last_rx = clock_.now();
  std::optional<Clock::time_point> probe_until;
  for (;;) {
    const auto silent_at = probe_until ? *probe_until : last_rx + timeouts_.silent;
    auto m = receive(std::min(deadline, silent_at));
    const auto now = clock_.now();
    if (!m) {
      if (now >= deadline)
        throw AyabError("the knitting machine did not become ready within " + seconds_text(timeouts_.ready) +
                        ": move the carriage across the turn mark");
      if (probe_until)
        throw MachineSilent(0, "the knitting machine stopped answering while waiting for the carriage to cross the turn "
                        "mark (no answer to an info request within " + seconds_text(timeouts_.reply) + ")");
      send(ReqInfo{});
      probe_until = now + timeouts_.reply;
      continue;
    }
    last_rx = now;
    probe_until.reset();
    const auto* st = std::get_if<IndState>(&*m);
    if (st && st->error == err::success && (st->state == FsmState::ready || st->state == FsmState::init)) return;
  }
}

void HostSession::start(const KnitPlan& plan) {
  line_bytes_ = line_bytes(plan.machine);
  // Continuous reporting: an indState at every needle step, for PassWatch.
  const ReqStart request{static_cast<uint8_t>(plan.start_needle), static_cast<uint8_t>(plan.stop_needle), true,
                         true};
  send(request);
  int attempts = 1;
  auto deadline = clock_.now() + timeouts_.reply;
  for (;;) {
    auto m = receive(deadline);
    if (!m)
      throw AyabError("the knitting machine did not answer the start request within " + seconds_text(timeouts_.reply));
    if (const auto* c = std::get_if<CnfStart>(&*m)) {
      if (c->error == err::success) break;
      if (garbled_request(c->error) && attempts < kStartAttempts) {
        ++attempts;  // the request reached it garbled and was not acted on
        send(request);
        deadline = clock_.now() + timeouts_.reply;
        continue;
      }
      if (err::is_wrong_state(c->error)) {
        // Firmware 1.0 does not say which state it is in; what this session saw does.
        std::string state = error_text(c->error);
        if (state_seen_) state += ", last reported in state " + state_name(last_state_.state);
        if (!reset_) state += "; it was not reset when the port opened and is still in an earlier session's state";
        throw StartRefused(c->error, "the knitting machine refused to start: " + state +
                                         "; reset it (the reset button on its Arduino, or unplug it for a moment; "
                                         "if its carriage has not crossed a turn mark since the last job, move it "
                                         "across one) and retry the job");
      }
      throw StartRefused(c->error, "the knitting machine refused to start knitting needles " +
                                       std::to_string(plan.start_needle) + ".." + std::to_string(plan.stop_needle) +
                                       ": " + error_text(c->error));
    }
    if (std::holds_alternative<ReqLine>(*m)) {
      pending_.push_front(std::move(*m));  // cnfStart lost, but the machine is knitting: go on
      break;
    }
  }
  started_ = true;
}

int HostSession::knit(const KnitPlan& plan, int from_pass, const std::function<void(const KnitProgress&)>& on_pass,
                      const std::atomic<bool>& cancel) {
  const int total = static_cast<int>(plan.passes.size());
  if (from_pass < 0 || from_pass > total)
    throw std::invalid_argument("knit: from_pass " + std::to_string(from_pass) + " outside 0.." + std::to_string(total));
  // Rows fully knitted after `passes` passes: a fixed number of passes per row, or (lace,
  // passes_per_row = 0) every row before the next pass's row.
  auto rows_done = [&plan, total](int passes) {
    if (plan.passes_per_row > 0) return passes / plan.passes_per_row;
    if (passes <= 0) return 0;
    if (passes >= total || passes >= static_cast<int>(plan.pattern_row.size()))
      return plan.pattern_row.empty() ? 0 : plan.pattern_row.back() + 1;
    return plan.pattern_row[passes];
  };
  line_bytes_ = line_bytes(plan.machine);
  if (!started_) start(plan);
  started_ = false;  // a next knit() starts again

  LineTracker tracker;
  PassWatch watch(plan.machine, plan.start_needle, plan.stop_needle);
  int done = from_pass;
  std::optional<CnfLine> last_sent;
  bool ended = false;     // blank last line sent
  bool canceled = false;  // ... because of `cancel`: its pass is not waited for
  // The firmware ended a pass at an indState received then: its reqLine must come next.
  std::optional<Clock::time_point> pass_ended_at;
  auto last_rx = clock_.now();
  // The reqInfo sent after the last cnfLine has been answered: the line is in the buffer.
  bool fenced = true;
  auto too_early = [&]() -> LineGarbled {
    const int pass = from_pass + tracker.expected() - 1;
    return LineGarbled(pass, true, "the carriage was on the needles before line " +
                                       std::to_string(tracker.expected() - 1) + " reached the knitting machine: pass " +
                                       std::to_string(pass + 1) + " mixes it with the line before");
  };
  auto garbled = [&]() -> LineGarbled {
    const int pass = from_pass + tracker.expected() - 1;
    return LineGarbled(pass, false, "the knitting machine did not ask for the line after line " +
                                 std::to_string(tracker.expected() - 1) +
                                 " at the end of its pass: that line reached it garbled and pass " +
                                 std::to_string(pass + 1) + " was knitted from a wrong line");
  };
  // A knitter may pause between rows for as long as they like, and the firmware says nothing
  // meanwhile. After `silent` without a word we ask for cnfInfo: a live machine answers it in
  // any state; only a machine that does not answer within `reply` is declared silent.
  std::optional<Clock::time_point> probe_until;
  for (;;) {
    // The end of a canceled job is not waited for; nor the last pass, when the firmware does
    // not report the carriage (then it cannot be seen).
    if (ended && (canceled || !watch.reporting())) break;
    const auto silent_at = probe_until ? *probe_until : last_rx + timeouts_.silent;
    auto deadline = pass_ended_at ? std::min(silent_at, *pass_ended_at + timeouts_.pass_end) : silent_at;
    // Waiting for the last pass, which the knitter may never make: a cancel ends the wait.
    if (ended) {
      if (cancel.load()) break;
      deadline = std::min(deadline, clock_.now() + kCancelPoll);
    }
    auto m = receive(deadline);
    const auto now = clock_.now();
    if (!m) {
      if (pass_ended_at && now >= *pass_ended_at + timeouts_.pass_end) throw garbled();
      if (now >= silent_at) {
        if (probe_until)
          throw MachineSilent(done, "the knitting machine went silent after row " + std::to_string(rows_done(done)));
        send(ReqInfo{});
        probe_until = now + timeouts_.reply;
      }
      continue;
    }
    last_rx = now;
    probe_until.reset();
    if (const auto* st = std::get_if<IndState>(&*m)) {
      // A report after the one that ended the pass, and no reqLine between: none will come.
      if (pass_ended_at) throw garbled();
      if (!fenced && !ended && last_sent && watch.in_range(*st)) throw too_early();
      // Out of the knit state after the last line: the firmware has stopped knitting.
      if (ended && st->state != FsmState::knit) break;
      if (watch.on_state(*st) && last_sent) {
        if (ended) break;  // the blank line's pass: the firmware stops knitting here
        pass_ended_at = now;
      }
      continue;
    }
    if (std::holds_alternative<CnfInfo>(*m)) {
      fenced = true;
      continue;
    }
    const auto* req = std::get_if<ReqLine>(&*m);
    if (!req) continue;  // debug, stray confirmations
    pass_ended_at.reset();
    if (req->error != err::success)
      throw AyabError("the knitting machine reported " + error_text(req->error) + " when asking for line " +
                      std::to_string(req->line));
    const LineTracker::Result r = tracker.on_request(req->line);
    if (r.kind == LineTracker::Kind::out_of_sequence)
      throw AyabError("machine asked for line " + std::to_string(req->line) + ", expected " +
                      std::to_string(r.line & 0xFF));
    if (r.kind == LineTracker::Kind::repeat) {
      send(*last_sent);  // the firmware did not take our answer (e.g. wrong line number)
      if (!ended) {
        send(ReqInfo{});
        fenced = false;
      }
      continue;
    }
    watch.line_requested();
    if (ended) continue;  // asked for a line after the last: nothing more to knit
    // Asking for line k confirms that lines 0..k-1 of this session were knitted.
    if (r.line > 0) {
      done = from_pass + r.line;
      if (on_pass) on_pass(KnitProgress{done, total});
    }
    const int pass = from_pass + r.line;
    CnfLine line;
    line.line = static_cast<uint8_t>(r.line & 0xFF);
    if (pass >= total || cancel.load()) {
      line.last_line = true;  // blank: all needles unselected; the machine ends cleanly
      line.needles.assign(static_cast<size_t>(line_bytes_), 0);
      ended = true;
      canceled = pass < total;
    } else {
      line.colour = plan.colour[static_cast<size_t>(pass)];
      line.needles = plan.passes[static_cast<size_t>(pass)];
    }
    send(line);
    last_sent = line;
    if (!ended) {
      send(ReqInfo{});  // the fence (see host_session.h)
      fenced = false;
    }
    if (ended && !canceled && events_.last_pass) events_.last_pass();
  }

  // reqInfo answered means the firmware has read everything before it, the last line included.
  const auto end_deadline = clock_.now() + timeouts_.reply;
  while (clock_.now() < end_deadline) {
    send(ReqInfo{});
    const auto retry = std::min(clock_.now() + timeouts_.info_retry, end_deadline);
    while (auto m = receive(retry)) {
      if (std::holds_alternative<CnfInfo>(*m)) return done;
      const auto* req = std::get_if<ReqLine>(&*m);
      if (req && req->line == last_sent->line) send(*last_sent);  // asked again for the last line
    }
  }
  throw AyabError("the knitting machine did not confirm the end of knitting within " + seconds_text(timeouts_.reply));
}

}  // namespace atelier::ayab

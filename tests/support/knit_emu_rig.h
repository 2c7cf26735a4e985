// Test helpers for the knitting-machine emulator: a scripted host around the pure firmware
// model, speaking encoded AYAB v6 messages on a simulated clock. Header-only; one thread.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "drivers/ayab/messages.h"
#include "drivers/ayab/slip.h"
#include "tools/knit_emu/firmware.h"

namespace atelier::knit_emu::testing {

namespace ab = atelier::ayab;

// The one message in `msgs`, of type T (a test failure otherwise).
template <class T>
T only(const std::vector<ab::Message>& msgs) {
  EXPECT_EQ(msgs.size(), 1u);
  const T* m = msgs.empty() ? nullptr : std::get_if<T>(&msgs.front());
  if (!m) {
    ADD_FAILURE() << "expected one message of the right type, got "
                  << (msgs.empty() ? std::string("nothing") : ab::describe(msgs.front()));
    return T{};
  }
  return *m;
}

// The messages of type T in `msgs`, in order.
template <class T>
std::vector<T> all_of(const std::vector<ab::Message>& msgs) {
  std::vector<T> out;
  for (const auto& m : msgs)
    if (const T* t = std::get_if<T>(&m)) out.push_back(*t);
  return out;
}

inline FirmwareOptions opts(ab::MachineType m = ab::MachineType::kh930, int64_t row_ms = 100) {
  FirmwareOptions o;
  o.machine = m;
  o.row_ms = row_ms;
  return o;
}

struct Rig {
  explicit Rig(FirmwareOptions o = {})
      : options(o), fw(o, [this](const KnittedRow& r) { rows.push_back(r); }) {}

  void send(const ab::Message& m) { fw.receive(ab::slip_encode(ab::encode(m))); }
  void send_payload(const ab::Bytes& payload) { fw.receive(ab::slip_encode(payload)); }
  void send_raw(const ab::Bytes& bytes) { fw.receive(bytes); }
  void advance(int64_t ms) {
    t += ms;
    fw.advance_to(t);
    pump();
  }
  // Every message the firmware has sent since the last call, decoded.
  std::vector<ab::Message> take() {
    pump();
    std::vector<ab::Message> out;
    out.swap(inbox);
    return out;
  }
  // Runs the clock event by event until `done` holds, nothing more would happen on its own, or
  // `max_ms` have passed; returns whether `done` holds. Messages stay for take().
  bool run_until(const std::function<bool()>& done, int64_t max_ms = 10000000) {
    const int64_t until = t + max_ms;
    pump();
    while (!done()) {
      const auto next = fw.next_event_ms();
      if (!next || *next > until) return false;
      t = std::max(t, *next);
      fw.advance_to(t);
      pump();
    }
    return true;
  }
  // Runs until the firmware sends a message of type T (true), kept for take() with the rest.
  template <class T>
  bool run_until_sent(int64_t max_ms = 10000000) {
    size_t seen = 0;
    return run_until(
        [&] {
          for (; seen < inbox.size(); ++seen)
            if (std::holds_alternative<T>(inbox[seen])) return true;
          return false;
        },
        max_ms);
  }
  // reqInfo, reqInit, then the knitter takes the carriage over the left turn mark: ready, and
  // the carriage at rest.
  void make_ready() {
    send(ab::ReqInfo{});
    send(ab::ReqInit{options.machine});
    run_until([&] { return fw.state() == ab::FsmState::ready && !fw.carriage_moving(); });
    take();
  }
  // reqStart (accepted) and, on a first job, the reqLine(0) that follows it at once.
  void start(uint8_t first, uint8_t last, bool continuous = false) {
    send(ab::ReqStart{first, last, continuous, true});
    const auto msgs = take();
    EXPECT_FALSE(msgs.empty());
    if (!msgs.empty()) {
      EXPECT_EQ(std::get<ab::CnfStart>(msgs.front()).error, ab::err::success);
    }
  }
  // Answers line n with rows[n] until every row is knitted, then sends the blank last line and
  // runs until the job has ended (state init) and the firmware is ready again.
  void knit_job(const std::vector<std::string>& rows_from_0, uint8_t first_line = 0) {
    for (size_t i = 0; i < rows_from_0.size(); ++i) {
      take();
      send(line(static_cast<uint8_t>(first_line + i), rows_from_0[i]));
      ASSERT_TRUE(run_until_sent<ab::ReqLine>()) << "no reqLine after line " << i;
    }
    take();
    send(line(static_cast<uint8_t>(first_line + rows_from_0.size()), "", true));
    ASSERT_TRUE(run_until([&] { return fw.state() == ab::FsmState::ready; })) << "the job never ended";
  }
  ab::CnfLine line(uint8_t n, const std::string& needles_from_0, bool last = false) const {
    ab::CnfLine c;
    c.line = n;
    c.last_line = last;
    c.needles.assign(static_cast<size_t>(ab::line_bytes(options.machine)), 0);
    for (size_t i = 0; i < needles_from_0.size(); ++i)
      ab::select_needle(c.needles, static_cast<int>(i), needles_from_0[i] == '1');
    return c;
  }

  FirmwareOptions options;
  std::vector<KnittedRow> rows;
  Firmware fw;
  ab::SlipDecoder dec{512};
  std::vector<ab::Message> inbox;  // decoded, not taken yet
  int64_t t = 0;

 private:
  void pump() {
    for (const auto& p : dec.feed(fw.take_output())) {
      auto d = ab::decode(p, ab::line_bytes(options.machine));
      if (d.message) inbox.push_back(*d.message);
    }
  }
};

}  // namespace atelier::knit_emu::testing

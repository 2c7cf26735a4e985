// Test helper: a scripted AYAB firmware 1.0 with a carriage that a knitter pushes to and fro,
// as the far end of a SimulatedTransport (a KH-930, knit carriage). It does what firmware 1.0's
// knitter.cpp and com.cpp do where the host session's correctness depends on it, written from
// their behaviour for the host tests (the emulator's model is tools/knit_emu/firmware.h):
// - cnfLine: the needle bytes go into the buffer BEFORE the CRC is checked; a bad CRC is
//   dropped without a word; a good copy of the requested line is accepted; a good copy of
//   another line gets reqLine(current) again.
// - the carriage sweeps positions 60..200, so the working range must lie within needles 57..145;
// - with continuous reporting, an indState (state knit, position 0..255, direction) at every
//   step of the carriage; a pass ends at the first needle 13 past the working range after a
//   needle inside it (needle = position - 42 moving right, - 16 moving left); then reqLine(n+1)
//   if a good line came, else nothing (the next pass knits the buffer again); with the
//   last-line flag the firmware stops (state init) without a word.
// - first run after boot: reqLine(0) right after cnfStart.
// - faults: a garbled copy of a line (one needle byte flipped, so its CRC is bad); a firmware
//   hung (as on a garbled SLIP escape) on receiving a line, until a DTR pulse (or for good); cnfInit / cnfStart answered 0x04 (garbled request) a few times.
// Records each pass as the needles knitted (one '0'/'1' per needle of the working range).
// Threading: used from the session's thread only; read results after the session is done.
// Header-only.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "drivers/ayab/messages.h"
#include "drivers/simulated_transport.h"

namespace atelier::test {

struct CarriageScript {
  std::chrono::milliseconds step{2};            // one carriage step (one firmware position)
  std::chrono::milliseconds turn_mark{100};     // after cnfInit, the carriage passes the turn mark
  int garble_first_copy_of = -1;                // session line whose first cnfLine arrives garbled
  int hang_at_line = -1;                        // hang on receiving this session line's cnfLine
  bool hang_before_ready = false;               // hang right after cnfInit (before the turn mark)
  bool hang_survives_reset = false;             // the hang needs a power cycle
  int init_garbled = 0;                         // cnfInit(0x04) this many times first
  int start_garbled = 0;                        // cnfStart(0x04) this many times first
  int slow_line = -1;                           // after asking for this session line, the firmware
  std::chrono::milliseconds slow_for{0};        // reads its input only this much later (the carriage goes on)
  int pause_after_pass = -1;                    // the knitter stops after this pass ...
  std::chrono::milliseconds pause{0};           // ... for this long
};

class CarriageFirmware : public SimulatedPeer {
 public:
  explicit CarriageFirmware(CarriageScript script) : script_(script) {}

  // The passes the carriage made while knitting, needles start..stop, leftmost first.
  const std::vector<std::string>& passes() const { return passes_; }
  int copies_of(int line) const {
    int n = 0;
    for (int l : cnf_lines_) n += l == line;
    return n;
  }
  int dtr_pulses() const { return dtr_pulses_; }
  ayab::FsmState state() const { return state_; }
  bool hung() const { return hung_; }

  void receive(const uint8_t* data, size_t size, Clock::time_point now) override {
    advance(now);
    if (hung_) return;
    if (slow_until_ && now < *slow_until_) {
      held_.insert(held_.end(), data, data + size);
      return;
    }
    for (const ayab::Bytes& packet : dec_.feed(data, size)) handle(packet, now);
  }
  std::vector<uint8_t> take_output(Clock::time_point now) override {
    advance(now);
    return std::exchange(out_, {});
  }
  std::optional<Clock::time_point> next_event() const override {
    if (hung_) return std::nullopt;
    if (ready_at_) return ready_at_;
    return next_step_;
  }
  void dtr_pulse(Clock::time_point, std::chrono::milliseconds) override {
    ++dtr_pulses_;
    if (script_.hang_survives_reset) return;
    const CarriageScript script = script_;
    const int pulses = dtr_pulses_;
    auto passes = std::move(passes_);
    auto lines = std::move(cnf_lines_);
    *this = CarriageFirmware(script);  // a fresh boot, wait-for-machine
    script_.hang_at_line = -1;
    script_.hang_before_ready = false;
    dtr_pulses_ = pulses;
    passes_ = std::move(passes);
    cnf_lines_ = std::move(lines);
  }

 private:
  // The carriage sweeps positions 60..200: working ranges within needles 57..145.
  int start_ = 0, stop_ = 0;
  void send(const ayab::Message& m) {
    const ayab::Bytes f = ayab::slip_encode(ayab::encode(m));
    out_.insert(out_.end(), f.begin(), f.end());
  }
  void send_state() {
    ayab::IndState s;
    s.state = state_;
    s.carriage = ayab::Carriage::knit;
    s.position = static_cast<uint8_t>(position_);
    s.direction = right_ ? ayab::Direction::right : ayab::Direction::left;
    send(s);
  }
  void req_line() {
    send(ayab::ReqLine{static_cast<uint8_t>(line_ & 0xFF), 0});
    requested_ = true;
    if (line_ == script_.slow_line) slow_until_ = next_step_.value_or(Clock::time_point{}) + script_.slow_for;
  }

  void handle(const ayab::Bytes& packet, Clock::time_point now) {
    if (packet.empty()) return;
    const auto id = static_cast<ayab::MsgId>(packet[0]);
    if (id == ayab::MsgId::cnfLine) {
      if (packet.size() < 25 + 5) return;
      if (packet[1] == script_.hang_at_line) {
        hung_ = true;  // as on a garbled SLIP escape inside this line: nothing more, until reset
        return;
      }
      cnf_lines_.push_back(packet[1]);
      ayab::Bytes copy = packet;
      if (packet[1] == script_.garble_first_copy_of) {
        script_.garble_first_copy_of = -1;
        copy[4 + 12] ^= 0x5A;  // needles 96..103: inside the working range
      }
      buffer_.assign(copy.begin() + 4, copy.begin() + 29);  // copied before the CRC check
      const auto r = ayab::decode(copy, 25);
      if (!r.message) return;  // bad CRC: not a word
      const auto& c = std::get<ayab::CnfLine>(*r.message);
      if (!requested_) return;
      if (c.line != static_cast<uint8_t>(line_ & 0xFF)) {
        send(ayab::ReqLine{static_cast<uint8_t>(line_ & 0xFF), 0});
        return;
      }
      requested_ = false;
      if (c.last_line) last_ = true;
      return;
    }
    const auto r = ayab::decode(packet, 25);
    if (!r.message) return;
    if (std::holds_alternative<ayab::ReqInfo>(*r.message)) {
      send(ayab::CnfInfo{6, 1, 0, 0, ""});
    } else if (std::holds_alternative<ayab::ReqInit>(*r.message)) {
      if (script_.init_garbled > 0) {
        --script_.init_garbled;
        send(ayab::CnfInit{ayab::err::bad_crc});
        return;
      }
      if (state_ != ayab::FsmState::wait_for_machine) {
        send(ayab::CnfInit{ayab::err::wrong_machine_state});
        return;
      }
      state_ = ayab::FsmState::init;
      send(ayab::CnfInit{0});
      if (script_.hang_before_ready) hung_ = true;
      else ready_at_ = now + script_.turn_mark;
    } else if (const auto* s = std::get_if<ayab::ReqStart>(&*r.message)) {
      if (script_.start_garbled > 0) {
        --script_.start_garbled;
        send(ayab::CnfStart{ayab::err::bad_crc});
        return;
      }
      if (state_ != ayab::FsmState::ready) {
        send(ayab::CnfStart{ayab::err::wrong_machine_state});
        return;
      }
      continuous_ = s->continuous_reporting;
      start_ = s->start_needle;
      stop_ = s->stop_needle;
      state_ = ayab::FsmState::knit;
      send(ayab::CnfStart{0});
      line_ = 0;
      req_line();  // first run after boot
      next_step_ = now + script_.step;
    }
  }

  void advance(Clock::time_point now) {
    if (hung_) return;
    if (ready_at_ && now >= *ready_at_) {
      ready_at_.reset();
      position_ = 40;  // just past the left turn mark, moving right
      right_ = true;
      ayab::IndState s;  // firmware 1.0 reports it with the state byte still init
      s.state = ayab::FsmState::init;
      s.carriage = ayab::Carriage::knit;
      s.position = static_cast<uint8_t>(position_);
      s.direction = ayab::Direction::right;
      send(s);
      state_ = ayab::FsmState::ready;
    }
    while (next_step_ && now >= *next_step_ && !hung_) {
      const auto at = *next_step_;
      next_step_ = at + script_.step;
      if (slow_until_ && at >= *slow_until_) {  // the input held back is read now
        slow_until_.reset();
        const auto held = std::exchange(held_, {});
        for (const ayab::Bytes& packet : dec_.feed(held.data(), held.size())) handle(packet, at);
      }
      step(at);
    }
  }

  void step(Clock::time_point at) {
    if (state_ != ayab::FsmState::knit) {
      next_step_.reset();
      return;
    }
    position_ += right_ ? 1 : -1;
    if (position_ >= 200) right_ = false;
    if (position_ <= 60) right_ = true;
    if (continuous_) send_state();
    const int needle = position_ - (right_ ? 42 : 16);
    if (needle >= start_ && needle <= stop_) worked_ = true;
    if (!worked_ || (needle >= start_ - 12 && needle <= stop_ + 12)) return;
    worked_ = false;
    std::string knitted;
    for (int n = start_; n <= stop_; ++n) knitted.push_back(ayab::needle_selected(buffer_, n) ? '1' : '0');
    passes_.push_back(knitted);
    if (!requested_ && !last_) {
      ++line_;
      req_line();
    } else if (last_) {
      state_ = ayab::FsmState::init;  // the double beep; not a word on the line
      next_step_.reset();
      return;
    }
    if (static_cast<int>(passes_.size()) - 1 == script_.pause_after_pass) next_step_ = at + script_.pause;
  }

  CarriageScript script_;
  ayab::SlipDecoder dec_;
  std::vector<uint8_t> out_;
  ayab::FsmState state_ = ayab::FsmState::wait_for_machine;
  std::optional<Clock::time_point> ready_at_, next_step_;
  int position_ = 0;
  bool right_ = true;
  bool continuous_ = false;
  bool worked_ = false, requested_ = false, last_ = false, hung_ = false;
  int line_ = 0;
  ayab::Bytes buffer_ = ayab::Bytes(25, 0);
  std::vector<std::string> passes_;
  std::vector<int> cnf_lines_;
  int dtr_pulses_ = 0;
  std::optional<Clock::time_point> slow_until_;
  std::vector<uint8_t> held_;
};

}  // namespace atelier::test

#include "tools/knit_emu/firmware.h"

#include <algorithm>
#include <cstdio>

#include "drivers/ayab/crc8.h"
#include "tools/knit_emu/bed.h"

namespace atelier::knit_emu {
namespace ab = ayab;

namespace {
constexpr uint8_t kNoMachine = 0xFF;
constexpr int64_t kTestLoopMs = 500;  // TEST_LOOP_DELAY
// How far past the line-finished point the knitter takes the carriage.
constexpr int kKnitterOvershoot = 2;
// Test-mode command ids (com.h AYAB_API).
enum : uint8_t {
  kHelp = 0x25, kSendCmd = 0x26, kBeep = 0x27, kSetSingle = 0x28, kSetAll = 0x29,
  kReadEol = 0x2A, kReadEnc = 0x2B, kAutoRead = 0x2C, kAutoTest = 0x2D, kStop = 0x2E, kQuit = 0x2F,
};
}  // namespace

Firmware::Firmware(FirmwareOptions options, RowObserver on_row, int64_t start_ms)
    : opt_(std::move(options)), on_row_(std::move(on_row)), now_(start_ms), rng_(opt_.faults.seed) {
  // A machine that went silent stays silent after a reset.
  silent_ = opt_.faults.silent_after_row && opt_.rows_before >= *opt_.faults.silent_after_row;
  if (opt_.boot_ms > 0) boot_until_ = start_ms + opt_.boot_ms;
  if (opt_.carriage_position) x_ = std::clamp(*opt_.carriage_position, 0, bed::last_position(opt_.machine));
  resting_since_ = start_ms;
}

ab::MachineType Firmware::fw_machine() const {
  if (machine_ && *machine_ <= 2) return static_cast<ab::MachineType>(*machine_);
  return opt_.machine;
}

uint8_t Firmware::next_corruption_mask() {
  if (opt_.faults.corrupt <= 0.0) return 0;
  // 53 random bits as a double in [0,1): mt19937_64 is fully specified, so a seed hits the
  // same bytes on every platform.
  const double u = static_cast<double>(rng_() >> 11) * (1.0 / 9007199254740992.0);
  if (u >= opt_.faults.corrupt) return 0;
  return static_cast<uint8_t>(1 + rng_() % 255);
}

void Firmware::receive(const uint8_t* data, size_t size) {
  if (stopped() || size == 0) return;
  if (boot_until_ && now_ < *boot_until_) return;  // still booting: the bytes are lost
  ab::Bytes in(data, data + size);
  for (auto& b : in) b ^= next_corruption_mask();
  for (auto& packet : slip_.feed(in.data(), in.size())) {
    handle_packet(std::move(packet));
    if (stopped()) return;
  }
}

void Firmware::send(const ab::Message& m) {
  if (stopped()) return;
  out_.emplace_back(now_ + opt_.faults.delay_ms, ab::slip_encode(ab::encode(m)));
}

void Firmware::beep(bool line_accepted) {
  ++beeps_;
  if (line_accepted) beep_at_ = now_;
}

uint16_t Firmware::hall(bool left) const {
  const ab::MachineType m = opt_.machine;
  const bool over = left ? (x_ >= bed::left_sensor(m) && x_ <= bed::left_sensor(m) + bed::kMagnetWidth)
                         : (x_ <= bed::right_sensor(m) && x_ >= bed::right_sensor(m) - bed::kMagnetWidth);
  return over ? bed::hall_k_carriage(m, left) : bed::hall_idle(m, left);
}

// Encoders::detectCarriageLeft/Right for the K carriage (FILTER_*: above 600 is K; the KH-910's
// right sensor reads low for K).
ab::Carriage Firmware::detect(bool left) const {
  const uint16_t v = hall(left);
  if (!left && fw_machine() == ab::MachineType::kh910) return v < 200 ? ab::Carriage::knit : ab::Carriage::none;
  if (v > 600) return ab::Carriage::knit;
  if (v < 200) return ab::Carriage::lace;
  return ab::Carriage::none;
}

ab::IndState Firmware::ind_state(uint8_t error) const {
  ab::IndState s;
  s.error = error;
  s.state = state_;
  s.hall_left = hall(true);
  s.hall_right = hall(false);
  s.carriage = carriage_;
  s.position = position_;
  s.direction = direction_;
  return s;
}

bool Firmware::selected(int pixel) const {
  const size_t byte = static_cast<size_t>(pixel) >> 3;
  if (byte >= buffer_.size()) return false;
  return ((buffer_[byte] >> (pixel & 7)) & 1) == 0;  // the buffer holds the inverted line
}

void Firmware::handle_packet(ab::Bytes p) {
  switch (p[0]) {
    case static_cast<uint8_t>(ab::MsgId::reqInit): h_req_init(p); break;
    case static_cast<uint8_t>(ab::MsgId::reqStart): h_req_start(p); break;
    case static_cast<uint8_t>(ab::MsgId::cnfLine): {
      ++cnf_lines_;
      if (state_ == ab::FsmState::knit) line_arrived_ = true;
      if (opt_.faults.corrupt_line && cnf_lines_received() == *opt_.faults.corrupt_line) {
        const size_t at = 4 + (static_cast<size_t>(start_) >> 3);
        if (at + 1 < p.size()) p[at] ^= 0xFF;  // a needle byte; the CRC no longer matches
      }
      h_cnf_line(p);
      break;
    }
    case static_cast<uint8_t>(ab::MsgId::reqInfo): send(ab::CnfInfo{opt_.faults.api, 1, 0, 0, opt_.suffix}); break;
    case static_cast<uint8_t>(ab::MsgId::reqTest): h_req_test(); break;
    default:
      if (p[0] >= kHelp && p[0] <= kQuit) test_command(p);
      // Anything else (our own message ids echoed, unknown ids) is ignored.
  }
}

void Firmware::h_req_init(const ab::Bytes& p) {
  if (p.size() < 3) return send(ab::CnfInit{ab::err::expected_longer_message});
  if (ab::crc8(p.data(), 2) != p[2]) return send(ab::CnfInit{ab::err::checksum_error});
  blank_buffer();
  if (state_ != ab::FsmState::wait_for_machine) return send(ab::CnfInit{ab::err::wrong_machine_state});
  if (p[1] == kNoMachine) return send(ab::CnfInit{ab::err::no_machine_type});
  machine_ = p[1];
  // Encoders::init, then the knitter's interrupt handler is attached.
  position_ = 0;
  direction_ = hall_active_ = ab::Direction::unknown;
  carriage_ = prev_detected_left_ = prev_detected_right_ = ab::Carriage::none;
  encoder_attached_ = true;
  state_ = ab::FsmState::init;
  send(ab::CnfInit{ab::err::success});
  init_move_at_ = now_ + opt_.faults.knitter_pause_ms;
}

void Firmware::h_req_start(const ab::Bytes& p) {
  if (p.size() < 5) return send(ab::CnfStart{ab::err::expected_longer_message});
  if (ab::crc8(p.data(), 4) != p[4]) return send(ab::CnfStart{ab::err::checksum_error});
  blank_buffer();
  if (state_ != ab::FsmState::ready) return send(ab::CnfStart{ab::err::wrong_machine_state});
  const uint8_t start = p[1], stop = p[2];
  if (!(start < stop && stop < ab::needle_count(fw_machine()))) return send(ab::CnfStart{ab::err::needle_value_invalid});
  start_ = start;
  stop_ = stop;
  continuous_ = (p[3] & 1) != 0;
  current_line_ = 255;  // incremented before the request
  line_requested_ = false;
  last_line_flag_ = false;
  state_ = ab::FsmState::knit;
  beep(false);  // ready
  send(ab::CnfStart{ab::err::success});
  pass_needles_.assign(static_cast<size_t>(stop_ - start_ + 1), '0');
  resting_since_ = now_;
  beepless_pushes_ = 0;
  job_pushes_ = 0;
  line_arrived_ = false;
  beep_at_.reset();
  if (first_run_) {
    // The first knit() after power-on asks for line 0 at once.
    first_run_ = false;
    beep(false);
    req_line(++current_line_);
  } else {
    beep_at_ = now_;  // the knitter hears "ready" and nothing is asked of the host: a blank pass
  }
  knit();  // the position may differ from the last one knitted (m_sOldPosition)
}

void Firmware::h_cnf_line(const ab::Bytes& p) {
  if (!machine_) return;  // no machine type yet: the firmware would read past LINE_BUFFER_LEN
  const int n = line_bytes();
  if (p.size() < static_cast<size_t>(n) + 5) return;
  for (int i = 0; i < n; ++i) buffer_[static_cast<size_t>(i)] = static_cast<uint8_t>(~p[static_cast<size_t>(i) + 4]);
  if (ab::crc8(p.data(), static_cast<size_t>(n) + 4) != p[static_cast<size_t>(n) + 4]) return;
  // Knitter::setNextLine
  if (!line_requested_) return;
  if (p[1] != current_line_) return req_line(current_line_);
  line_requested_ = false;
  beep(true);
  if (p[3] & 1) last_line_flag_ = true;
}

void Firmware::req_line(uint8_t n) {
  send(ab::ReqLine{n, ab::err::success});
  line_requested_ = true;
}

// ---- The test mode (tester.cpp) ----

void Firmware::h_req_test() {
  if (state_ != ab::FsmState::wait_for_machine && state_ != ab::FsmState::init && state_ != ab::FsmState::ready)
    return send(ab::CnfTest{ab::err::wrong_machine_state});
  state_ = ab::FsmState::test;
  test_text("AYAB Hardware Test, ");
  test_text("Firmware v1.0.0");
  if (!opt_.suffix.empty()) test_text("-" + opt_.suffix);
  test_text(" API v6\n\n");
  test_command(ab::Bytes{kHelp});
  encoder_attached_ = false;  // the tester's encoder handler replaces the knitter's
  auto_read_ = auto_test_ = timer_odd_ = false;
  test_timer_last_ = now_;
  send(ab::CnfTest{ab::err::success});
  loop();  // encodePosition
}

void Firmware::read_eol_sensors() {
  test_text("  EOL_L: " + std::to_string(hall(true)));
  test_text("  EOL_R: " + std::to_string(hall(false)));
}

void Firmware::read_encoders() {
  // The encoder lines rest low between steps.
  for (const char* pin : {"  ENC_A: ", "  ENC_B: ", "  ENC_C: "}) {
    test_text(pin);
    test_text("LOW");
  }
}

void Firmware::test_command(const ab::Bytes& p) {
  switch (p[0]) {
    case kHelp:
      for (const char* t : {"The following commands are available:\n", "setSingle [0..15] [1/0]\n", "setAll [0..FFFF]\n",
                            "readEOLsensors\n", "readEncoders\n", "beep\n", "autoRead\n", "autoTest\n", "send\n",
                            "stop\n", "quit\n", "help\n"})
        test_text(t);
      break;
    case kSendCmd:
      test_text("Called send\n");
      if (!stopped()) out_.emplace_back(now_ + opt_.faults.delay_ms, ab::slip_encode(ab::Bytes{0x31, 0x32, 0x33}));
      test_text("\n");
      break;
    case kBeep:
      test_text("Called beep\n");
      beep(false);
      break;
    case kSetSingle:
      test_text("Called setSingle\n");
      if (p.size() < 3) test_text("Error: invalid arguments\n");
      else if (p[1] > 15) test_text("Error: invalid solenoid index " + std::to_string(p[1]) + "\n");
      else if (p[2] > 1) test_text("Error: invalid solenoid value " + std::to_string(p[2]) + "\n");
      break;
    case kSetAll:
      test_text("Called setAll\n");
      if (p.size() < 3) test_text("Error: invalid arguments\n");
      break;
    case kReadEol:
      test_text("Called readEOLsensors\n");
      read_eol_sensors();
      test_text("\n");
      break;
    case kReadEnc:
      test_text("Called readEncoders\n");
      read_encoders();
      test_text("\n");
      break;
    case kAutoRead:
      test_text("Called autoRead, send stop to quit\n");
      auto_read_ = true;
      break;
    case kAutoTest:
      test_text("Called autoTest, send stop to quit\n");
      auto_test_ = true;
      break;
    case kStop: auto_read_ = auto_test_ = false; break;
    case kQuit:
      // Tester::quitCmd: interrupts detached, wait-for-machine (Knitter::init is NOT called:
      // fsm.cpp only does that on a way to init).
      encoder_attached_ = false;
      state_ = ab::FsmState::wait_for_machine;
      break;
  }
}

void Firmware::test_timer() {
  test_timer_last_ = now_;
  if (auto_read_ && timer_odd_) {
    test_text("\n");
    read_eol_sensors();
    read_encoders();
    test_text("\n");
  }
  if (auto_test_) test_text(timer_odd_ ? "Set odd solenoids\n" : "Set even solenoids\n");
  timer_odd_ = !timer_odd_;
}

// ---- The main loop and the encoder ----

void Firmware::loop() {
  const ab::FsmState before = state_;
  switch (state_) {
    case ab::FsmState::init: is_ready(); break;
    case ab::FsmState::knit: knit(); break;
    case ab::FsmState::test:
      if (old_position_ != position_) {  // Knitter::encodePosition
        old_position_ = position_;
        send(ind_state(ab::err::unspecified_failure));
      }
      break;
    default: break;
  }
  // The firmware loops on its own between encoder edges: a job that just ended is checked for
  // ready at once.
  if (state_ == ab::FsmState::init && before != ab::FsmState::init) is_ready();
}

void Firmware::edge_rising(bool moving_right) {
  hall_active_ = ab::Direction::unknown;
  direction_ = moving_right ? ab::Direction::right : ab::Direction::left;
  if (moving_right) ++position_;
  const ab::Carriage seen = detect(true), before = prev_detected_left_;
  prev_detected_left_ = seen;
  if (moving_right && seen != ab::Carriage::none && seen != before) {
    hall_active_ = ab::Direction::left;
    carriage_ = seen;
    position_ = static_cast<uint8_t>(bed::left_sensor(fw_machine()));
  }
}

void Firmware::edge_falling(bool moving_right) {
  hall_active_ = ab::Direction::unknown;
  direction_ = moving_right ? ab::Direction::right : ab::Direction::left;
  if (!moving_right) --position_;
  const ab::Carriage seen = detect(false), before = prev_detected_right_;
  prev_detected_right_ = seen;
  if (!moving_right && seen != ab::Carriage::none && seen != before) {
    hall_active_ = ab::Direction::right;
    carriage_ = seen;
    position_ = static_cast<uint8_t>(bed::right_sensor(fw_machine()));
  }
}

void Firmware::step_carriage(int dir) {
  x_ += dir;
  if (!encoder_attached_ || stopped()) return;
  // Each step is a rising and a falling edge of encoder A; the main loop runs after each.
  const bool right = dir > 0;
  if (right) {
    edge_rising(true);
    loop();
    edge_falling(true);
    loop();
  } else {
    edge_falling(false);
    loop();
    edge_rising(false);
    loop();
  }
}

void Firmware::is_ready() {
  if (hall_active_ != ab::Direction::unknown) last_hall_ = hall_active_;
  const ab::MachineType m = fw_machine();
  const bool passed_left = direction_ == ab::Direction::right && last_hall_ == ab::Direction::left &&
                           position_ > bed::left_sensor(m) + bed::kGarterSlop;
  const bool passed_right = direction_ == ab::Direction::left && last_hall_ == ab::Direction::right &&
                            position_ < bed::right_sensor(m) - bed::kGarterSlop;
  if (!passed_left && !passed_right) return;
  send(ind_state(ab::err::success));  // still state init: the FSM moves on after the dispatch
  state_ = ab::FsmState::ready;
  init_move_at_.reset();
}

void Firmware::knit() {
  if (old_position_ == position_) return;
  old_position_ = position_;
  if (continuous_) send(ind_state(ab::err::success));
  if (direction_ == ab::Direction::unknown) {
    beep(false);  // calculatePixelAndSolenoid fails: error beep
    return;
  }
  const ab::MachineType m = fw_machine();
  int pixel = position_ - (carriage_ == ab::Carriage::none ? 0 : bed::start_offset(m, direction_));
  if (pixel < 0) pixel += m == ab::MachineType::kh270 ? 252 : 256;
  pixel &= 0xFF;
  if (pixel >= start_ && pixel <= stop_) {
    worked_on_line_ = true;
    pass_needles_[static_cast<size_t>(pixel - start_)] = selected(pixel) ? '1' : '0';
  }
  const int off = ab::end_of_line_offset(m);
  if ((pixel < start_ - off || pixel > stop_ + off) && worked_on_line_) {
    worked_on_line_ = false;
    line_finished();
  }
}

void Firmware::line_finished() {
  KnittedRow row;
  row.line = current_line_;
  row.start_needle = start_;
  row.stop_needle = stop_;
  row.needles = pass_needles_;
  row.stale = line_requested_;
  pass_needles_.assign(pass_needles_.size(), '0');
  const bool blank_end = last_line_flag_ && row.needles.find('1') == std::string::npos;
  if (!blank_end) {
    ++rows_;
    row.number = opt_.rows_before + rows_;
    if (on_row_) on_row_(row);
    if (opt_.faults.silent_after_row && row.number >= *opt_.faults.silent_after_row) {
      silent_ = true;
      return;
    }
    if (opt_.faults.bad_escape_after_row && row.number == *opt_.faults.bad_escape_after_row) slip_.poison_next_byte();
  }
  if (!line_requested_ && !last_line_flag_) req_line(++current_line_);
  else if (last_line_flag_) stop_knitting();
}

void Firmware::stop_knitting() {
  beep(false);  // endWork
  state_ = ab::FsmState::init;
  init_move_at_ = now_ + opt_.faults.knitter_pause_ms;
}

// ---- The carriage and the knitter ----

void Firmware::move(int to, int64_t duration) {
  Move mv;
  mv.to = std::clamp(to, 0, bed::last_position(opt_.machine));
  mv.duration = std::max<int64_t>(0, duration);
  moves_.push_back(mv);
  if (moves_.size() == 1) {
    moves_.front().from = x_;
    moves_.front().t0 = now_;
  }
}

void Firmware::push_carriage(int position, int64_t duration_ms) { move(position, duration_ms); }

void Firmware::turn_mark_move() {
  init_move_at_.reset();
  const int bed_positions = bed::last_position(opt_.machine) + 1;
  auto time_for = [&](int from, int to) { return opt_.row_ms * std::abs(to - from) / bed_positions; };
  int at = x_;
  if (at > kRestPosition) {
    move(kRestPosition, time_for(at, kRestPosition));
    at = kRestPosition;
  }
  move(kReadyPosition, time_for(at, kReadyPosition));
}

void Firmware::push_pass() {
  ++job_pushes_;
  beepless_pushes_ = beep_at_ ? 0 : beepless_pushes_ + 1;
  beep_at_.reset();
  const ab::MachineType m = fw_machine();
  const int off = ab::end_of_line_offset(m);
  const int right_end = stop_ + off + 1 + bed::start_offset(m, ab::Direction::right) + kKnitterOvershoot;
  const int left_end = start_ - off - 1 + bed::start_offset(m, ab::Direction::left) - kKnitterOvershoot;
  const bool go_right = x_ <= (left_end + right_end) / 2;
  move(go_right ? right_end : left_end, opt_.row_ms);
}

std::optional<int64_t> Firmware::next_step_ms() const {
  if (moves_.empty() || stopped()) return std::nullopt;
  const Move& mv = moves_.front();
  const int n = std::abs(mv.to - mv.from);
  if (n == 0) return mv.t0;
  return mv.t0 + mv.duration * (mv.done + 1) / n;
}

std::optional<int64_t> Firmware::next_push_ms() const {
  if (stopped() || !moves_.empty()) return std::nullopt;
  if (state_ == ab::FsmState::init) return init_move_at_;
  if (state_ != ab::FsmState::knit) return std::nullopt;
  const Faults& f = opt_.faults;
  if (beep_at_) return std::max(resting_since_, *beep_at_ + f.knitter_pause_ms);
  // The knitter starts a job on a beep - or, once the host has sent a line (atelier says
  // "knitting row 1"), after its patience even if the line came garbled and no beep came - and
  // after two pushes in a row with no beep waits for one. A session abandoned before it sent a
  // line never has its firmware knit on its own.
  if ((job_pushes_ == 0 && !line_arrived_) || beepless_pushes_ >= 2) return std::nullopt;
  const int64_t patience = f.knitter_patience_ms ? *f.knitter_patience_ms : 2 * opt_.row_ms;
  int64_t at = resting_since_ + patience;
  if (f.impatient_knitter) at = std::min(at, resting_since_ + f.knitter_pause_ms);
  return at;
}

void Firmware::advance_to(int64_t time_ms) {
  for (;;) {
    const auto step = next_step_ms();
    const auto push = next_push_ms();
    std::optional<int64_t> timer;
    if (state_ == ab::FsmState::test && (auto_read_ || auto_test_) && !stopped()) timer = test_timer_last_ + kTestLoopMs;
    std::optional<int64_t> next;
    for (const auto& t : {step, push, timer})
      if (t && (!next || *t < *next)) next = t;
    if (!next || *next > time_ms) break;
    now_ = std::max(now_, *next);
    if (step && *step == *next) {
      Move& mv = moves_.front();
      const int n = std::abs(mv.to - mv.from);
      if (n > 0) {
        step_carriage(mv.to > mv.from ? 1 : -1);
        ++mv.done;
      }
      if (mv.done >= n) {
        moves_.pop_front();
        if (!moves_.empty()) {
          moves_.front().from = x_;
          moves_.front().t0 = now_;
              } else {
          resting_since_ = now_;
        }
      }
    } else if (push && *push == *next) {
      if (state_ == ab::FsmState::init) turn_mark_move();
      else push_pass();
    } else {
      test_timer();
    }
  }
  now_ = std::max(now_, time_ms);
}

ab::Bytes Firmware::take_output() {
  ab::Bytes bytes;
  while (!out_.empty() && out_.front().first <= now_) {
    bytes.insert(bytes.end(), out_.front().second.begin(), out_.front().second.end());
    out_.pop_front();
  }
  return bytes;
}

std::optional<int64_t> Firmware::next_event_ms() const {
  std::optional<int64_t> next = next_step_ms();
  const auto push = next_push_ms();
  if (push && (!next || *push < *next)) next = push;
  if (state_ == ab::FsmState::test && (auto_read_ || auto_test_) && !stopped()) {
    const int64_t t = test_timer_last_ + kTestLoopMs;
    if (!next || t < *next) next = t;
  }
  if (!out_.empty() && (!next || out_.front().first < *next)) next = out_.front().first;
  return next;
}

}  // namespace atelier::knit_emu

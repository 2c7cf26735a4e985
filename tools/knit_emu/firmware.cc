#include "tools/knit_emu/firmware.h"

#include <algorithm>

namespace atelier::knit_emu {
namespace ab = ayab;

namespace {
// Hall sensor readings (10-bit ADC): idle, and with the K carriage's magnet over the sensor.
constexpr uint16_t kHallIdle = 0x0200;
constexpr uint16_t kHallKCarriage = 0x0320;
}  // namespace

Firmware::Firmware(FirmwareOptions options, RowObserver on_row, int64_t start_ms)
    : opt_(std::move(options)), on_row_(std::move(on_row)), now_(start_ms), rng_(opt_.faults.seed) {
  // A machine that went silent stays silent after a replug.
  silent_ = opt_.faults.silent_after_row && opt_.rows_before >= *opt_.faults.silent_after_row;
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
  if (silent_ || size == 0) return;
  if (opt_.boot_ms > 0 && !boot_until_) boot_until_ = now_ + opt_.boot_ms;
  if (boot_until_ && now_ < *boot_until_) return;  // still resetting: the bytes are lost
  ab::Bytes in(data, data + size);
  for (auto& b : in) b ^= next_corruption_mask();
  for (const auto& packet : slip_.feed(in)) {
    handle_packet(packet);
    if (silent_) return;
  }
}

void Firmware::send(const ab::Message& m) {
  if (silent_) return;
  out_.emplace_back(now_ + opt_.faults.delay_ms, ab::slip_encode(ab::encode(m)));
}

ab::IndState Firmware::ind_state() const {
  ab::IndState s;
  s.error = ab::err::success;
  s.state = state_;
  const bool at_left = position_ <= 0, at_right = position_ >= ab::needle_count(opt_.machine) - 1;
  s.hall_left = at_left ? kHallKCarriage : kHallIdle;
  s.hall_right = at_right ? kHallKCarriage : kHallIdle;
  s.carriage = ab::Carriage::knit;
  s.position = static_cast<uint8_t>(std::clamp(position_, 0, 255));
  s.direction = direction_;
  return s;
}

void Firmware::handle_packet(const ab::Bytes& p) {
  const int nbytes = ab::line_bytes(opt_.machine);
  const ab::DecodeResult d = ab::decode(p, nbytes);
  if (!d.message) {
    // The firmware answers a malformed reqInit/reqStart with its error code, drops a
    // malformed cnfLine silently and ignores ids it does not know.
    if (p[0] == static_cast<uint8_t>(ab::MsgId::reqInit)) send(ab::CnfInit{d.error});
    else if (p[0] == static_cast<uint8_t>(ab::MsgId::reqStart)) send(ab::CnfStart{d.error});
    return;
  }
  const ab::Message& m = *d.message;

  if (std::holds_alternative<ab::ReqInfo>(m)) {
    send(ab::CnfInfo{opt_.faults.api, 1, 0, 0, opt_.suffix});
  } else if (const auto* init = std::get_if<ab::ReqInit>(&m)) {
    if (state_ != ab::FsmState::wait_for_machine) {
      send(ab::CnfInit{ab::err::wrong_machine_state});
    } else if (init->machine != opt_.machine) {
      send(ab::CnfInit{ab::err::bad_argument});
    } else {
      state_ = ab::FsmState::init;
      send(ab::CnfInit{ab::err::success});
      // The knitter moves the carriage across the left turn mark.
      carriage_ = Carriage::to_turn_mark;
      carriage_due_ = now_ + opt_.row_ms;
    }
  } else if (const auto* start = std::get_if<ab::ReqStart>(&m)) {
    if (state_ != ab::FsmState::ready) {
      send(ab::CnfStart{ab::err::wrong_machine_state});
    } else if (!(start->start_needle < start->stop_needle &&
                 start->stop_needle < ab::needle_count(opt_.machine))) {
      send(ab::CnfStart{ab::err::bad_needles});
    } else {
      start_needle_ = start->start_needle;
      stop_needle_ = start->stop_needle;
      continuous_ = start->continuous_reporting;
      state_ = ab::FsmState::knit;
      expected_line_ = 0;
      line_requested_ = true;
      send(ab::CnfStart{ab::err::success});
      send(ab::ReqLine{expected_line_, ab::err::success});
    }
  } else if (const auto* line = std::get_if<ab::CnfLine>(&m)) {
    if (state_ != ab::FsmState::knit || !line_requested_) return;
    if (line->line != expected_line_) {
      send(ab::ReqLine{expected_line_, ab::err::success});
      return;
    }
    line_requested_ = false;
    row_data_ = line->needles;
    carriage_ = line->last_line ? Carriage::knitting_blank : Carriage::knitting_row;
    carriage_due_ = now_ + opt_.row_ms;
    // The carriage heads for the far side of the working range.
    direction_ = position_ < start_needle_ ? ab::Direction::right : ab::Direction::left;
  } else if (std::holds_alternative<ab::ReqTest>(m)) {
    send(ab::CnfTest{ab::err::generic});
  }
  // Messages the firmware itself sends (cnf*, indState, reqLine, ...) are ignored if echoed.
}

void Firmware::on_carriage_event() {
  const Carriage what = carriage_;
  carriage_ = Carriage::idle;
  carriage_due_.reset();
  const int offset = ab::end_of_line_offset(opt_.machine);
  const int last_needle = ab::needle_count(opt_.machine) - 1;

  switch (what) {
    case Carriage::idle: return;
    case Carriage::to_turn_mark: {
      // Left sensor passed moving right, or right sensor passed moving left.
      if (direction_ == ab::Direction::left) {
        position_ = last_needle;
      } else {
        position_ = 0;
        direction_ = ab::Direction::right;
      }
      state_ = ab::FsmState::ready;
      send(ind_state());
      return;
    }
    case Carriage::knitting_row:
    case Carriage::knitting_blank: {
      position_ = direction_ == ab::Direction::right ? stop_needle_ + offset : start_needle_ - offset;
      if (what == Carriage::knitting_blank) {
        // All solenoids set, beep, back to init; the carriage runs on to the turn mark.
        state_ = ab::FsmState::init;
        carriage_ = Carriage::to_turn_mark;
        carriage_due_ = now_ + opt_.row_ms;
        direction_ = direction_ == ab::Direction::right ? ab::Direction::left : ab::Direction::right;
        return;
      }
      ++rows_;
      KnittedRow row;
      row.number = opt_.rows_before + rows_;
      row.line = expected_line_;
      row.start_needle = start_needle_;
      row.stop_needle = stop_needle_;
      for (int n = start_needle_; n <= stop_needle_; ++n)
        row.needles.push_back(ab::needle_selected(row_data_, n) ? '1' : '0');
      if (on_row_) on_row_(row);
      if (opt_.faults.silent_after_row && row.number >= *opt_.faults.silent_after_row) {
        silent_ = true;
        return;
      }
      if (continuous_) send(ind_state());
      expected_line_ = static_cast<uint8_t>(expected_line_ + 1);
      line_requested_ = true;
      send(ab::ReqLine{expected_line_, ab::err::success});
      return;
    }
  }
}

void Firmware::advance_to(int64_t time_ms) {
  while (carriage_due_ && *carriage_due_ <= time_ms) {
    now_ = std::max(now_, *carriage_due_);
    on_carriage_event();
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
  std::optional<int64_t> next = carriage_due_;
  if (!out_.empty() && (!next || out_.front().first < *next)) next = out_.front().first;
  return next;
}

}  // namespace atelier::knit_emu

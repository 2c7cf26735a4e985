#include "drivers/ayab/pass_watch.h"

namespace atelier::ayab {
namespace {

// Firmware 1.0's START_OFFSET[machine][direction][carriage] (encoders.h): direction 0 = the
// left offset, used while the carriage moves right; carriage knit, lace, garter.
constexpr uint8_t kStartOffset[3][2][3] = {
    {{42, 32, 32}, {16, 24, 48}},  // KH-910
    {{42, 32, 32}, {16, 24, 48}},  // KH-930
    {{34, 0, 0}, {22, 0, 0}},      // KH-270
};

}  // namespace

std::optional<int> firmware_pixel(MachineType machine, uint8_t position, Direction direction, Carriage carriage) {
  if (direction != Direction::left && direction != Direction::right) return std::nullopt;
  const int m = static_cast<int>(machine);
  if (m < 0 || m > 2) return std::nullopt;
  int offset = 0;  // no carriage seen: the firmware uses 0
  const auto c = static_cast<uint8_t>(carriage);
  if (c <= 2) offset = kStartOffset[m][direction == Direction::right ? 0 : 1][c];
  int pixel = static_cast<int>(position) - offset;
  if (pixel < 0) pixel += machine == MachineType::kh270 ? 252 : 256;
  return pixel;
}

PassWatch::PassWatch(MachineType machine, int start_needle, int stop_needle)
    : machine_(machine), start_(start_needle), stop_(stop_needle) {}

bool PassWatch::in_range(const IndState& s) const {
  if (s.state != FsmState::knit) return false;
  const auto pixel = firmware_pixel(machine_, s.position, s.direction, s.carriage);
  return pixel && *pixel >= start_ && *pixel <= stop_;
}

bool PassWatch::on_state(const IndState& s) {
  if (s.state != FsmState::knit) return false;
  reporting_ = true;
  // The firmware looks only when the position changed.
  if (last_position_ && *last_position_ == s.position) return false;
  last_position_ = s.position;
  const auto pixel = firmware_pixel(machine_, s.position, s.direction, s.carriage);
  if (!pixel) return false;
  if (*pixel >= start_ && *pixel <= stop_) worked_ = true;
  const int past = end_of_line_offset(machine_);
  if (worked_ && (*pixel < start_ - past || *pixel > stop_ + past)) {
    worked_ = false;
    return true;
  }
  return false;
}

}  // namespace atelier::ayab

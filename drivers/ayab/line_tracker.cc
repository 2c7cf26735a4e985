#include "drivers/ayab/line_tracker.h"

namespace atelier::ayab {

LineTracker::Result LineTracker::on_request(uint8_t wire) {
  if (wire == static_cast<uint8_t>(next_ & 0xFF)) return {Kind::next, next_++};
  if (next_ > 0 && wire == static_cast<uint8_t>((next_ - 1) & 0xFF)) return {Kind::repeat, next_ - 1};
  return {Kind::out_of_sequence, next_};
}

}  // namespace atelier::ayab

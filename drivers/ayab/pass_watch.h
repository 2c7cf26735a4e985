// Follows the carriage through firmware 1.0's indState stream (continuous reporting) the way
// its Knitter::knit does, so the host knows when the firmware has decided that a pass over the
// working range is over - the moment it asks for the next line, or (the last, blank line)
// stops knitting.
//
// Units: `position` is the firmware's carriage position, 0..255 (KH-270 0..167); needles
// (pixels) are counted from 0 at the left of the bed, as in reqStart. Firmware 1.0
// (knitter.cpp calculatePixelAndSolenoid, encoders.h START_OFFSET): moving right, pixel =
// position - START_OFFSET[machine][left][carriage]; moving left, the right-hand offset;
// below 0 it wraps by 256 (KH-270: 252); no direction: no pixel. A pass is over at the first
// pixel more than END_OF_LINE_OFFSET (12; KH-270 6) needles outside the range after a pixel
// inside it, on either side.
// Pure value type; not thread-safe.
#pragma once

#include <cstdint>
#include <optional>

#include "drivers/ayab/messages.h"

namespace atelier::ayab {

// The needle firmware 1.0 works on with the carriage at `position`; nullopt without a direction.
std::optional<int> firmware_pixel(MachineType machine, uint8_t position, Direction direction, Carriage carriage);

class PassWatch {
 public:
  PassWatch(MachineType machine, int start_needle, int stop_needle);

  // The firmware has just asked for a line (its "worked on the line" flag is clear then).
  void line_requested() { worked_ = false; }
  // An indState of the knit state. True when this report is where the firmware ends the pass
  // (firmware 1.0 sends this indState, then at once reqLine or nothing).
  bool on_state(const IndState& s);
  // The report puts the carriage on a needle of the working range (the firmware sets that
  // needle's solenoid from its buffer as it sends the report).
  bool in_range(const IndState& s) const;
  // Some knit-state indState has come since construction: the firmware reports the carriage.
  bool reporting() const { return reporting_; }

 private:
  MachineType machine_;
  int start_, stop_;
  bool worked_ = false;
  bool reporting_ = false;
  std::optional<uint8_t> last_position_;
};

}  // namespace atelier::ayab

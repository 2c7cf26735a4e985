// The needle bed as AYAB firmware 1.0 sees it (src/ayab/encoders.h, knitter.cpp): carriage
// positions in the firmware's encoder units (0..255, KH-270 0..167), the turn-mark Hall sensors,
// and which needle (pixel) the firmware sets a solenoid for at a position. Only the K (knit)
// carriage is modelled. Pure constants and functions; thread-safe.
#pragma once

#include <cstdint>

#include "drivers/ayab/messages.h"

namespace atelier::knit_emu::bed {

// END_LEFT_PLUS_OFFSET / END_RIGHT_MINUS_OFFSET: where the left and right Hall sensors put
// the position when the K carriage's magnet passes them (moving right / moving left).
constexpr int left_sensor(ayab::MachineType) { return 28; }
constexpr int right_sensor(ayab::MachineType m) { return m == ayab::MachineType::kh270 ? 139 : 227; }
// END_RIGHT: the last position.
constexpr int last_position(ayab::MachineType m) { return m == ayab::MachineType::kh270 ? 167 : 255; }
// GARTER_SLOP: isReady wants the carriage this far past the sensor.
constexpr int kGarterSlop = 2;
// The magnet is over a sensor for this many positions from where it is first seen (inwards).
constexpr int kMagnetWidth = 2;

// START_OFFSET for the K carriage: moving right the firmware uses the "Left" column, moving
// left the "Right" one (Knitter::calculatePixelAndSolenoid).
constexpr int start_offset(ayab::MachineType m, ayab::Direction moving) {
  const bool kh270 = m == ayab::MachineType::kh270;
  return moving == ayab::Direction::right ? (kh270 ? 28 + 6 : 42) : (kh270 ? 28 - 6 : 16);
}

// The pixel (needle) the firmware sets a solenoid for at `position` moving `moving`:
// position - START_OFFSET, wrapped by 256 (KH-270: 252) below 0, as a uint8_t.
constexpr uint8_t pixel(ayab::MachineType m, int position, ayab::Direction moving) {
  int p = position - start_offset(m, moving);
  if (p < 0) p += m == ayab::MachineType::kh270 ? 252 : 256;
  return static_cast<uint8_t>(p);
}

// Hall sensor readings (10-bit ADC), from the firmware's doc/carriage_hallvalues.md (KH-930:
// left idle 43 %, K 74 %; right idle 35 %, K 73 %; KH-910: left idle 38 %, right idle 57 % and K 0 %, its shield's
// wiring). Above FILTER_*_MAX (600) reads as the K carriage; KH-910 right below 200.
constexpr uint16_t hall_idle(ayab::MachineType m, bool left_sensor_) {
  if (m == ayab::MachineType::kh910) return left_sensor_ ? 389 : 583;
  return left_sensor_ ? 440 : 358;
}
constexpr uint16_t hall_k_carriage(ayab::MachineType m, bool left_sensor_) {
  return left_sensor_ ? 757 : (m == ayab::MachineType::kh910 ? 0 : 747);
}

}  // namespace atelier::knit_emu::bed

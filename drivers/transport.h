// The Transport seam: a byte link to a machine (serial port, pseudo-terminal, or an
// in-memory pair in tests). Drivers speak protocols over it and never touch the OS directly.
//
// Threading: one reader and one writer thread may use a transport at once; close() may be
// called from any thread and wakes a blocked read. Errors: a lost link (unplugged cable,
// closed peer) throws LinkLost from read/write; a read that times out returns 0 bytes.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "base/error.h"

namespace atelier {

class LinkLost : public DeviceError {
 public:
  using DeviceError::DeviceError;
};

class Transport {
 public:
  virtual ~Transport() = default;
  // Writes all `size` bytes (blocking until queued to the device). Throws LinkLost.
  virtual void write(const uint8_t* data, size_t size) = 0;
  // Reads up to `max` bytes, waiting at most `timeout` for the first. Returns the count
  // (0 on timeout). Throws LinkLost when the link is gone.
  virtual size_t read(uint8_t* data, size_t max, std::chrono::milliseconds timeout) = 0;
  // Discards unread input (e.g. boot noise after an Arduino reset).
  virtual void flush_input() = 0;
  // Resets the board the way its USB-serial adapter is wired to: DTR (and RTS) dropped for
  // `low`, then raised again; an Arduino restarts its firmware (AYAB, GRBL) on that edge. Where
  // the port has no modem lines (a pseudo-terminal) the port is closed for `low` and opened
  // again, which an emulator at the other end sees as the DTR drop. Blocks for about `low`;
  // unread input is discarded. Throws LinkLost when the port does not come back.
  virtual void pulse_dtr(std::chrono::milliseconds low) = 0;
  virtual void close() = 0;
};

}  // namespace atelier

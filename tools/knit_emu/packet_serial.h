// The firmware's side of SLIP framing, as AYAB firmware 1.0 receives it (PacketSerial with SLIP,
// a 64-byte receive buffer; src/ayab/com.h). Unlike the host's ayab::SlipDecoder, which drops
// a packet with a bad escape, this one follows the firmware's library: a packet holding ESC
// followed by a byte that is neither ESC_END (0xDC) nor ESC_ESC (0xDD), or ending in ESC, makes
// the decoder loop for ever when the packet's END arrives. hung() then stays true: the board
// answers nothing until it is reset (a new decoder). A packet longer than the buffer is dropped
// (line noise). Empty packets are skipped.
// Pure; not thread-safe.
#pragma once

#include <cstdint>
#include <vector>

#include "drivers/ayab/slip.h"

namespace atelier::knit_emu {

class PacketSerialDecoder {
 public:
  static constexpr size_t kBufferBytes = 64;

  // Returns the packets completed by `data`, in order; none once hung().
  std::vector<ayab::Bytes> feed(const uint8_t* data, size_t size);
  bool hung() const { return hung_; }
  // The next byte received is taken as ESC followed by an invalid byte (fault
  // bad-escape-after-row): the packet it belongs to hangs the decoder at its END.
  void poison_next_byte() { poison_ = true; }

 private:
  void end_of_packet(std::vector<ayab::Bytes>& out);

  ayab::Bytes raw_;  // still SLIP-escaped, as the firmware buffers it
  bool overflow_ = false;
  bool poison_ = false;
  bool hung_ = false;
};

}  // namespace atelier::knit_emu

// Bytes from a knitting machine as the AYAB host reads them: SLIP-decoded in the chunks they
// arrive in, then each packet decoded for every machine's line length (KH-910/930: 25 bytes,
// KH-270: 14) and described for the log, as host_session does. A decoded message is encoded
// again (the emulator's direction).
#include <algorithm>

#include "drivers/ayab/messages.h"
#include "drivers/ayab/slip.h"
#include "tests/fuzz/fuzz_targets.h"

int fuzz_ayab_messages(const uint8_t* data, size_t size) {
  if (size > atelier::fuzz::kMaxFuzzInput || size == 0) return 0;
  namespace ayab = atelier::ayab;
  // The first byte sets the chunk size (1..64), so both whole and split frames are read.
  const size_t chunk = 1 + data[0] % 64;
  ayab::SlipDecoder decoder;
  for (size_t off = 1; off < size; off += chunk) {
    const size_t n = std::min(chunk, size - off);
    for (const ayab::Bytes& packet : decoder.feed(data + off, n)) {
      for (ayab::MachineType m : {ayab::MachineType::kh930, ayab::MachineType::kh270}) {
        ayab::DecodeResult r = ayab::decode(packet, ayab::line_bytes(m));
        if (!r.message) {
          (void)ayab::error_text(r.error);
          continue;
        }
        (void)ayab::describe(*r.message);
        (void)ayab::slip_encode(ayab::encode(*r.message));
      }
    }
  }
  return 0;
}

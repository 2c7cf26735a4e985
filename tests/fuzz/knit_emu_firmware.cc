// Bytes from the host into the knitting-machine emulator's firmware model, in chunks, with the
// simulated clock moving between them so that the carriage knits rows and turns.
// Input: byte 0 picks the machine (bit 0..1) and whether the firmware boots (bit 2); then
// records of [length byte (chunk 1..32 bytes, clock step in row-times/4 from its top bits),
// chunk].
#include <algorithm>

#include "tests/fuzz/fuzz_targets.h"
#include "tools/knit_emu/firmware.h"

int fuzz_knit_emu_firmware(const uint8_t* data, size_t size) {
  if (size > atelier::fuzz::kMaxFuzzInput || size == 0) return 0;
  namespace ayab = atelier::ayab;
  namespace emu = atelier::knit_emu;
  emu::FirmwareOptions options;
  const ayab::MachineType machines[] = {ayab::MachineType::kh910, ayab::MachineType::kh930,
                                        ayab::MachineType::kh270, ayab::MachineType::kh930};
  options.machine = machines[data[0] & 3];
  options.row_ms = 40;
  options.boot_ms = (data[0] & 4) ? 20 : 0;
  int rows = 0;
  emu::Firmware firmware(options, [&rows](const emu::KnittedRow&) { ++rows; }, 0);
  int64_t now = 0;
  for (size_t off = 1; off < size;) {
    const uint8_t header = data[off++];
    const size_t n = std::min<size_t>(1 + (header & 31), size - off);
    firmware.receive(data + off, n);
    off += n;
    now += (header >> 5) * options.row_ms / 4;
    firmware.advance_to(now);
    (void)firmware.take_output();
  }
  // Let everything under way finish (a row, the turn mark, delayed replies).
  for (int i = 0; i < 8; ++i) {
    auto next = firmware.next_event_ms();
    if (!next) break;
    firmware.advance_to(*next);
    (void)firmware.take_output();
  }
  return 0;
}

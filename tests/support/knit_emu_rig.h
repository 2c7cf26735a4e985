// Test helpers for the knitting-machine emulator: a scripted host around the pure firmware
// model, speaking encoded AYAB v6 messages on a simulated clock.
#pragma once

#include <string>
#include <vector>

#include "drivers/ayab/messages.h"
#include "drivers/ayab/slip.h"
#include "tools/knit_emu/firmware.h"

namespace atelier::knit_emu::testing {

namespace ab = atelier::ayab;

struct Rig {
  explicit Rig(FirmwareOptions o = {})
      : options(o), fw(o, [this](const KnittedRow& r) { rows.push_back(r); }) {}

  void send(const ab::Message& m) { fw.receive(ab::slip_encode(ab::encode(m))); }
  void send_payload(const ab::Bytes& payload) { fw.receive(ab::slip_encode(payload)); }
  void advance(int64_t ms) {
    t += ms;
    fw.advance_to(t);
  }
  // Every message the firmware has sent since the last call, decoded.
  std::vector<ab::Message> take() {
    std::vector<ab::Message> out;
    for (const auto& p : dec.feed(fw.take_output())) {
      auto d = ab::decode(p, ab::line_bytes(options.machine));
      if (d.message) out.push_back(*d.message);
    }
    return out;
  }
  // reqInfo, reqInit, one row-time for the carriage to pass the turn mark: machine ready.
  void make_ready() {
    send(ab::ReqInfo{});
    send(ab::ReqInit{options.machine});
    advance(options.row_ms);
    take();
  }
  ab::CnfLine line(uint8_t n, const std::string& needles_from_0, bool last = false) const {
    ab::CnfLine c;
    c.line = n;
    c.last_line = last;
    c.needles.assign(static_cast<size_t>(ab::line_bytes(options.machine)), 0);
    for (size_t i = 0; i < needles_from_0.size(); ++i)
      ab::select_needle(c.needles, static_cast<int>(i), needles_from_0[i] == '1');
    return c;
  }

  FirmwareOptions options;
  std::vector<KnittedRow> rows;
  Firmware fw;
  ab::SlipDecoder dec;
  int64_t t = 0;
};

}  // namespace atelier::knit_emu::testing

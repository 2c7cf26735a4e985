// A pure model of the AYAB v6 firmware on a Brother knitting machine, with a simulated knitter
// moving the carriage (../shared/protocols/ayab-v6.md). Bytes in, SLIP-framed bytes out, time
// from a simulated clock: no I/O, no real time, so tests are deterministic.
//
// Units: all times are milliseconds on the caller's clock (any origin, never decreasing).
// Threading: one Firmware is used from one thread. The row observer is called synchronously
// from advance_to().
//
// Behaviour (firmware v1.0 semantics where the protocol file is silent):
// - States: wait-for-machine -> (reqInit) init -> (carriage passes a turn mark, one row-time
//   later) ready, announced by indState(error 0, state ready, carriage K) -> (reqStart) knit
//   -> (blank last line knitted) init -> (one row-time later, turn mark) ready again. So a second
//   job needs only a new reqStart after the next ready indState; reqInit is accepted only in
//   wait-for-machine, as on the real firmware (a fresh boot is the only way back there).
// - reqInfo is answered in every state: cnfInfo(api, fw 1.0.0, suffix "atelier-emu").
// - reqInit: outside wait-for-machine -> cnfInit(0xEF wrong_machine_state, firmware 1.0's one
//   code for every wrong state); machine type other than the emulated one -> cnfInit(0x10 bad
//   argument); too short -> cnfInit(0x01); bad CRC -> cnfInit(0x04). reqStart likewise with
//   cnfStart: not ready (wait-for-machine, init, knit, ...) -> 0xEF, range not
//   start < stop < needle count -> 0x11, too short 0x01, bad CRC 0x04. On success cnfStart(0)
//   and at once reqLine(0).
// - cnfLine: too short or bad CRC -> silently dropped (no reply, like the firmware). Outside
//   knit state, or while the carriage is still knitting the previous row (no line requested):
//   ignored. Wrong line number -> reqLine(expected) re-sent. Correct -> the carriage knits the
//   row for row_ms (the pass across the working range plus 12 needles past it, 6 on KH-270),
//   the row is reported to the observer, and only then reqLine(n+1 mod 256) is sent.
//   With the last-line flag the (blank) row is knitted but not reported, all solenoids are set
//   and the firmware returns to init; no message is sent.
// - With continuous reporting (reqStart flag bit0) an indState(error 0, state knit) is sent each
//   time the carriage turns at the end of a pass, before the next reqLine.
// - Unknown message ids and empty packets are ignored (the firmware does nothing with them).
// - reqTest: the hardware test mode is not emulated; answered cnfTest(0xF0).
// - Boot (boot_ms > 0): the first byte received is taken as the port being opened (an Arduino
//   resets then); everything received during the following boot_ms is lost.
// - A reset (DTR dropped: the host closed the port or died; unless the no-dtr-reset fault says
//   the board is not wired for it) is a new Firmware: the program around the model makes one.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <random>
#include <string>

#include "drivers/ayab/messages.h"
#include "drivers/ayab/slip.h"
#include "tools/knit_emu/faults.h"

namespace atelier::knit_emu {

struct FirmwareOptions {
  ayab::MachineType machine = ayab::MachineType::kh930;
  int64_t row_ms = 2000;  // one carriage pass, also the init -> ready turn-mark delay
  int64_t boot_ms = 0;    // input ignored this long after the first byte arrives
  int rows_before = 0;    // rows knitted by earlier firmware lives (numbering, silent fault)
  std::string suffix = "atelier-emu";
  Faults faults;          // corrupt, seed, silent-after-row, api, delay-ms are used here;
                          // drop-after-row / replug-ms belong to the program around the model
};

struct KnittedRow {
  int number = 0;       // 1-based over the emulator's life (rows_before + rows of this firmware)
  uint8_t line = 0;     // protocol line number (mod 256)
  int start_needle = 0, stop_needle = 0;
  std::string needles;  // one '0'/'1' per needle start..stop, leftmost first; '1' = selected
};

class Firmware {
 public:
  using RowObserver = std::function<void(const KnittedRow&)>;

  // `start_ms`: the clock value at power-on.
  explicit Firmware(FirmwareOptions options, RowObserver on_row = {}, int64_t start_ms = 0);

  // Bytes from the host (raw serial stream, SLIP framed), received at now().
  void receive(const uint8_t* data, size_t size);
  void receive(const ayab::Bytes& data) { receive(data.data(), data.size()); }

  // Moves the simulated clock forward to `time_ms` (ignored if earlier than now()), running
  // every carriage event due on the way in order.
  void advance_to(int64_t time_ms);

  // SLIP-framed bytes due for sending by now(), in order; removed from the queue.
  ayab::Bytes take_output();

  // The earliest time something will happen on its own (carriage event or delayed reply), so
  // an event loop knows how long it may sleep. Empty when idle.
  std::optional<int64_t> next_event_ms() const;

  int64_t now() const { return now_; }
  ayab::FsmState state() const { return state_; }
  bool silent() const { return silent_; }
  int rows_knitted() const { return rows_; }  // by this firmware life

 private:
  enum class Carriage { idle, to_turn_mark, knitting_row, knitting_blank };

  void handle_packet(const ayab::Bytes& packet);
  void on_carriage_event();
  void send(const ayab::Message& m);
  ayab::IndState ind_state() const;
  uint8_t next_corruption_mask();

  FirmwareOptions opt_;
  RowObserver on_row_;
  int64_t now_;
  ayab::SlipDecoder slip_{64};  // the firmware's receive buffer is 64 bytes
  std::mt19937_64 rng_;
  std::optional<int64_t> boot_until_;
  std::deque<std::pair<int64_t, ayab::Bytes>> out_;  // (due time, framed bytes)

  ayab::FsmState state_ = ayab::FsmState::wait_for_machine;
  Carriage carriage_ = Carriage::idle;
  std::optional<int64_t> carriage_due_;
  int position_ = 0;  // needle the carriage is at (clamped to 0..255 when reported)
  ayab::Direction direction_ = ayab::Direction::unknown;

  int start_needle_ = 0, stop_needle_ = 0;
  bool continuous_ = false;
  uint8_t expected_line_ = 0;
  bool line_requested_ = false;
  ayab::Bytes row_data_;
  int rows_ = 0;
  bool silent_ = false;
};

}  // namespace atelier::knit_emu

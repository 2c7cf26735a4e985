// A pure model of AYAB firmware 1.0.0 (API v6) on a Brother knitting machine, with a simulated
// knitter pushing the K carriage. Bytes in, SLIP-framed bytes out, time from a simulated clock:
// no I/O, no real time, so tests are deterministic. It follows the firmware's source
// (src/ayab/com.cpp, knitter.cpp, encoders.cpp, fsm.cpp, tester.cpp), not our protocol notes.
//
// Units: times are milliseconds on the caller's clock (any origin, never decreasing); carriage
// positions are the firmware's encoder units, 0..255 (KH-270 0..167; tools/knit_emu/bed.h).
// Threading: one Firmware is used from one thread. The row observer is called synchronously
// from advance_to().
//
// The firmware:
// - States wait-for-machine -> (reqInit) init -> (carriage over a turn mark) ready -> (reqStart)
//   knit -> (the pass after the last line) init -> (turn mark) ready. reqInit works only in
//   wait-for-machine (a reset or the test mode's quit gets there again).
// - reqInit: shorter than 3 bytes -> cnfInit(0x01); bad CRC -> 0x04; then the line buffer is
//   blanked; outside wait-for-machine -> 0xEF; machine byte 0xFF -> 0x20; ANY other byte is
//   accepted (the firmware takes the host's word; bytes past 2 use this machine's tables).
// - reqStart: short -> cnfStart(0x01); bad CRC -> 0x04; the buffer is blanked (even if refused);
//   not ready -> 0xEF; not start < stop < needle count -> 0x11; else cnfStart(0), state knit.
//   The first reqStart after power-on sends reqLine(0) at once; after a finished job (firmware's
//   m_firstRun false) it does not: the carriage knits one pass of the blank buffer, and that
//   pass's end asks for line 0.
// - cnfLine (Com::h_cnfLine): shorter than line bytes + 5 -> ignored. Otherwise the needle bytes
//   are copied into the buffer FIRST, then the CRC is checked: bad -> nothing else (the garbled
//   line stays in the buffer, no reply). Good: if a line was requested, the right number is
//   accepted (beep; the last-line flag is kept) and a wrong one gets reqLine(requested) again; if
//   none was requested, nothing. No state check (only the knit state moves needles). cnfLines
//   before the first reqInit are ignored (the firmware would read past its tables).
// - While knitting, each change of position: with continuous reporting an indState(0, state
//   knit, hall values, carriage, position, direction); the solenoid of the pixel under the
//   carriage is set from the buffer; once the pixel has been in start..stop and then goes past
//   start-12 / stop+12 (KH-270 6) the line is finished: if no line is awaited and the last line
//   was not knitted, reqLine(next); if the last-line flag is set, the job ends (state init,
//   double beep); if the requested line never came, NOTHING is sent and the next pass knits the
//   buffer as it is (the old line, or a garbled copy).
// - isReady (state init): direction right, last sensor the left one, position > 30; or direction
//   left, last sensor the right one, position < 225. It sends indState(0) whose state byte still
//   says init (the FSM changes state at the end of its dispatch), then the state is ready.
// - reqInfo, in every state: cnfInfo(api 6, 1.0.0, suffix), 22 bytes; release builds have an
//   empty suffix (zero padded).
// - reqTest in wait-for-machine, init or ready: testRes texts (tester.cpp, no NUL), then
//   cnfTest(0), state test; else cnfTest(0xEF). The test commands 0x25..0x2F are handled in every
//   state, as com.cpp dispatches them: help, send, beep, setSingle, setAll, readEOLsensors,
//   readEncoders, autoRead / autoTest (every 500 ms in test state), stop, quit (state
//   wait-for-machine; the carriage's encoder is detached until the next reqInit). In test state
//   the tester's interrupt handler replaces the knitter's, so the position stays frozen: the
//   indState(0xFF) of encodePosition comes once, on entering test, if the carriage moved since
//   the last knitting.
// - Unknown ids and empty packets are ignored. SLIP: an ESC followed by an invalid byte hangs the
//   board until reset (tools/knit_emu/packet_serial.h).
// - Boot (boot_ms > 0): everything received during the first boot_ms after power-on (start_ms)
//   is lost. A reset (DTR, replug) is a new Firmware: the program around the model makes one;
//   the carriage stays where it was (carriage_position).
//
// The carriage and the knitter (the model's hand; faults.h for the options):
// - The carriage steps position by position; the firmware sees each step as encoder edges once
//   reqInit has attached its interrupt. The K carriage's magnet reads high on a Hall sensor
//   for 3 positions inwards from the sensor (28..30, 225..227); moving right over the left
//   sensor (moving left over the right one) the firmware sets its position to 28 (227).
// - It rests at kRestPosition (left of the left turn mark) at power-on. knitter_pause_ms after
//   the firmware enters init (reqInit accepted, or a job ended) and is not ready, the knitter
//   moves the carriage over the left turn mark: to kRestPosition if it is right of it, then
//   right to kReadyPosition, at one bed length (positions) per row_ms.
// - While knitting, a pass goes from where the carriage rests to 2 positions past the point where
//   the firmware finishes the line on the other side (clamped to the bed), and takes row_ms.
//   The knitter pushes the next pass knitter_pause_ms after the beep of an accepted line
//   (setNextLine), or after the reqStart beep when the firmware asks for no line (the blank
//   pass of a second job); with no beep, knitter_patience_ms after the end of the previous pass
//   (default 2 x row_ms); an impatient knitter pushes knitter_pause_ms after the end of each
//   pass whatever it heard. A job's first pass waits for a beep (or, once a cnfLine of any kind
//   came, for knitter_patience_ms), and after two pushes in a row
//   with no beep heard between them the knitter waits for one. It never pushes outside the
//   knit state.
// - The record (the observer): every pass over the working range in knit state, with the
//   needles it actually selected (the buffer's bit for each needle when the carriage set its
//   solenoid), whatever the host thinks; `stale` says the firmware was still waiting for the
//   line it had asked for, so the pass knitted an old, garbled or blank buffer. The one pass
//   that is left out is a blank pass that ends the job (the blank last line AYAB hosts send):
//   a test compares the record with the pattern rows and sees every wrong or extra row.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <random>
#include <string>

#include "drivers/ayab/messages.h"
#include "tools/knit_emu/faults.h"
#include "tools/knit_emu/packet_serial.h"

namespace atelier::knit_emu {

struct FirmwareOptions {
  ayab::MachineType machine = ayab::MachineType::kh930;
  int64_t row_ms = 2000;   // one carriage pass
  int64_t boot_ms = 0;     // input lost this long after power-on (start_ms)
  int rows_before = 0;     // rows recorded by earlier firmware lives (numbering, row faults)
  int cnf_lines_before = 0;  // cnfLines received by earlier lives (corrupt-line)
  std::optional<int> carriage_position;  // where the carriage is at power-on; empty: kRestPosition
  std::string suffix;      // cnfInfo version suffix (release firmware: empty)
  Faults faults;           // all but drop-after-row / replug-ms / no-dtr-reset, which belong to
                           // the program (or test rig) around the model
};

struct KnittedRow {
  int number = 0;       // 1-based over the emulator's life (rows_before + rows of this firmware)
  uint8_t line = 0;     // the line number the firmware was at (mod 256)
  int start_needle = 0, stop_needle = 0;
  std::string needles;  // one '0'/'1' per needle start..stop, leftmost first; '1' = selected
  bool stale = false;   // the requested line had not come: the pass knitted the buffer as it was
};

class Firmware {
 public:
  using RowObserver = std::function<void(const KnittedRow&)>;
  static constexpr int kRestPosition = 20;   // carriage at power-on: left of the left turn mark
  static constexpr int kReadyPosition = 32;  // where the knitter stops after the turn mark

  // `start_ms`: the clock value at power-on.
  explicit Firmware(FirmwareOptions options, RowObserver on_row = {}, int64_t start_ms = 0);

  // Bytes from the host (raw serial stream, SLIP framed), received at now().
  void receive(const uint8_t* data, size_t size);
  void receive(const ayab::Bytes& data) { receive(data.data(), data.size()); }

  // Moves the simulated clock forward to `time_ms` (ignored if earlier than now()), running
  // every carriage step and knitter action due on the way, in order.
  void advance_to(int64_t time_ms);

  // SLIP-framed bytes due for sending by now(), in order; removed from the queue.
  ayab::Bytes take_output();

  // The earliest time something will happen on its own (carriage step, knitter, test timer,
  // delayed reply), so an event loop knows how long it may sleep. Empty when idle.
  std::optional<int64_t> next_event_ms() const;

  // Moves the carriage by hand to `position` over `duration_ms` from now (tests; the knitter
  // does the rest on its own).
  void push_carriage(int position, int64_t duration_ms);

  int64_t now() const { return now_; }
  ayab::FsmState state() const { return state_; }
  bool silent() const { return silent_; }
  bool hung() const { return slip_.hung(); }
  int rows_knitted() const { return rows_; }  // recorded by this firmware life
  int cnf_lines_received() const { return opt_.cnf_lines_before + cnf_lines_; }  // over the life
  int carriage_position() const { return x_; }  // physical, in firmware units
  bool carriage_moving() const { return !moves_.empty(); }
  int beeps() const { return beeps_; }  // beep sequences (ready, line, end of work) so far

 private:
  struct Move {
    int from = 0, to = 0;
    int64_t t0 = 0, duration = 0;
    int done = 0;  // steps taken
  };

  void handle_packet(ayab::Bytes packet);
  void h_req_init(const ayab::Bytes& p);
  void h_req_start(const ayab::Bytes& p);
  void h_cnf_line(const ayab::Bytes& p);
  void h_req_test();
  void test_command(const ayab::Bytes& p);
  void test_text(const std::string& text) { send(ayab::TestRes{text}); }
  void read_eol_sensors();
  void read_encoders();
  void test_timer();

  // The firmware's main loop and interrupts.
  void step_carriage(int dir);
  void edge_rising(bool moving_right);
  void edge_falling(bool moving_right);
  void loop();
  void is_ready();
  void knit();
  void line_finished();
  void stop_knitting();
  void req_line(uint8_t n);
  void beep(bool line_accepted);
  void send(const ayab::Message& m);
  ayab::IndState ind_state(uint8_t error) const;
  uint16_t hall(bool left) const;
  ayab::Carriage detect(bool left) const;
  ayab::MachineType fw_machine() const;
  int line_bytes() const { return ayab::line_bytes(fw_machine()); }
  bool selected(int pixel) const;  // what the buffer selects for needle `pixel`
  void blank_buffer() { buffer_.assign(25, 0xFF); }
  uint8_t next_corruption_mask();

  // The knitter.
  std::optional<int64_t> next_step_ms() const;
  std::optional<int64_t> next_push_ms() const;
  void push_pass();
  void turn_mark_move();
  void move(int to, int64_t duration);
  bool stopped() const { return silent_ || slip_.hung(); }

  FirmwareOptions opt_;
  RowObserver on_row_;
  int64_t now_;
  PacketSerialDecoder slip_;
  std::mt19937_64 rng_;
  std::optional<int64_t> boot_until_;
  std::deque<std::pair<int64_t, ayab::Bytes>> out_;  // (due time, framed bytes)
  bool silent_ = false;

  // Firmware variables (names as in knitter.cpp / encoders.cpp).
  ayab::FsmState state_ = ayab::FsmState::wait_for_machine;
  std::optional<uint8_t> machine_;  // m_machineType; empty: NoMachine
  uint8_t start_ = 0, stop_ = 0;
  bool continuous_ = false;
  bool line_requested_ = false;
  uint8_t current_line_ = 0;
  bool last_line_flag_ = false;
  bool first_run_ = true;
  bool worked_on_line_ = false;
  uint8_t old_position_ = 0;  // m_sOldPosition
  ayab::Direction last_hall_ = ayab::Direction::unknown;
  bool encoder_attached_ = false;  // the knitter's interrupt handler
  uint8_t position_ = 0;           // the firmware's idea of the position
  ayab::Direction direction_ = ayab::Direction::unknown;
  ayab::Direction hall_active_ = ayab::Direction::unknown;
  ayab::Carriage carriage_ = ayab::Carriage::none;
  ayab::Carriage prev_detected_left_ = ayab::Carriage::none, prev_detected_right_ = ayab::Carriage::none;
  ayab::Bytes buffer_ = ayab::Bytes(25, 0x00);  // lineBuffer: inverted, bit set = not selected
  bool auto_read_ = false, auto_test_ = false, timer_odd_ = false;
  int64_t test_timer_last_ = 0;

  // The carriage and the knitter.
  int x_ = kRestPosition;
  std::deque<Move> moves_;
  std::optional<int64_t> init_move_at_;
  int64_t resting_since_ = 0;
  std::optional<int64_t> beep_at_;  // an accepted-line beep the knitter heard since it last pushed
  int beepless_pushes_ = 0;
  int job_pushes_ = 0;  // passes pushed since reqStart
  bool line_arrived_ = false;  // a cnfLine (good or garbled) came since reqStart
  std::string pass_needles_;

  int rows_ = 0;
  int cnf_lines_ = 0;
  int beeps_ = 0;
};

}  // namespace atelier::knit_emu

// A pure model of a GRBL 1.1h laser controller (1.1h.20190830, laser mode $32=1, S max
// $30=1000; settings in settings.h): bytes in, bytes out, on a clock the caller drives. No I/O,
// no real time: tests run it in virtual time. Written from GRBL's own source (protocol.c,
// report.c, system.c, limits.c, settings.c, gcode.c).
//
// Serial line (serial.c): bytes written by the host arrive one per byte time (10 bits at the
// baud rate: 86.8 us at 115200): arrival = max(write time, previous arrival + byte time).
// Real-time bytes (? ! ~ 0x18 and >= 0x80) are acted on at arrival and never enter the receive
// buffer; the rest go into a 128-byte ring buffer (127 usable). A byte arriving when it is full
// is dropped and counted in the Record as an overflow (one event per line hit) - except
// during a critical alarm, when GRBL reads nothing and the job is already lost. Replies leave at
// the same byte rate; the main loop stalls while more than 104 bytes (TX_BUFFER_SIZE) wait.
// Bytes >= 0x80 (serial.c, protocol_exec_rt_system()): 0x84 safety door, 0x85 jog cancel,
// 0x90-0x9D feed/rapid/spindle overrides, 0x9E spindle stop (in a hold), 0xA0 flood toggle
// (Idle, Run, Hold, Jog); the rest (0xA1 mist: no ENABLE_M7) are dropped. The ISR only sets
// flags; the main loop applies them when it next polls, so override bytes arriving while it
// cannot (blocked on a full TX buffer, in an alarm report, homing) coalesce: nine 0x9B bytes
// then count as one -10 %. Each is otherwise applied on arrival (an idle 16 MHz main loop
// polls far faster than one byte per 86.8 us). Feed override 10..200 % (+-10, +-1, 0x90 reset),
// rapid 100/50/25 %, spindle 10..200 %: the laser power scales by it (S reported as
// min(S * ovr, $30)); a jog is not feed-overridden. A change shows "Ov:" in the next report,
// as a spindle or coolant change does. A reset puts them back to 100 %.
// Safety door 0x84 (no door switch: the door reads closed at once): "[MSG:Check Door]" each
// time, from Idle, Run, Hold or Jog (a jog is cancelled first); "Door:2" while decelerating,
// then laser and flood off, "Door:0"; lines wait meanwhile. "~" restores ("Door:3": 1 s when
// flood was on, 4 s for a spindle outside laser mode; no delay for a laser) and resumes the
// program, or gives Idle. Laser mode with M3/M4 on: a feed hold turns the beam off once
// stopped (DISABLE_LASER_DURING_HOLD), "~" prints "[MSG:Restoring spindle]" and resumes; 0x9E
// in that hold turns the beam back on (same message) before the resume.
//
// Main loop (protocol.c): takes bytes from the receive buffer into a line (80-byte line
// buffer: 79 characters after dropping spaces, control characters and comments, else error:11),
// upper-cases it and executes it: "$" system commands, else G-code (error:9 in Alarm). Every
// line gets exactly one "ok"/"error:N" (CR and LF both end a line, so "\r\n" gets two), sent
// once the line is executed: motion lines when queued in the 15-block planner. While the
// planner is full, during buffer syncs (spindle changes, dwells, M2/M30, G92), feed holds and
// critical alarms the main loop takes nothing from the receive buffer.
// States: Idle, Run, Hold:1 (decelerating) / Hold:0 (stopped, ready to resume), Alarm, Check,
// Home, Jog, Sleep. "$SLP" (Idle or Alarm): "ok", then "[MSG:Sleeping]", beam and motion off,
// nothing but "?" and 0x18 until a reset, which comes back locked in Alarm. Power-up with homing on ($22=1) is locked in Alarm (HOMING_INIT_LOCK).
// "$I": "[VER:1.1h.20190830:INFO]" and "[OPT:V,15,128]" ("VZ" when built with
// HOMING_FORCE_SET_ORIGIN, ControllerOptions::force_set_origin); "$I=INFO" stores INFO.
// "$N0=LINE"/"$N1=LINE" (Idle only) execute LINE to check it and store it only if it runs;
// after every reset that leaves the controller unlocked, and after "$H", each stored line runs
// and is answered ">LINE:ok" or ">LINE:error:N". "$RST=$" compiled defaults, "$RST=#" offsets,
// "$RST=*" both plus startup lines and build info; each then resets.
// "$H" (mc_homing_cycle(): Z, then X and Y) takes the time of seek ($25), pull-off ($27),
// locate ($24) and pull-off moves with the $26 debounce after each; it ends at the home
// position: stock, an axis homing towards negative ($23 bit) at -$13x + $27, otherwise at
// -$27; with force_set_origin every axis at 0. A 0x18 while homing is ALARM:6.
//
// Real-time commands: "?" status report "<Idle|MPos:0.000,0.000,0.000|FS:0,0>" (WPos when $10
// bit 0 is clear; "|Bf:blocks,bytes" free space when $10 has value 2 set; "|WCO:" every 10th
// (30th when busy) report and "|Ov:100,100,100" plus "|A:S"/"|A:C" when the beam is on, on the
// counters GRBL uses); "!" feed hold (from Run or Idle); "~" resume (only from Hold:0);
// 0x18 soft reset: in motion (Run, Hold:1) ALARM:3 first (and its 500 ms); flushes both
// buffers and the planner, resets the parser's modes (G92 too), prints the banner, and stays in
// Alarm (printing "[MSG:'$H'|'$X' to unlock]") if it was in an alarm, else runs the startup lines. A reset at Hold:0 keeps the position and
// gives Idle: GRBL's way to abort without losing position.
// "$J=" jogging (jog.c, gcode.c): from Idle or Jog (else error:8); G1 and G94 enforced, F
// required (error:22), S/T error:36, other commands than G20/G21 G90/G91 G53 error:16, each
// where gcode.c checks it (word errors first, 16 last); a target beyond the soft limits error:15
// (no alarm). Without axis words the target is machine 0,0,0 (gcode.c never fills it). The
// jog carries the parser's spindle and S: with M3 on a laser burns while jogging. Answered once queued; state Jog while it runs
// (G-code then error:9); the parser's modes stay, its position follows the jog. 0x85 (or "!")
// while jogging decelerates, flushes the planner and gives Idle with the position kept.
// Alarms: soft limits ($20=1, system_check_travel_limits()): machine space is -$13x..0 per
// axis in stock 1.1h; with force_set_origin an axis homing towards negative ($23 bit set) is
// 0..$13x. A target outside raises ALARM:2 when the line is executed (queued) - after a
// controlled feed hold if moving. ALARM:1 (hard limit; ControllerOptions::alarm_at_line) stops
// the head dead. Every alarm prints "ALARM:N", then report_alarm_message() waits 500 ms
// (kAlarmReportDelayUs) during which nothing runs and real-time bytes are lost. ALARM:1/2 then
// print "[MSG:Reset to continue]" and stay in the critical-event loop: nothing is answered,
// not even "?", until a 0x18 sent after that message (one sent before it is lost). Other codes
// (ALARM:3 reset in motion, injected ones) reset by themselves after the delay. On the reset,
// the line that was executing when the alarm struck gets its "ok", then the banner and
// "[MSG:'$H'|'$X' to unlock]".
//
// Units: the public clock is microseconds (steady, any origin, never decreasing); inside,
// nanoseconds. Positions mm. Threading: one Controller is used from one thread; the Record
// passed in is written from the same thread and must outlive the Controller.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tools/laser_emu/gcode.h"
#include "tools/laser_emu/motion.h"
#include "tools/laser_emu/record.h"
#include "tools/laser_emu/settings.h"

namespace atelier::laser_emu {

struct ControllerOptions {
  double work_w_mm = 400, work_h_mm = 400;  // $130, $131
  double time_scale = 1.0;                  // motion and dwell durations are multiplied by it
  int baud = 115200;
  // Lines are numbered from lines_before + 1 (the emulator numbers them over its whole life,
  // across replugs): every line the main loop takes counts, G-code, $ commands, empty lines.
  long lines_before = 0;
  // Fault: raise ALARM:alarm_code when the main loop takes line N. That line is not executed
  // or answered.
  std::optional<long> alarm_at_line;
  int alarm_code = 1;
  // Fault: once line N is answered the controller stops reading the serial line and answering
  // (every byte, real-time ones too, is ignored); motion already planned runs on. The program
  // uses it for a stalled link and for the moment before it pulls the cable.
  std::optional<long> halt_after_line;
  double epoch_at_zero_s = 0;  // unix time (s) of clock value 0, for the record's times
  // The power-on banner waits for host_connected() (a program on a pty that no host has
  // opened yet: an Uno prints it after the reset that opening the port causes).
  bool banner_waits_for_host = false;
  // Settings the owner stored ("$N=V" in this order) over Settings' laser values; a value GRBL
  // refuses (e.g. $20=1 before $22=1: error:10) makes the constructor throw
  // std::invalid_argument naming it.
  std::vector<std::pair<int, double>> settings;
  // Startup lines $N0/$N1 stored in EEPROM at power-on (checked like "$Nx=" when applied;
  // one that fails makes the constructor throw).
  std::string startup_lines[2];
  // The build: false = stock 1.1h (every axis homed at -$13x..0); true = built with
  // HOMING_FORCE_SET_ORIGIN ("Z" in [OPT:], homed axes at 0, an axis homing towards negative,
  // $23 bit set, then lives in 0..$13x).
  bool force_set_origin = false;
};

enum class MachineState { idle, run, hold, alarm, check, home, jog, sleep, door };

class Controller {
 public:
  static constexpr int kRxBufferSize = 128;   // RX_BUFFER_SIZE; one slot always free
  static constexpr int kTxBufferSize = 104;   // TX_BUFFER_SIZE
  static constexpr int kLineBufferSize = 80;  // LINE_BUFFER_SIZE, terminator included
  static constexpr const char* kBanner = "\r\nGrbl 1.1h ['$' for help]\r\n";
  static constexpr int64_t kAlarmReportDelayUs = 500'000;  // report_alarm_message()'s delay_ms(500)

  // Power-on at `now_us`: the banner is the first output (see banner_waits_for_host).
  Controller(ControllerOptions options, Record& record, int64_t now_us);

  // The host wrote `bytes` at `now_us` (>= the last call's time). They arrive at the serial
  // byte rate, after any earlier bytes still on the wire; advance_to() delivers them.
  void host_write(std::string_view bytes, int64_t now_us);
  // Runs everything due up to `now_us`: byte arrivals, the main loop, motion, dwells.
  void advance_to(int64_t now_us);
  // Output bytes whose transmission has completed by now, in order; removed from the queue.
  std::string take_output();
  // When something will next happen on its own (arrival, motion event, dwell end, or an output
  // byte completing), so an event loop knows how long it may sleep.
  std::optional<int64_t> next_event_us() const;

  int64_t now_us() const { return now_ / 1000; }
  MachineState state() const { return state_; }
  bool hold_complete() const { return hold_complete_; }
  // In GRBL's critical-event loop (ALARM:1/2, its 500 ms delay included): only 0x18 after
  // "[MSG:Reset to continue]" gets out of it.
  bool critical_alarm() const { return critical_ && alarm_critical_; }
  bool halted() const { return halted_; }  // halt_after_line reached
  std::string state_name() const;  // as in status reports: "Idle", "Hold:1", ...
  Vec3 position() const { return motion_.position(); }
  int rx_used() const { return static_cast<int>(rx_.size()); }
  int planner_blocks() const { return motion_.blocks(); }
  long lines_received() const { return lines_received_; }      // number of the last line taken
  long lines_acknowledged() const { return lines_acked_; }      // ok/error answers sent (count)
  long last_acknowledged_line() const { return last_acked_line_; }  // number of the last line answered
  bool output_pending() const { return !tx_.empty(); }
  double laser_s() const { return motion_.laser_s(); }  // S applied now; 0 = beam off
  const Settings& settings() const { return settings_; }
  const GcState& gcode_state() const { return gc_; }

  // The record so far, with the piece under way closed at now.
  Record snapshot() const;
  // The board loses power (cable pulled): the head stops dead and the beam goes off now.
  void power_off();
  // The host dropped DTR (closed the port, or died): an Uno's auto-reset restarts the board
  // now. Head stopped dead, beam off, planner, receive buffer, bytes on the wire and unsent
  // output discarded, parser modes and position back to power-up (0,0,0), state Alarm if
  // homing is enabled ($22=1, "[MSG:'$H'|'$X' to unlock]") else Idle. Recorded as a "hangup"
  // event then the reset's "beam_off" (if it was on). The banner comes with host_connected().
  // Settings ($$, like GRBL's EEPROM) and the halt fault stay.
  void hangup(int64_t now_us);
  // A host opened the port: after a hangup() the restarted board's banner goes out now.
  void host_connected(int64_t now_us);

 private:
  // Serial side.
  void receive_byte(uint8_t c);  // the "ISR"
  void emit(std::string_view text);
  size_t tx_backlog() const;     // bytes not yet transmitted at now_
  // Main loop.
  void run_main();
  void take_char(uint8_t c);
  void process_line();
  bool run_actions();  // false while blocked
  bool wait_sync();    // protocol_buffer_synchronize(): true once the planner is empty and stopped
  void respond(int status);
  int system_command(const std::string& line);
  void auto_cycle_start();
  // Motion and states.
  void advance_motion(int64_t t);
  void feed_hold();
  void cycle_start();
  void soft_reset();
  void raise_alarm(int code);
  bool outside_limits(const Vec3& target) const;
  void end_alarm_report();  // report_alarm_message()'s delay is over
  void abort_to_reset();    // sys.abort: the executing line's "ok", then main()'s re-initialisation
  void finish_homing();
  int store_startup_line(int index, const std::string& line);
  int jog_command(const std::string& line);  // "$J=...": status, or kPending with actions_ set
  void jog_cancel();
  void apply_overrides();           // protocol_exec_rt_system()'s override part
  void safety_door();
  void door_stopped();              // the door's hold is complete: retract (beam, coolant off)
  void finish_door_restore();
  void spindle_stop_step();         // protocol_exec_rt_suspend()'s spindle-stop handling
  void set_flood(bool on);
  void run_startup_lines();
  void reinitialise(bool announce = true);  // what GRBL's main() does after every reset; the banner if `announce`
  std::string status_report();
  double epoch(int64_t t) const { return opt_.epoch_at_zero_s + static_cast<double>(t) * 1e-9; }

  ControllerOptions opt_;
  Record& record_;
  Settings settings_;
  Motion motion_;
  GcState gc_;
  int64_t now_ = 0;         // ns
  double byte_ns_ = 0;

  std::deque<std::pair<int64_t, uint8_t>> incoming_;  // (arrival ns, byte) still on the wire
  double last_arrival_ns_ = -1e18;
  std::deque<uint8_t> rx_;
  long isr_lines_ = 0;              // line ends seen by the ISR, for overflow line numbers
  long last_overflow_line_ = 0;

  std::string tx_;                  // not yet transmitted
  double tx_head_ns_ = 0;           // when tx_[0] completes
  double last_tx_ns_ = -1e18;       // when the last taken byte completed
  bool tx_blocked_ = false;

  std::string line_;
  bool comment_paren_ = false, comment_semi_ = false, line_overflow_ = false;
  bool line_active_ = false;        // executing a G-code line's actions
  std::deque<Action> actions_;
  bool action_checked_ = false;     // soft limits checked for actions_.front()
  std::optional<int64_t> dwell_until_;
  bool reset_after_response_ = false;
  bool banner_owed_ = false;        // restarted by a hangup: the banner waits for a host
  long lines_received_ = 0, last_acked_line_ = 0, lines_acked_ = 0;

  MachineState state_ = MachineState::idle;
  bool hold_complete_ = false;
  bool critical_ = false;
  bool halted_ = false;
  bool soft_limit_stop_ = false;    // decelerating before ALARM:2
  std::optional<int64_t> alarm_report_until_;  // ns: inside report_alarm_message()'s delay
  bool alarm_critical_ = false;     // the alarm being reported is ALARM:1/2
  bool ok_owed_ = false;            // a line was executing when the alarm/reset struck
  std::optional<int64_t> homing_until_;  // ns: $H under way
  Vec3 homed_position_{};
  bool homed_once_ = false;
  bool sleep_after_response_ = false;  // "$SLP" answered: sleep next
  bool jog_line_ = false;           // the line under way is a "$J=" jog
  bool jog_cancel_ = false;         // decelerating to cancel a jog (0x85, or "!" while jogging)         // the switches are where the last $H found them
  int wco_counter_ = 0, ovr_counter_ = 0;
  // Overrides (sys.f_override, r_override, spindle_speed_ovr) and the ISR's pending flags.
  int feed_ovr_ = 100, rapid_ovr_ = 100, spindle_ovr_ = 100;
  unsigned motion_ovr_flags_ = 0, accessory_ovr_flags_ = 0;
  bool flood_on_ = false;           // the flood coolant pin (M8, 0xA0; off in a door, sleep, reset)
  unsigned spindle_stop_ = 0;       // sys.spindle_stop_ovr bits (kStop*)
  bool door_retracted_ = false;     // SUSPEND_RETRACT_COMPLETE: stopped, laser and coolant off
  bool door_after_jog_ = false;     // the door opened while a jog was being cancelled
  std::optional<int64_t> door_restore_until_;  // ns: Door:3, restoring
  long rx_pushed_ = 0;              // bytes ever put in the ring (its head index, mod 128)
  std::string build_info_;
  std::string startup_lines_[2];
};

}  // namespace atelier::laser_emu

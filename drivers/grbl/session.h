// The host side of a GRBL 1.1 session (../shared/protocols/grbl-1.1.md) over a Transport:
// banner and setup ($I, $$, $# for the work offset), single commands by send-response, job
// streaming by character counting (or send-response) with a time left that counts down while
// GRBL runs, check mode, feed hold / resume, cancel that leaves the beam off with the position
// kept, and the operator's controls (home, jog, work zero here, a console line). Alarms are
// handled as protocol.c does them: after ALARM:1/2 the reset waits for "[MSG:Reset to
// continue]" (GRBL drops one sent before), and the $X lock is left to the operator. A
// controller found at rest is not reset at connect (that would re-run its $N startup lines).
// Where a job goes on the machine (start from bed/origin/here): machine_space.h.
// Follows GRBL 1.1h's own report.c/protocol.c formats, so it works against real controllers,
// grbl-sim and tools/laser_emu alike.
//
// Time: timeouts, polls and progress throttling are on the Clock given (real_clock() in the
// daemon); the transport's reads must wait on the same clock (a SimulatedTransport on a
// FakeClock in tests).
// Threading: one Session per transport, used from one thread (the device worker). Controls
// may be set from any thread; the session reacts within ~20 ms (of its clock).
// Errors: LinkLost (from the transport) propagates unchanged; the classes below say what
// went wrong with a message for the operator. A controller that restarts by itself in the
// middle of a command or job (banner out of turn) is a DeviceError saying so.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>

#include "base/clock.h"
#include "base/error.h"
#include "drivers/grbl/messages.h"
#include "drivers/grbl/program.h"
#include "drivers/transport.h"

namespace atelier::grbl {

struct Timeouts {
  std::chrono::milliseconds banner{2500};  // banner after opening (boards reset on open), then again after 0x18
  std::chrono::milliseconds reply{3000};   // answers to setup commands ($I, $$, $C) and to '?'
  std::chrono::milliseconds poll{200};     // status '?' every 200 ms = 5 Hz at most
  std::chrono::milliseconds silent{10000}; // nothing at all received (status polls unanswered)
  std::chrono::milliseconds stop{3000};    // feed hold to settle; banner after a soft reset
};

struct MachineInfo {
  std::string version;         // "1.1h" from the banner, "1.1h.20190830" once $I answered
  int rx_buffer = 128;         // receive buffer bytes ([OPT:...,blocks,bytes])
  int planner_blocks = 15;     // planner blocks free when empty ([OPT:...,blocks,bytes])
  std::map<int, double> settings;  // $$
  double s_max = 1000, s_min = 0;  // $30, $31
  bool laser_mode = false;         // $32
  double max_travel_x = 0, max_travel_y = 0;  // $130/$131, mm
  double max_travel_z = 0;                    // $132, mm
  bool soft_limits = false;                   // $20
  bool homing = false;                        // $22
  int homing_dir_mask = 0;                    // $23: bit i set = axis i homes towards negative
  std::string build_options;                  // the letters of [OPT:letters,blocks,bytes], e.g. "VZL"
  bool force_set_origin = false;              // 'Z' in build_options: HOMING_FORCE_SET_ORIGIN
  bool alarm_locked = false;  // in Alarm: G-code refused (error:9) until $X or $H
};

enum class StreamMode { character_counting, send_response };

struct Progress {
  size_t acked = 0, total = 0;  // program lines acknowledged / in the program
  double seconds_left = 0;      // estimate from Program::seconds and the planner fill
  Status status;                // the last status report (MPos)
  // While GRBL holds at a program pause (M0): that pause's note (Program::pauses; "M0" when
  // the source has no comment before it). Empty otherwise.
  std::string paused;
};

struct Controls {
  std::atomic<bool> cancel{false};  // set from any thread
  std::atomic<bool> hold{false};    // true: feed hold ('!'); back to false: resume ('~')
  // Set from any thread to end a program pause (M0) with a cycle start ('~'); the session
  // clears it when it has sent the '~'. Ignored (and cleared) when no pause is under way.
  std::atomic<bool> release_pause{false};
};

// GRBL refused a line. what(): "line 12 (G1X500Y10F600): error:33 invalid target: ..."
// (the source line number and text); for a single command "command '$C': error:8 ...".
class GrblError : public DeviceError {
 public:
  GrblError(int code, size_t line_number, std::string line);
  int code;
  size_t line_number;  // 1-based source line; 0 for command()
  std::string line;
};

// GRBL raised an alarm. what(): "ALARM:1 hard limit at line 12 (G1X500Y10): a limit switch
// ...; check the machine, then home it ($H)" (codes.h alarm_advice).
class GrblAlarm : public DeviceError {
 public:
  explicit GrblAlarm(int code, size_t line_number = 0, std::string line = {});
  int code;
  size_t line_number;  // 1-based source line GRBL was executing (oldest unacknowledged); 0 if none
  std::string line;    // that source line as written
};

class SetupError : public DeviceError {  // no banner, laser mode off ($32=0), bad $I, ...
 public:
  using DeviceError::DeviceError;
};
class Silent : public DeviceError {  // the controller stopped answering (the link is up)
 public:
  using DeviceError::DeviceError;
};
class Canceled : public Cancelled {  // stream ended by Controls::cancel
 public:
  using Cancelled::Cancelled;
  bool position_kept = true;  // false: the reset stopped a moving head (see stop_outcome)
};

// What a stop left behind, for the operator: "the beam is off and the position kept", or that
// the position may be lost and the machine wants homing or $X before the next job.
std::string stop_outcome(bool position_kept);

class Session {
 public:
  using ProgressFn = std::function<void(const Progress&)>;

  // Borrows `link` and `clock` for its life.
  explicit Session(Transport& link, Timeouts t = {}, Clock& clock = real_clock());

  // Waits for the banner "Grbl 1.1x ['$' for help]"; if none comes within timeouts.banner,
  // asks '?': a controller at rest (Idle with an empty planner, or Alarm) is used as it is;
  // otherwise (no answer, a queue still running from an earlier connection, a hold, check
  // mode) it sends a soft reset (0x18) once and waits again. Then $I, $$ and $# (work
  // offset). Throws SetupError if there is no
  // banner, the firmware is not GRBL 1.1, or laser mode is off ($32=0). Notes an alarm lock.
  MachineInfo connect();
  // For a session kept open between jobs and commands (after connect()): checks that the
  // controller is still there and re-reads what a console line may have changed, without a
  // reset and without the banner wait. Reads what arrived since the last use (a banner there
  // means the board restarted: set up afresh, $I too), then '?', $$ and $#; a controller left
  // in check mode, a hold or sleep is reset as connect() does. Throws as connect() does
  // (Silent, LinkLost, SetupError): the caller then drops the link and connects anew.
  MachineInfo revalidate();
  const MachineInfo& info() const { return info_; }

  // Sends one line and waits for its ok (send-response; for $ commands and single G-code
  // lines). Throws GrblError on error:N, GrblAlarm on ALARM:N, Silent when nothing arrives.
  void command(const std::string& line);
  Status query_status();  // sends '?', waits for the <...> report (timeouts.reply)
  void unlock();          // $X

  // Operator controls (contract C). Each waits until done and throws as command() does.
  void home();  // $H (up to 60 s of the clock), then waits for Idle
  // $J=G91G21X..Y..F.. relative jog; waits until GRBL reports Idle again.
  void jog(double dx_mm, double dy_mm, double feed_mm_min);
  void set_origin_here();  // G10L20P1X0Y0: work zero G54 at the head's position (stored in EEPROM)
  // One console line and every line GRBL answers, up to and including its ok / error:N (an
  // error is returned, not thrown). A lone real-time byte ('?', '!', '~', 0x18, 0x80-0xFF) is
  // sent as such: '?' returns the status report, 0x18 the lines up to the banner, the others
  // nothing. Refuses (std::invalid_argument) '$RST=...' (wipes settings or offsets: not from a
  // console) and lines longer than 79 characters. ALARM:N: resets as stream() does, GrblAlarm.
  std::vector<std::string> console(const std::string& line);
  // Last work coordinate offset seen (WCO, or G54+G92 from $# at connect); query_status()
  // refreshes it. {0,0,0} when none seen.
  std::array<double, 3> work_offset() const { return wco_.value_or(std::array<double, 3>{}); }

  // Dry run in GRBL check mode: $C, stream (G-code parsed, nothing moves), $C again, which
  // makes GRBL reset itself ("[MSG:Disabled]", ok, banner): waits for that banner.
  // Throws GrblError for the first refused line (after a soft reset that leaves check mode).
  void check(const Program& p, StreamMode mode, Controls& c, const ProgressFn& on_progress);

  // Streams every line and returns once all are acknowledged and the machine is Idle again.
  // error:N: stops sending, feed hold, soft reset (the queued lines must not run), M5, then
  // GrblError for that line. ALARM:N: soft reset (for alarms 1 and 2 once GRBL has printed
  // "[MSG:Reset to continue]", up to timeouts.stop), GrblAlarm with the oldest unacknowledged
  // source line. Progress::seconds_left: estimates of the lines not yet executed (the planner's
  // Bf: fill counted as not executed) less the time the current one has been running.
  // Controls::hold: '!' when it becomes true, '~' when it becomes false (again while GRBL still
  // reports Hold, since it drops a '~' that comes before the hold is complete).
  // Controls::cancel: '!' and the laser override to 10 %, up to 50 ms for Hold:0, then 0x18
  // (at rest: position kept; still moving: beam off at once, and the ALARM:3 lock is left for
  // the operator), banner, M5, then Canceled. Nothing received for timeouts.silent: Silent.
  // Idle with lines unacknowledged for 5 s (a lost ok): hold, reset, std::runtime_error.
  // Any other unexpected exception: hold and reset before it propagates.
  // Program pause (M0): GRBL reports Hold:0 with the M0 line unanswered and its planner empty.
  // That is neither a fault nor a hold to repeat '~' for: the session keeps polling, reports
  // Progress::paused at once, and sends '~' only for Controls::release_pause (or a hold/resume
  // of the operator's own).
  void stream(const Program& p, StreamMode mode, Controls& c, const ProgressFn& on_progress);

  // Traces the bounds with the beam off (frame_program) at feed_mm_min; waits for Idle.
  void frame(const Bounds& b, double feed_mm_min, Controls& c);

  const Status& last_status() const { return last_status_; }

 private:
  void write_line(const std::string& line);
  void write_byte(uint8_t b);
  // The next non-empty line from the controller, or nullopt once `deadline` passes.
  std::optional<std::string> read_line(Clock::time_point deadline);
  // The next line, classified; status reports update last_status_ and the unlock hint
  // sets info_.alarm_locked on the way.
  std::optional<Reply> next(Clock::time_point deadline);
  bool wait_banner(std::chrono::milliseconds limit);
  // Reads what the controller sent since the last read, without waiting, and handles its
  // complete lines (next()). Returns true if a banner was among them.
  bool drain_input();
  // $I (version, buffer sizes, build options) into info_. Throws SetupError.
  void read_build_info();
  // After the banner (or at rest): $I if `build_info`, $$, $#, and a reset if the state
  // would not run a job as sent. Throws SetupError.
  void read_setup(bool build_info);
  // A setup query ($I, $$): the lines before its ok. Throws SetupError.
  std::vector<Reply> setup_query(const std::string& cmd);
  void run_lines(const Program& p, StreamMode mode, Controls& c, const ProgressFn& on_progress, bool check_mode);
  // Cancel/error path: feed hold with the laser override at its floor, up to 50 ms for the
  // head to come to rest, soft reset, banner, M5 (unless locked). Returns true if the head was
  // at rest when reset (position kept); false when the reset stopped it moving (ALARM:3: the
  // lock stays for the operator, since the position may be lost).
  bool stop_machine();
  // Last resort on an unexpected failure: feed hold and soft reset, errors ignored.
  void emergency_stop() noexcept;
  // run_lines with emergency_stop() on any unexpected exception.
  void guarded_run(const Program& p, StreamMode mode, Controls& c, const ProgressFn& on_progress, bool check_mode);
  // After ALARM:N: soft reset so the alarm's lock-up ends and the queue is dropped.
  void reset_after_alarm(int code);
  // After no banner: '?' answered with Idle or Alarm (a controller at rest whose banner went
  // before we opened the port). Anything else, or no answer, is an unknown state.
  bool answers_at_rest();
  // $#: the work offset (G54 + G92, Z with the tool length offset) into wco_.
  void read_offsets();
  // Sends `line` and waits for its ok like command(), tolerating `quiet` without any answer.
  void command_for(const std::string& line, std::chrono::milliseconds quiet);
  void wait_idle(std::chrono::milliseconds limit, const std::string& what);

  Transport& link_;
  Timeouts t_;
  Clock& clock_;
  MachineInfo info_;
  std::string rx_;                         // bytes after the last complete line
  Clock::time_point last_rx_;              // when anything last arrived
  Status last_status_;
  std::optional<std::array<double, 3>> wco_;  // last work coordinate offset reported
};

}  // namespace atelier::grbl

// The host side of an AYAB v6 session (../shared/protocols/ayab-v6.md "Session"): info with
// API check, init, wait for ready, start (with continuous reporting), answering every reqLine
// with 256-row block tracking, the blank last line and its pass, and a final reqInfo.
//
// Why a cnfLine is sent once per request, and never again on a timeout (firmware 1.0,
// com.cpp h_cnfLine and knitter.cpp knit/setNextLine): the firmware copies a cnfLine's needles
// into the buffer the solenoids are set from BEFORE it checks the CRC, says nothing about a bad
// CRC, and never asks again; at the end of a pass it asks for the next line only if a good copy
// of the requested one came, otherwise it says nothing and the next pass knits whatever the
// buffer holds. There is no acknowledgement of a good cnfLine, so a re-send after a timeout can
// only do harm: after a good copy, a garbled re-send silently replaces the right row by a wrong
// one (and the firmware asks on as if all were well). So each line goes out once, and again only
// when the firmware asks for it again (a line number it did not expect). A garbled copy is then
// found by following the carriage (indState at every needle step, continuous reporting): a pass
// that crossed the working range and ended (PassWatch) without the next reqLine right after
// was knitted from a bad buffer. That pass is not counted; knit() throws LineGarbled naming it,
// so no row that may be wrong is ever reported as knitted. Each cnfLine is followed by a reqInfo
// as a fence: the firmware handles its input after the knit step that sends an indState, in
// order, so every indState before the cnfInfo was sent while the old buffer was in place; one of
// them on the working range means the carriage was pushed before the line arrived, and that
// pass is reported the same way (LineGarbled::early). The blank last line is the one whose
// garbling the host cannot see (a good one stops the firmware without a word, a bad one keeps it
// knitting silently); it selects no needles, so at worst its one plain pass shows stray stitches.
//
// Time: deadlines and timeouts are on the Clock given (real_clock() in the daemon); the
// transport's reads must wait on the same clock (a SimulatedTransport on a FakeClock in tests).
// No wait is unbounded: each has a timeout below, and the waits for a person (the carriage
// across a turn mark, a pause between rows) last as long as the knitter likes only while the
// machine is alive - after `silent` without a word the session asks for cnfInfo, and a machine
// that does not answer within `reply` fails the wait.
// Threading: one HostSession per transport, used from one thread (the device worker).
// Errors: LinkLost (from the transport) when the machine goes away; AyabError for protocol
// failures (API mismatch, firmware errors, out-of-sequence requests, timeouts) with a
// user-facing message.
#pragma once

#include <atomic>
#include <chrono>
#include <deque>
#include <functional>
#include <optional>
#include <string>

#include "base/clock.h"
#include "base/error.h"
#include "drivers/ayab/knit_plan.h"
#include "drivers/ayab/messages.h"
#include "drivers/transport.h"

namespace atelier::ayab {

class AyabError : public DeviceError {
 public:
  using DeviceError::DeviceError;
};

// A pass crossed the working range and ended without the firmware asking for the next line:
// the line for it reached the firmware garbled (its needle buffer held the garbled copy, or the
// previous line if the copy was cut short), so that pass was not knitted as planned. `pass` is
// its index in the plan; passes before it were knitted as planned.
// `early`: instead, the carriage was on the working range before the line was in the buffer
// (pushed before the firmware had the line), so the pass mixes the old line and the new one.
class LineGarbled : public AyabError {
 public:
  LineGarbled(int pass, bool early, const std::string& message) : AyabError(message), pass(pass), early(early) {}
  int pass;
  bool early;
};

// The machine stopped answering (not even a reqInfo) while knitting, or while init() waited for
// the carriage (passes_done 0); passes before `passes_done` were knitted. Firmware 1.0 hangs
// like this on a garbled SLIP escape until the board is reset.
class MachineSilent : public AyabError {
 public:
  MachineSilent(int passes_done, const std::string& message) : AyabError(message), passes_done(passes_done) {}
  int passes_done;
};

// The firmware refused reqStart (cnfStart with an error). Firmware 1.0 answers 0xEF
// (wrong_machine_state) outside its ready state, e.g. a board that was not reset when the port
// opened and still knits an earlier session's pattern: resetting the board (Transport::pulse_dtr)
// and a new connect/init/start may recover. what(): "the knitting machine refused to start:
// <error and state>; <what to do>".
class StartRefused : public AyabError {
 public:
  StartRefused(uint8_t code, const std::string& message) : AyabError(message), code(code) {}
  uint8_t code;
  bool wrong_state() const { return err::is_wrong_state(code); }
};

struct SessionTimeouts {
  std::chrono::milliseconds boot{5000};        // first cnfInfo after opening (Arduino reset ~2 s)
  std::chrono::milliseconds info_retry{100};   // reqInfo repeat interval while booting
  std::chrono::milliseconds reply{1000};       // cnfInit / cnfStart
  std::chrono::milliseconds ready{0};          // indState ready after init; 0 = as long as the machine answers
  std::chrono::milliseconds pass_end{1000};    // no reqLine this long after a pass ended: its line was garbled
  std::chrono::milliseconds silent{10000};     // nothing at all from the machine this long: fail
};

struct KnitProgress {
  int passes_done = 0;   // carriage passes confirmed knitted
  int passes_total = 0;
};

// Moments of a session a knitter is told about (the device words them). Called on the
// session's thread, from init() and knit().
struct SessionEvents {
  // init() confirmed: the firmware waits for the carriage to pass a turn mark.
  std::function<void()> waiting_for_carriage;
  // The blank last line was sent: one more pass of the carriage ends the knitting (firmware 1.0
  // beeps twice then). Not called for a canceled job, whose end is not waited for.
  std::function<void()> last_pass;
};

class HostSession {
 public:
  // Borrows `link` and `clock` for its life.
  HostSession(Transport& link, SessionTimeouts timeouts = {}, Clock& clock = real_clock());
  void set_events(SessionEvents events) { events_ = std::move(events); }

  // reqInfo until cnfInfo (tolerating the boot delay); throws AyabError for api < 6.
  CnfInfo connect();
  // reqInit(machine) until cnfInit (asking again when the firmware says it got it garbled:
  // 0x01 too short, 0x04 bad CRC); then waits for indState ready (carriage past a turn mark).
  // A firmware that answers wrong state is initialised already (the board was not reset when
  // the port opened): init() returns at once and was_reset() is false.
  void init(MachineType machine);
  bool was_reset() const { return reset_; }
  // reqStart with the plan's needle range and continuous reporting, until cnfStart (or a
  // reqLine, if the cnfStart was lost); asked again on cnfStart 0x01/0x04 (garbled request).
  // Throws StartRefused for an error, AyabError when nothing answers within `reply`.
  void start(const KnitPlan& plan);
  // Knits plan.passes[from_pass ...]: start(plan) unless it was called, then answers each
  // reqLine once (again only when asked again). `on_pass` is called after each pass the
  // firmware has confirmed by asking for the next line. When `cancel` becomes true the session
  // answers the next request with the blank last line (the machine ends cleanly) and returns
  // early. Returns the passes done in total (from_pass + knitted now). Ends with the blank last
  // line, its pass (waited for when the firmware reports the carriage) and a final
  // reqInfo/cnfInfo. Throws LineGarbled (see above), MachineSilent when the machine stops
  // answering, LinkLost, AyabError.
  int knit(const KnitPlan& plan, int from_pass, const std::function<void(const KnitProgress&)>& on_pass,
           const std::atomic<bool>& cancel);

  // Every message received (for logs/tests): last indState seen.
  const IndState& last_state() const { return last_state_; }

 private:
  void send(const Message& m);
  // The next valid message, or nullopt once `deadline` passes. Records indState.
  std::optional<Message> receive(Clock::time_point deadline);
  // Waits for an indState ready (error 0) after init: until `ready`, or while the machine
  // answers cnfInfo when asked after `silent` of silence (ready = 0). Throws AyabError.
  void wait_ready();

  Transport& link_;
  SessionTimeouts timeouts_;
  SessionEvents events_;
  Clock& clock_;
  IndState last_state_;
  SlipDecoder decoder_;           // one byte stream across connect/init/knit
  std::deque<Message> pending_;   // decoded, not yet consumed
  int line_bytes_ = 25;           // needle data bytes of the machine given to init()
  bool reset_ = true;             // the last init() found the firmware freshly booted
  bool started_ = false;          // start() succeeded; knit() does not ask again
  bool state_seen_ = false;       // an indState arrived since connect()
};

}  // namespace atelier::ayab

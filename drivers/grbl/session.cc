#include "drivers/grbl/session.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <deque>
#include <vector>

#include "drivers/grbl/char_counter.h"
#include "drivers/grbl/codes.h"

namespace atelier::grbl {
namespace {

using std::chrono::milliseconds;

constexpr uint8_t kSoftReset = 0x18;
constexpr uint8_t kSpindleOverrideMinus10 = 0x9B;  // real-time: spindle (laser) override -10 %
// A cancel gives the feed hold this long to bring the head to rest (a reset at rest keeps the
// position); a head still moving then is stopped by a soft reset at once, so the beam is off
// within ~100 ms of the request whatever the feed and acceleration ($120/$121).
constexpr milliseconds kHoldBudget{50};
constexpr milliseconds kHoldPoll{10};
// Lines in flight, the machine Idle with an empty planner, and no ok for this long: an ok was
// lost (a noisy line) and the stream is out of step.
constexpr milliseconds kOutOfStep{5000};
// Longest a read blocks, so controls set from another thread take effect within this.
constexpr milliseconds kSlice{10};
// Progress callbacks at most this often (acks can arrive at hundreds per second).
constexpr milliseconds kProgressEvery{100};

std::string seconds_text(milliseconds ms) {
  char buf[32];
  if (ms.count() % 1000 == 0) std::snprintf(buf, sizeof buf, "%lld s", static_cast<long long>(ms.count() / 1000));
  else std::snprintf(buf, sizeof buf, "%.1f s", static_cast<double>(ms.count()) / 1000.0);
  return buf;
}

std::string trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

std::string error_text(int code, size_t line_number, const std::string& line) {
  const std::string where = line_number > 0 ? "line " + std::to_string(line_number) + " (" + trim(line) + ")"
                                            : "command '" + line + "'";
  return where + ": error:" + std::to_string(code) + " " + error_meaning(code);
}

// States in which a feed hold has nothing left to decelerate (Door:2/3 still move).
bool settled(const Status& s) {
  return (s.state == "Hold" && s.substate == 0) || s.state == "Idle" || s.state == "Check" || s.state == "Alarm" ||
         (s.state == "Door" && (s.substate == 0 || s.substate == 1)) || s.state == "Sleep";
}

}  // namespace

GrblError::GrblError(int c, size_t n, std::string l)
    : DeviceError(error_text(c, n, l)), code(c), line_number(n), line(std::move(l)) {}

namespace {
std::string alarm_text(int code, size_t line_number, const std::string& line) {
  std::string where;
  if (line_number > 0) where = " at line " + std::to_string(line_number) + " (" + trim(line) + ")";
  const std::string advice = alarm_advice(code);
  // "ALARM:1 hard limit at line 12 (G1X5): a limit switch was hit, ..."
  const size_t colon = advice.find(':');
  if (colon == std::string::npos) return "ALARM:" + std::to_string(code) + where + " " + advice;
  return "ALARM:" + std::to_string(code) + " " + advice.substr(0, colon) + where + advice.substr(colon);
}
}  // namespace

GrblAlarm::GrblAlarm(int c, size_t n, std::string l)
    : DeviceError(alarm_text(c, n, l)), code(c), line_number(n), line(std::move(l)) {}

Session::Session(Transport& link, Timeouts t, Clock& clock)
    : link_(link), t_(t), clock_(clock), last_rx_(clock.now()) {}

void Session::write_line(const std::string& line) {
  const std::string wire = line + "\n";
  link_.write(reinterpret_cast<const uint8_t*>(wire.data()), wire.size());
}

void Session::write_byte(uint8_t b) { link_.write(&b, 1); }

std::optional<std::string> Session::read_line(Clock::time_point deadline) {
  uint8_t buf[256];
  for (;;) {
    // GRBL ends lines with "\r\n"; split on '\n', drop '\r' and empty lines (banner padding).
    for (size_t nl; (nl = rx_.find('\n')) != std::string::npos;) {
      std::string line = rx_.substr(0, nl);
      rx_.erase(0, nl + 1);
      line.erase(std::remove(line.begin(), line.end(), '\r'), line.end());
      if (!line.empty()) return line;
    }
    const auto now = clock_.now();
    if (now >= deadline) return std::nullopt;
    const auto wait = std::min<Clock::duration>(deadline - now, kSlice);
    const size_t n = link_.read(buf, sizeof buf, std::chrono::ceil<milliseconds>(wait));
    if (n > 0) {
      last_rx_ = clock_.now();
      rx_.append(reinterpret_cast<const char*>(buf), n);
    }
  }
}

std::optional<Reply> Session::next(Clock::time_point deadline) {
  auto line = read_line(deadline);
  if (!line) return std::nullopt;
  Reply r = classify(*line);
  switch (r.kind) {
    case Reply::status:
      if (auto s = parse_status(*line)) {
        if (s->wco) wco_ = s->wco;
        if (s->has_wpos && wco_) apply_wco(*s, *wco_);
        last_status_ = *s;
        info_.alarm_locked = s->state == "Alarm";
      }
      break;
    case Reply::feedback:
      if (r.text == "MSG:'$H'|'$X' to unlock") info_.alarm_locked = true;
      else if (r.text == "MSG:Caution: Unlocked") info_.alarm_locked = false;
      break;
    case Reply::alarm:
      info_.alarm_locked = true;
      break;
    case Reply::banner:
      // A fresh start: the lock hint follows right after it if GRBL stays in Alarm.
      info_.alarm_locked = false;
      wco_.reset();
      break;
    default:
      break;
  }
  return r;
}

bool Session::wait_banner(milliseconds limit) {
  const auto deadline = clock_.now() + limit;
  while (auto r = next(deadline))
    if (r->kind == Reply::banner) {
      if (info_.version.rfind(r->text, 0) != 0) info_.version = r->text;  // keep "1.1h.2019..." from $I
      return true;
    }
  return false;
}

std::vector<Reply> Session::setup_query(const std::string& cmd) {
  write_line(cmd);
  std::vector<Reply> out;
  const auto deadline = clock_.now() + t_.reply;
  for (;;) {
    auto r = next(deadline);
    if (!r) throw SetupError("GRBL did not answer " + cmd + " within " + seconds_text(t_.reply));
    if (r->kind == Reply::ok) return out;
    if (r->kind == Reply::error)
      throw SetupError("GRBL refused " + cmd + ": error:" + std::to_string(r->code) + " " + error_meaning(r->code));
    if (r->kind == Reply::banner) throw SetupError("GRBL restarted while answering " + cmd);
    out.push_back(std::move(*r));
  }
}

MachineInfo Session::connect() {
  info_ = MachineInfo{};
  rx_.clear();
  wco_.reset();
  last_status_ = Status{};
  // Boards with an auto-reset print the banner ~1-2 s after the port opens. Others (and
  // pseudo-terminals) printed it long ago: a soft reset makes them print it again.
  if (!wait_banner(t_.banner) && !answers_at_rest()) {
    // No banner and no sensible answer to '?': an unknown state, so a soft reset (it also
    // stops a queue still running from an earlier connection). Otherwise no reset: a reset
    // re-runs the user's $N startup lines.
    write_byte(kSoftReset);
    if (!wait_banner(t_.banner))
      throw SetupError("no GRBL banner within " + seconds_text(t_.banner) +
                       ", nor after a soft reset: check the port, the baud rate (115200) and that the controller "
                       "runs GRBL 1.1");
  }
  // Without a banner (a controller at rest) the version comes from $I below.
  if (!info_.version.empty() && info_.version.rfind("1.1", 0) != 0)
    throw SetupError("the controller runs GRBL " + info_.version + "; atelier needs GRBL 1.1");

  read_setup(true);
  return info_;
}

MachineInfo Session::revalidate() {
  // What came in since the last use: status reports, an alarm (a limit switch touched by
  // hand), or a banner (the board restarted: power, USB reset, a reset button).
  if (drain_input()) {
    const std::string version = info_.version;
    info_ = MachineInfo{};
    info_.version = version;
    last_status_ = Status{};
    read_setup(true);
    return info_;
  }
  // Still there? A kept link to a board that went quiet fails here, before anything of a job.
  query_status();
  read_setup(false);
  return info_;
}

bool Session::drain_input() {
  uint8_t buf[256];
  for (size_t n; (n = link_.read(buf, sizeof buf, milliseconds(0))) > 0;) {
    last_rx_ = clock_.now();
    rx_.append(reinterpret_cast<const char*>(buf), n);
  }
  bool banner = false;
  while (auto r = next(clock_.now()))  // the complete lines only: nothing more is read
    if (r->kind == Reply::banner) {
      banner = true;
      if (info_.version.rfind(r->text, 0) != 0) info_.version = r->text;
    }
  return banner;
}

void Session::read_build_info() {
  // Without [OPT:...,blocks,bytes] (GRBL 1.1 before 1.1d) the 1.1 defaults stand: 15, 128.
  for (const Reply& r : setup_query("$I")) {
    if (r.kind != Reply::feedback) continue;
    if (r.text.rfind("VER:", 0) == 0) {
      std::string v = r.text.substr(4);
      v = v.substr(0, v.find(':'));
      if (!v.empty()) info_.version = v;
    } else if (auto opt = parse_opt("[" + r.text + "]")) {
      info_.planner_blocks = opt->first;
      info_.rx_buffer = opt->second;
      const std::string body = r.text.substr(4);
      info_.build_options = body.substr(0, body.find(','));
      info_.force_set_origin = info_.build_options.find('Z') != std::string::npos;
    }
  }
  if (info_.version.rfind("1.1", 0) != 0)
    throw SetupError("the controller runs GRBL " + (info_.version.empty() ? std::string("(no version in $I)") : info_.version) +
                     "; atelier needs GRBL 1.1");
  // Character counting needs room for the longest line (79 characters and '\n') plus one.
  if (info_.rx_buffer < static_cast<int>(kMaxLineChars) + 2)
    throw SetupError("GRBL reports a receive buffer of " + std::to_string(info_.rx_buffer) +
                     " bytes in $I; streaming needs at least " + std::to_string(kMaxLineChars + 2));

}

void Session::read_setup(bool build_info) {
  if (build_info) read_build_info();
  info_.settings.clear();
  for (const Reply& r : setup_query("$$"))
    if (r.kind == Reply::setting)
      if (auto s = parse_setting("$" + std::to_string(r.code) + "=" + r.text)) info_.settings[s->first] = s->second;
  const auto setting = [&](int n) -> std::optional<double> {
    auto it = info_.settings.find(n);
    return it == info_.settings.end() ? std::nullopt : std::optional<double>(it->second);
  };
  if (!setting(32))
    throw SetupError("GRBL did not report $32 (laser mode) in $$; the firmware needs variable spindle (PWM) support");
  info_.laser_mode = *setting(32) == 1;
  if (!info_.laser_mode) throw SetupError("laser mode is off ($32=0); set $32=1 on the controller");
  info_.s_max = setting(30).value_or(1000);
  info_.s_min = setting(31).value_or(0);
  info_.soft_limits = setting(20).value_or(0) == 1;
  info_.max_travel_x = setting(130).value_or(0);
  info_.max_travel_y = setting(131).value_or(0);
  info_.max_travel_z = setting(132).value_or(0);
  info_.homing = setting(22).value_or(0) == 1;
  info_.homing_dir_mask = static_cast<int>(setting(23).value_or(0));
  read_offsets();

  // Alarm (after power-up with homing enabled) is noted in alarm_locked. A controller left in
  // check mode, a hold, a door or sleep by someone else would not run the job as sent: a soft
  // reset brings it back to Idle (or to a lock the operator must clear).
  const Status s = query_status();
  if (s.state != "Idle" && s.state != "Alarm") {
    write_byte(kSoftReset);
    if (!wait_banner(t_.stop))
      throw SetupError("GRBL was in state " + s.state + " and did not restart after a soft reset");
    const Status again = query_status();
    if (again.state != "Idle" && again.state != "Alarm")
      throw SetupError("GRBL stays in state " + again.state + " after a soft reset (a safety door open?)");
  }
}

Status Session::query_status() {
  write_byte('?');
  const auto deadline = clock_.now() + t_.reply;
  for (;;) {
    auto r = next(deadline);
    if (!r) throw Silent("GRBL did not answer a status request ('?') within " + seconds_text(t_.reply));
    if (r->kind == Reply::status && parse_status(r->text)) return last_status_;
  }
}

void Session::command(const std::string& line) { command_for(line, t_.silent); }

void Session::command_for(const std::string& line, milliseconds quiet) {
  write_line(line);
  last_rx_ = clock_.now();
  auto last_poll = clock_.now();
  for (;;) {
    const auto now = clock_.now();
    if (now - last_rx_ >= quiet)
      throw Silent("GRBL did not answer '" + line + "' within " + seconds_text(quiet) +
                   " and stopped answering status requests");
    // Some lines (M5, G4) are answered only once motion before them ends: poll meanwhile so
    // a slow answer is told apart from a controller that is gone.
    if (now - last_poll >= t_.poll) {
      write_byte('?');
      last_poll = now;
    }
    auto r = next(std::min(last_poll + t_.poll, now + quiet));
    if (!r) continue;
    switch (r->kind) {
      case Reply::ok: return;
      case Reply::error: throw GrblError(r->code, 0, line);
      case Reply::alarm:
        reset_after_alarm(r->code);
        throw GrblAlarm(r->code);
      case Reply::banner:
        throw DeviceError("GRBL restarted while running '" + line + "'");
      default: break;
    }
  }
}

void Session::unlock() { command("$X"); }

bool Session::answers_at_rest() {
  write_byte('?');
  const auto deadline = clock_.now() + t_.reply;
  while (auto r = next(deadline)) {
    if (r->kind == Reply::banner) {  // a slow board's own start after all: a known state
      info_.version = r->text;
      return true;
    }
    if (r->kind == Reply::status && parse_status(r->text)) {
      const bool empty = last_status_.planner_free < 0 || last_status_.planner_free >= info_.planner_blocks;
      return (last_status_.state == "Idle" && empty) || last_status_.state == "Alarm";
    }
  }
  return false;
}

void Session::read_offsets() {
  // "[G54:x,y,z]", "[G92:x,y,z]", "[TLO:z]": work = machine - (G54 + G92), Z less the TLO too.
  std::array<double, 3> g54{}, g92{};
  double tlo = 0;
  bool seen = false;
  const auto values = [](const std::string& text, size_t from) {
    std::array<double, 3> v{};
    size_t at = from;
    for (int i = 0; i < 3 && at != std::string::npos; ++i) {
      v[i] = std::strtod(text.c_str() + at, nullptr);
      at = text.find(',', at);
      if (at != std::string::npos) ++at;
    }
    return v;
  };
  for (const Reply& r : setup_query("$#")) {
    if (r.kind != Reply::feedback) continue;
    if (r.text.rfind("G54:", 0) == 0) g54 = values(r.text, 4), seen = true;
    else if (r.text.rfind("G92:", 0) == 0) g92 = values(r.text, 4);
    else if (r.text.rfind("TLO:", 0) == 0) tlo = std::strtod(r.text.c_str() + 4, nullptr);
  }
  if (seen) wco_ = std::array<double, 3>{g54[0] + g92[0], g54[1] + g92[1], g54[2] + g92[2] + tlo};
}

void Session::wait_idle(milliseconds limit, const std::string& what) {
  const auto deadline = clock_.now() + limit;
  for (;;) {
    const Status s = query_status();
    if (s.state == "Idle") return;
    if (s.state == "Alarm") throw DeviceError("GRBL went into Alarm during " + what);
    if (clock_.now() >= deadline)
      throw DeviceError("GRBL was still " + s.state + " " + seconds_text(limit) + " after " + what);
    auto r = next(clock_.now() + t_.poll);  // paces the polls; the reply is handled in next()
    if (r && r->kind == Reply::alarm) {
      reset_after_alarm(r->code);
      throw GrblAlarm(r->code);
    }
  }
}

void Session::home() {
  // GRBL answers $H only once the cycle ends and may report nothing meanwhile.
  constexpr milliseconds kHoming{60000};
  command_for("$H", kHoming);
  wait_idle(t_.stop, "homing ($H)");
  query_status();  // the report after $H carries the new WCO
}

void Session::jog(double dx_mm, double dy_mm, double feed_mm_min) {
  if (!(feed_mm_min > 0)) throw std::invalid_argument("a jog needs a feed above 0 mm/min");
  char buf[96];
  std::snprintf(buf, sizeof buf, "$J=G91G21X%.3fY%.3fF%.0f", dx_mm, dy_mm, feed_mm_min);
  // A jog runs under the modal spindle state: after a console M3/M4 S.. it would burn a line
  // all along the way. M5 first, so a jog only ever moves the head.
  command("M5");
  command(buf);  // ok: the jog was accepted (error:15 past the travel, error:8 not Idle)
  // Time for the distance at the feed, plus room for acceleration.
  const double seconds = std::hypot(dx_mm, dy_mm) / feed_mm_min * 60.0;
  wait_idle(milliseconds(static_cast<long long>(seconds * 1000 * 2)) + t_.stop, std::string("jog ") + buf);
}

void Session::set_origin_here() {
  command("G10L20P1X0Y0");
  query_status();  // GRBL sends WCO in the next report after an offset change
}

std::vector<std::string> Session::console(const std::string& line) {
  std::vector<std::string> out;
  if (line.size() == 1 && (line[0] == '?' || line[0] == '!' || line[0] == '~' || line[0] == 0x18 ||
                           static_cast<uint8_t>(line[0]) >= 0x80)) {
    const uint8_t b = static_cast<uint8_t>(line[0]);
    if (b == '?') {
      write_byte(b);
      const auto deadline = clock_.now() + t_.reply;
      while (auto l = read_line(deadline)) {
        out.push_back(*l);
        const Reply r = classify(*l);
        if (r.kind == Reply::status) {
          if (auto st = parse_status(*l)) {
            if (st->wco) wco_ = st->wco;
            if (st->has_wpos && wco_) apply_wco(*st, *wco_);
            last_status_ = *st;
          }
          return out;
        }
      }
      throw Silent("GRBL did not answer '?' within " + seconds_text(t_.reply));
    }
    write_byte(b);
    if (b != kSoftReset) return out;
    const auto deadline = clock_.now() + t_.stop;
    while (auto l = read_line(deadline)) {
      out.push_back(*l);
      const Reply r = classify(*l);
      if (r.kind == Reply::banner) {
        wco_.reset();
        info_.alarm_locked = false;
        return out;
      }
      if (r.kind == Reply::alarm) info_.alarm_locked = true;
    }
    throw Silent("GRBL did not restart within " + seconds_text(t_.stop) + " of a soft reset");
  }
  const std::string upper = [&] {
    std::string u;
    for (char ch : line)
      if (ch != ' ') u += static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
    return u;
  }();
  if (upper.rfind("$RST=", 0) == 0)
    throw std::invalid_argument("'" + line + "' wipes GRBL's settings or offsets; atelier does not send it from the console");
  if (line.size() > kMaxLineChars)
    throw std::invalid_argument("a console line holds at most " + std::to_string(kMaxLineChars) + " characters");
  if (line.find_first_of("\r\n") != std::string::npos) throw std::invalid_argument("one console line at a time");
  // $H is answered when the cycle ends, and GRBL may report nothing meanwhile.
  const milliseconds quiet = upper.rfind("$H", 0) == 0 ? std::max<milliseconds>(t_.silent, milliseconds(60000)) : t_.silent;
  write_line(line);
  last_rx_ = clock_.now();
  auto last_poll = clock_.now();
  for (;;) {
    const auto now = clock_.now();
    if (now - last_rx_ >= quiet) throw Silent("GRBL did not answer '" + line + "' within " + seconds_text(quiet));
    if (now - last_poll >= t_.poll) {
      write_byte('?');  // its report is not the operator's: not returned
      last_poll = now;
    }
    auto l = read_line(std::min(last_poll + t_.poll, now + quiet));
    if (!l) continue;
    const Reply r = classify(*l);
    if (r.kind != Reply::status) out.push_back(*l);
    switch (r.kind) {
      case Reply::status:
        if (auto st = parse_status(*l)) {
          if (st->wco) wco_ = st->wco;
          if (st->has_wpos && wco_) apply_wco(*st, *wco_);
          last_status_ = *st;
          info_.alarm_locked = st->state == "Alarm";
        }
        break;
      case Reply::ok:
      case Reply::error: return out;
      case Reply::alarm:
        info_.alarm_locked = true;
        reset_after_alarm(r.code);
        throw GrblAlarm(r.code, 0, line);
      case Reply::banner: throw DeviceError("GRBL restarted while running '" + line + "'");
      case Reply::feedback:
        if (r.text == "MSG:'$H'|'$X' to unlock") info_.alarm_locked = true;
        else if (r.text == "MSG:Caution: Unlocked") info_.alarm_locked = false;
        break;
      default: break;
    }
  }
}

void Session::reset_after_alarm(int code) {
  // Hard and soft limit alarms (1, 2) lock GRBL up until a reset, but protocol.c clears any
  // reset already received once it has printed "[MSG:Reset to continue]" (report.c waits
  // 500 ms after "ALARM:N" first) and answers no '?' meanwhile: a 0x18 sent before that
  // message is lost and GRBL stays frozen. So wait for it. For the others a reset drops what
  // is still queued. The alarm lock stays: unlocking is the operator's decision.
  if (code == 1 || code == 2) {
    const auto deadline = clock_.now() + t_.stop;
    while (auto r = next(deadline))
      if (r->kind == Reply::feedback && r->text == "MSG:Reset to continue") break;
  }
  write_byte(kSoftReset);
  if (!wait_banner(t_.stop)) return;  // the caller reports the alarm either way
  try {
    query_status();  // reads the lock hint that follows the banner
  } catch (const Silent&) {
  }
}

bool Session::stop_machine() {
  // Feed hold, and the laser override down to GRBL's floor (10 %) at once: in M4 the beam
  // also fades with the speed, and GRBL turns it off when the hold is complete.
  write_byte('!');
  for (int i = 0; i < 9; ++i) write_byte(kSpindleOverrideMinus10);
  const auto hold_by = clock_.now() + kHoldBudget;
  // A report already on its way answers a '?' sent before the hold: only the ones asked for
  // afterwards count, so skip as many reports as there were requests outstanding (at most one).
  int stale = 1;
  bool at_rest = false;
  Clock::time_point last_poll{};
  while (!at_rest) {
    const auto now = clock_.now();
    if (now >= hold_by) break;
    if (now - last_poll >= kHoldPoll) {
      write_byte('?');
      last_poll = now;
    }
    auto r = next(std::min(hold_by, last_poll + kHoldPoll));
    if (!r || r->kind != Reply::status) continue;
    if (stale-- > 0) continue;
    at_rest = settled(last_status_);
  }
  // At rest a reset keeps the position; in motion it stops the beam and steppers at once and
  // raises ALARM:3 (position possibly lost): the lock stays for the operator to clear.
  write_byte(kSoftReset);
  const auto banner_by = clock_.now() + t_.stop;
  for (bool banner = false; !banner;) {
    auto r = next(banner_by);
    if (!r)
      throw Silent("GRBL did not restart within " + seconds_text(t_.stop) +
                   " of a soft reset; the controller's state (and the beam's) is unknown");
    banner = r->kind == Reply::banner;
  }
  query_status();  // the lock hint, if any, came before this report
  if (!info_.alarm_locked) command("M5");
  return at_rest && !info_.alarm_locked;
}

void Session::emergency_stop() noexcept {
  try {
    write_byte('!');
    write_byte(kSoftReset);
  } catch (...) {  // best effort: the caller is already failing
  }
}

std::string stop_outcome(bool position_kept) {
  return position_kept ? "the beam is off and the position kept"
                       : "the beam is off; the head was still moving, so its position may be lost: home the "
                         "machine (or unlock it with $X) before the next job";
}

void Session::run_lines(const Program& p, StreamMode mode, Controls& c, const ProgressFn& on_progress,
                        bool check_mode) {
  const size_t n = p.lines.size();
  const bool counting = mode == StreamMode::character_counting;
  CharCounter window(counting ? static_cast<size_t>(std::max(info_.rx_buffer - 1, 1)) : SIZE_MAX);
  std::deque<size_t> in_flight;  // indices into p.lines, oldest first
  size_t next_line = 0, acked = 0;

  std::vector<double> left(n + 1, 0.0);  // left[i]: seconds of lines i..n-1
  for (size_t i = n; i-- > 0;) left[i] = left[i + 1] + (i < p.seconds.size() ? p.seconds[i] : 0.0);

  Progress prog;
  prog.total = n;
  Clock::time_point last_report{};
  // Time left counts down while GRBL runs, not only at acks: the first line not yet executed
  // (acknowledged lines still in the planner count as not executed: the status's Bf: fill, or
  // the whole planner when reports carry no Bf:), less the time it has been running.
  size_t running_line = 0;
  double running_for = 0;     // seconds the machine reported Run while on running_line
  bool fresh_status = false;  // a report arrived during this run (the one before is stale)
  bool done_polled = false;   // a '?' went out after the last ok
  Clock::time_point last_tick = clock_.now();
  const auto report = [&](bool force) {
    const auto now = clock_.now();
    if (last_status_.state == "Run") running_for += std::chrono::duration<double>(now - last_tick).count();
    last_tick = now;
    if (!on_progress) return;
    if (!force && now - last_report < kProgressEvery) return;
    last_report = now;
    prog.acked = acked;
    prog.status = last_status_;
    size_t queued = 0;
    if (!check_mode)
      queued = fresh_status && last_status_.planner_free >= 0
                   ? static_cast<size_t>(std::max(0, info_.planner_blocks - last_status_.planner_free))
                   : static_cast<size_t>(info_.planner_blocks);
    if (!check_mode && acked == n && done_polled && last_status_.state == "Idle") queued = 0;
    const size_t first = acked - std::min(queued, acked);
    if (first != running_line) {
      running_line = first;
      running_for = 0;
    }
    const double current = first < n && first < p.seconds.size() ? p.seconds[first] : 0.0;
    prog.seconds_left = std::max(0.0, left[first] - std::min(running_for, current));
    on_progress(prog);
  };

  bool hold_sent = false;
  bool resume_polled = false;  // a '?' went out since the last '~'
  // The M0 line GRBL is pausing at (paused) and the last pause released, which a report
  // asked for before the '~' may still show as held.
  std::optional<size_t> paused_at, released_at;
  const auto at_program_pause = [&]() -> std::optional<size_t> {
    if (in_flight.empty() || !p.pauses.count(in_flight.front()) || released_at == in_flight.front())
      return std::nullopt;
    const Status& s = last_status_;
    const bool planner_empty = s.planner_free < 0 || s.planner_free >= info_.planner_blocks;
    if (s.state == "Hold" && s.substate == 0 && planner_empty) return in_flight.front();
    return std::nullopt;
  };
  Clock::time_point last_ack = clock_.now();
  Clock::time_point last_poll{};
  last_rx_ = clock_.now();
  for (;;) {
    if (c.cancel) {
      const bool kept = stop_machine();
      Canceled canceled("canceled by the operator after " + std::to_string(acked) + " of " + std::to_string(n) +
                        " lines; " + stop_outcome(kept));
      canceled.position_kept = kept;
      throw canceled;
    }
    const bool want_hold = c.hold;
    if (want_hold != hold_sent) {
      write_byte(want_hold ? '!' : '~');
      hold_sent = want_hold;
      resume_polled = false;
    }
    if (c.release_pause.exchange(false) && paused_at) {
      write_byte('~');  // GRBL is at Hold:0, where a cycle start is always taken
      released_at = paused_at;
      paused_at.reset();
      prog.paused.clear();
      report(true);
    }
    while (next_line < n) {
      const size_t bytes = p.lines[next_line].size() + 1;
      if (counting ? !window.fits(bytes) : !in_flight.empty()) break;
      write_line(p.lines[next_line]);
      window.sent(bytes);
      in_flight.push_back(next_line++);
    }
    if (check_mode && acked == n) {
      report(true);
      return;  // check mode moves nothing: every line answered is the end
    }
    const auto now = clock_.now();
    if (now - last_rx_ >= t_.silent) {
      // Whatever it is doing, it must not go on doing it unattended.
      write_byte('!');
      write_byte(kSoftReset);
      throw Silent("GRBL stopped answering (nothing for " + seconds_text(t_.silent) + ") after " +
                   std::to_string(acked) + " of " + std::to_string(n) + " lines; sent feed hold and reset");
    }
    if (now - last_poll >= t_.poll) {
      write_byte('?');
      last_poll = now;
      if (acked == n) done_polled = true;
      if (!hold_sent) resume_polled = true;
    }
    auto r = next(std::min(last_poll + t_.poll, now + kSlice));
    if (!r) continue;
    switch (r->kind) {
      case Reply::ok:
        if (in_flight.empty()) throw DeviceError("GRBL sent 'ok' with no line in flight (protocol out of step)");
        in_flight.pop_front();
        window.acked();
        ++acked;
        last_ack = clock_.now();
        // The last ok: ask for the status at once rather than at the next poll (up to 200 ms
        // later), so the job ends as soon as GRBL is Idle (on a fast machine, ~1 % of a job).
        if (acked == n && !check_mode) last_poll = Clock::time_point{};
        report(acked == n);
        break;
      case Reply::error: {
        if (in_flight.empty())
          throw DeviceError("GRBL sent error:" + std::to_string(r->code) + " with no line in flight");
        const size_t k = in_flight.front();
        stop_machine();  // lines already queued would still run; the error says what matters
        throw GrblError(r->code, static_cast<size_t>(p.source_line[k]), p.source_text[k]);
      }
      case Reply::alarm: {
        // The oldest line not yet acknowledged is the one GRBL was on.
        const size_t line_number = in_flight.empty() ? 0 : static_cast<size_t>(p.source_line[in_flight.front()]);
        const std::string text = in_flight.empty() ? "" : p.source_text[in_flight.front()];
        reset_after_alarm(r->code);
        throw GrblAlarm(r->code, line_number, text);
      }
      case Reply::banner: {
        const int at = acked < n ? p.source_line[acked] : p.source_line.empty() ? 0 : p.source_line.back();
        throw DeviceError("GRBL restarted during the job (near line " + std::to_string(at) +
                                 "); the rest of the job was not run");
      }
      case Reply::status: {
        fresh_status = true;
        const bool idle_and_empty = last_status_.state == "Idle" &&
            (last_status_.planner_free < 0 || last_status_.planner_free >= info_.planner_blocks);
        // Done once a report requested after the last ok says Idle with an empty planner.
        if (acked == n && done_polled && idle_and_empty) {
          report(true);
          return;
        }
        if (auto pause = at_program_pause(); pause && !paused_at) {
          paused_at = pause;
          const std::string& note = p.pauses.at(*pause);
          prog.paused = note.empty() ? "M0" : note;
          report(true);
          break;
        }
        // GRBL takes '~' only once a hold is complete: a resume sent during the deceleration
        // is dropped, so say it again while the machine still reports a hold (not a program
        // pause: that one waits for the operator).
        if (!hold_sent && resume_polled && last_status_.state == "Hold" && !paused_at) {
          write_byte('~');
          resume_polled = false;
        }
        if (!in_flight.empty() && idle_and_empty && clock_.now() - last_ack >= kOutOfStep) {
          emergency_stop();
          throw DeviceError("GRBL is idle but has not acknowledged line " +
                                   std::to_string(p.source_line[in_flight.front()]) + " for " +
                                   seconds_text(kOutOfStep) + " (an ok was lost: the stream is out of step); "
                                   "sent feed hold and reset");
        }
        report(false);
        break;
      }
      default:
        break;
    }
  }
}

void Session::stream(const Program& p, StreamMode mode, Controls& c, const ProgressFn& on_progress) {
  guarded_run(p, mode, c, on_progress, false);
}

void Session::guarded_run(const Program& p, StreamMode mode, Controls& c, const ProgressFn& on_progress,
                          bool check_mode) {
  try {
    run_lines(p, mode, c, on_progress, check_mode);
  } catch (const LinkLost&) {
    throw;
  } catch (const Canceled&) {
    throw;
  } catch (const GrblError&) {
    throw;  // stopped already
  } catch (const GrblAlarm&) {
    throw;  // GRBL stopped itself; reset already sent
  } catch (const Silent&) {
    throw;  // hold and reset already sent
  } catch (...) {
    // Anything else (a progress callback that threw, a protocol surprise) must not leave
    // GRBL running the lines already queued.
    emergency_stop();
    throw;
  }
}

void Session::check(const Program& p, StreamMode mode, Controls& c, const ProgressFn& on_progress) {
  command("$C");  // "[MSG:Enabled]", ok; error:8 unless Idle
  guarded_run(p, mode, c, on_progress, true);
  // Leaving check mode makes GRBL reset itself: "[MSG:Disabled]", ok, then the banner.
  // Anything sent before the banner would be lost with the cleared receive buffer.
  write_line("$C");
  const auto deadline = clock_.now() + t_.stop;
  for (bool ok = false, banner = false; !(ok && banner);) {
    auto r = next(deadline);
    if (!r)
      throw Silent(std::string("GRBL did not ") + (ok ? "restart" : "answer '$C'") + " within " +
                   seconds_text(t_.stop) + " when leaving check mode");
    if (r->kind == Reply::ok) ok = true;
    else if (r->kind == Reply::banner) banner = true;
    else if (r->kind == Reply::error) throw GrblError(r->code, 0, "$C");
  }
}

void Session::frame(const Bounds& b, double feed_mm_min, Controls& c) {
  stream(frame_program(b, feed_mm_min), StreamMode::character_counting, c, {});
}

}  // namespace atelier::grbl

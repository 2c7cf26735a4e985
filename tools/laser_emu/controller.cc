#include "tools/laser_emu/controller.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace atelier::laser_emu {
namespace {

enum : int {
  kOk = 0, kBadNumberFormat = 2, kInvalidStatement = 3, kSettingDisabled = 5, kIdleError = 8,
  kSystemGcLock = 9, kOverflow = 11, kTravelExceeded = 15, kInvalidJogCommand = 16,
  kUndefinedFeedRate = 22, kUnusedWords = 36,
};
constexpr uint8_t kCmdJogCancel = 0x85;
constexpr int kAlarmHardLimit = 1, kAlarmSoftLimit = 2, kAlarmAbortCycle = 3, kAlarmHomingReset = 6;
constexpr int kPending = -1;  // system_command(): the line stays under way ($H)
constexpr int kHomingLocateCycles = 1;     // N_HOMING_LOCATE_CYCLE (config.h)
constexpr int kWcoRefreshBusy = 30, kWcoRefreshIdle = 10, kOvrRefreshBusy = 20, kOvrRefreshIdle = 10;
constexpr double kMmPerInch = 25.4;

std::string axis_values(const Vec3& v, bool inches) {
  char buf[96];
  if (inches)
    std::snprintf(buf, sizeof buf, "%.4f,%.4f,%.4f", v[0] / kMmPerInch, v[1] / kMmPerInch, v[2] / kMmPerInch);
  else
    std::snprintf(buf, sizeof buf, "%.3f,%.3f,%.3f", v[0], v[1], v[2]);
  return buf;
}

}  // namespace

Controller::Controller(ControllerOptions options, Record& record, int64_t now_us)
    : opt_(options),
      record_(record),
      settings_(options.work_w_mm, options.work_h_mm),
      motion_(settings_, options.time_scale, record, options.epoch_at_zero_s),
      now_(now_us * 1000),
      byte_ns_(1e9 * 10.0 / options.baud),
      lines_received_(options.lines_before),
      last_acked_line_(options.lines_before) {
  record_.work_w_mm = options.work_w_mm;
  record_.work_h_mm = options.work_h_mm;
  for (const auto& [id, value] : opt_.settings) {
    if (const int status = settings_.store(id, value); status != kOk)
      throw std::invalid_argument("setting $" + std::to_string(id) + "=" + std::to_string(value) +
                                  ": GRBL refuses it (error:" + std::to_string(status) +
                                  (status == 10 ? ", soft limits $20=1 need homing $22=1 stored first)" : ")"));
  }
  for (int i = 0; i < 2; ++i) {
    GcState scratch;
    if (execute_gcode_line(opt_.startup_lines[i], scratch, settings_).status != kOk)
      throw std::invalid_argument("startup line $N" + std::to_string(i) + "=" + opt_.startup_lines[i] +
                                  ": GRBL refuses it");
    startup_lines_[i] = opt_.startup_lines[i];
  }
  // HOMING_INIT_LOCK (config.h default): with homing on, power-up is locked in Alarm.
  if (settings_.homing()) state_ = MachineState::alarm;
  motion_.advance(now_);
  tx_head_ns_ = static_cast<double>(now_);
  reinitialise(!options.banner_waits_for_host);
  banner_owed_ = options.banner_waits_for_host;
}

// ---------------------------------------------------------------- serial side

void Controller::host_write(std::string_view bytes, int64_t now_us) {
  const double now = static_cast<double>(std::max(now_, now_us * 1000));
  for (const char c : bytes) {
    last_arrival_ns_ = std::max(now, last_arrival_ns_ + byte_ns_);
    incoming_.emplace_back(static_cast<int64_t>(std::ceil(last_arrival_ns_)), static_cast<uint8_t>(c));
  }
}

void Controller::receive_byte(uint8_t c) {
  if (halted_) return;
  // Inside report_alarm_message()'s delay the ISR still runs, but what it flags is lost: a
  // reset is already pending (mc_reset()) and the critical loop clears it, sys_rt_exec_state
  // is wiped at re-initialisation. Line bytes are buffered, then flushed by the reset.
  if (alarm_report_until_ && (c == '?' || c == '!' || c == '~' || c == 0x18 || c >= 0x80)) return;
  switch (c) {
    case '?':
      if (!critical_) emit(status_report());
      return;
    case '!': feed_hold(); return;
    case '~': cycle_start(); return;
    case 0x18: soft_reset(); return;
    case kCmdJogCancel: jog_cancel(); return;
    default: break;
  }
  if (c >= 0x80) return;  // extended real-time commands: not emulated, never buffered
  if (static_cast<int>(rx_.size()) >= kRxBufferSize - 1) {
    if (!critical_) {
      ++record_.rx_overflows;
      const long line = isr_lines_ + 1;
      if (line != last_overflow_line_) record_.add_event(epoch(now_), "overflow", std::nullopt, line);
      else ++record_.version;
      last_overflow_line_ = line;
    }
  } else {
    rx_.push_back(c);
    if (static_cast<int>(rx_.size()) > record_.max_rx_bytes) {
      record_.max_rx_bytes = static_cast<int>(rx_.size());
      ++record_.version;
    }
  }
  if (c == '\n' || c == '\r') ++isr_lines_;
}

void Controller::emit(std::string_view text) {
  if (tx_.empty()) tx_head_ns_ = std::max(static_cast<double>(now_), last_tx_ns_) + byte_ns_;
  tx_.append(text);
}

size_t Controller::tx_backlog() const {
  if (tx_.empty()) return 0;
  const double sent = std::floor((static_cast<double>(now_) - tx_head_ns_) / byte_ns_) + 1;
  return tx_.size() - static_cast<size_t>(std::clamp(sent, 0.0, static_cast<double>(tx_.size())));
}

std::string Controller::take_output() {
  const size_t n = tx_.size() - tx_backlog();
  std::string out = tx_.substr(0, n);
  tx_.erase(0, n);
  if (n > 0) {
    last_tx_ns_ = tx_head_ns_ + static_cast<double>(n - 1) * byte_ns_;
    tx_head_ns_ += static_cast<double>(n) * byte_ns_;
  }
  return out;
}

std::optional<int64_t> Controller::next_event_us() const {
  int64_t next = std::numeric_limits<int64_t>::max();
  if (!incoming_.empty()) next = std::min(next, incoming_.front().first);
  if (auto m = motion_.next_event()) next = std::min(next, *m);
  if (dwell_until_) next = std::min(next, *dwell_until_);
  if (alarm_report_until_) next = std::min(next, *alarm_report_until_);
  if (homing_until_) next = std::min(next, *homing_until_);
  if (!tx_.empty()) next = std::min(next, static_cast<int64_t>(std::ceil(tx_head_ns_)));
  if (next == std::numeric_limits<int64_t>::max()) return std::nullopt;
  return (std::max(next, now_) + 999) / 1000;
}

// ---------------------------------------------------------------- clock

void Controller::advance_motion(int64_t t) {
  const bool was_running = motion_.running(), was_decel = motion_.decelerating();
  motion_.advance(t);
  now_ = std::max(now_, t);
  if (!was_running || motion_.running()) return;
  if (was_decel) {  // feed hold complete
    if (jog_cancel_) {
      // protocol_exec_rt_system(), SUSPEND_JOG_CANCEL: flush the planner, sync the positions.
      jog_cancel_ = false;
      motion_.stop(now_);
      gc_.position = motion_.position();
      state_ = MachineState::idle;
    } else if (soft_limit_stop_) {
      soft_limit_stop_ = false;
      state_ = MachineState::idle;
      raise_alarm(kAlarmSoftLimit);
    } else {
      hold_complete_ = true;
      motion_.set_hold_beam_off(now_, true);  // DISABLE_LASER_DURING_HOLD
    }
  } else if (state_ == MachineState::run || state_ == MachineState::jog) {
    state_ = MachineState::idle;  // cycle stop: the planner ran dry
  }
}

void Controller::advance_to(int64_t now_us) {
  const int64_t target = now_us * 1000;
  for (;;) {
    int64_t next = std::numeric_limits<int64_t>::max();
    if (!incoming_.empty()) next = std::min(next, incoming_.front().first);
    if (auto m = motion_.next_event()) next = std::min(next, *m);
    // Wake-ups for the main loop count only while in the future: once due, run_main() below
    // has seen them (it may still be blocked for another reason, e.g. a feed hold).
    if (dwell_until_ && *dwell_until_ > now_) next = std::min(next, *dwell_until_);
    if (homing_until_ && *homing_until_ > now_) next = std::min(next, *homing_until_);
    if (alarm_report_until_) next = std::min(next, std::max(*alarm_report_until_, now_));
    if (tx_blocked_ && tx_.size() > static_cast<size_t>(kTxBufferSize)) {
      const auto unblock = static_cast<int64_t>(
          std::ceil(tx_head_ns_ + static_cast<double>(tx_.size() - kTxBufferSize - 1) * byte_ns_));
      if (unblock > now_) next = std::min(next, unblock);
    }
    if (next > target) break;
    advance_motion(std::max(next, now_));
    if (alarm_report_until_ && now_ >= *alarm_report_until_) end_alarm_report();
    while (!incoming_.empty() && incoming_.front().first <= now_) {
      const uint8_t c = incoming_.front().second;
      incoming_.pop_front();
      receive_byte(c);
    }
    run_main();
  }
  advance_motion(std::max(target, now_));
  if (alarm_report_until_ && now_ >= *alarm_report_until_) end_alarm_report();
  run_main();
}

// ---------------------------------------------------------------- main loop

void Controller::run_main() {
  for (;;) {
    if (halted_ || critical_ || state_ == MachineState::hold || state_ == MachineState::sleep || soft_limit_stop_)
      return;
    tx_blocked_ = tx_backlog() > static_cast<size_t>(kTxBufferSize);
    if (tx_blocked_) return;
    if (line_active_) {
      if (homing_until_) {
        if (now_ < *homing_until_) return;
        finish_homing();
      }
      if (!run_actions()) return;
      line_active_ = false;
      jog_line_ = false;
      respond(kOk);
      continue;
    }
    if (rx_.empty()) {
      auto_cycle_start();
      return;
    }
    const uint8_t c = rx_.front();
    rx_.pop_front();
    take_char(c);
  }
}

void Controller::take_char(uint8_t c) {
  if (c == '\n' || c == '\r') {
    process_line();
    line_.clear();
    comment_paren_ = comment_semi_ = line_overflow_ = false;
    return;
  }
  if (comment_paren_ || comment_semi_ || line_overflow_) {
    if (c == ')' && comment_paren_) comment_paren_ = false;
    return;
  }
  if (c <= ' ' || c == '/') return;  // whitespace, control characters; block delete unsupported
  if (c == '(') {
    comment_paren_ = true;
  } else if (c == ';') {
    comment_semi_ = true;
  } else if (static_cast<int>(line_.size()) >= kLineBufferSize - 1) {
    line_overflow_ = true;
  } else if (c >= 'a' && c <= 'z') {
    line_.push_back(static_cast<char>(c - 'a' + 'A'));
  } else {
    line_.push_back(static_cast<char>(c));
  }
}

void Controller::process_line() {
  ++lines_received_;
  ++record_.lines_received;
  ++record_.version;
  if (opt_.alarm_at_line && lines_received_ == *opt_.alarm_at_line) {
    ok_owed_ = true;  // struck while the line executes: its "ok" follows the reset
    raise_alarm(opt_.alarm_code);
    return;
  }
  if (line_overflow_) return respond(kOverflow);
  if (line_.empty()) return respond(kOk);
  if (line_[0] == '$') {
    const int status = system_command(line_);
    if (status == kPending) {  // actions_ set by the command
      line_active_ = true;
      return;
    }
    return respond(status);
  }
  if (state_ == MachineState::alarm || state_ == MachineState::jog) return respond(kSystemGcLock);
  LineResult r = execute_gcode_line(line_, gc_, settings_);
  if (r.status != kOk) return respond(r.status);
  actions_.assign(r.actions.begin(), r.actions.end());
  action_checked_ = false;
  line_active_ = true;
}

void Controller::respond(int status) {
  ++lines_acked_;
  last_acked_line_ = lines_received_;  // lines run one at a time: the answer is for the last one taken
  if (status == kOk) {
    emit("ok\r\n");
  } else {
    emit("error:" + std::to_string(status) + "\r\n");
    ++record_.errors;
    record_.add_event(epoch(now_), "error", status, lines_received_);
  }
  if (opt_.halt_after_line && last_acked_line_ >= *opt_.halt_after_line) halted_ = true;
  if (reset_after_response_) {
    reset_after_response_ = false;
    soft_reset();
  }
  if (sleep_after_response_) {
    // protocol_exec_rt_suspend(), STATE_SLEEP: spindle, coolant and steppers off, then only
    // real-time commands run until a reset.
    sleep_after_response_ = false;
    motion_.stop(now_);
    state_ = MachineState::sleep;
    emit("[MSG:Sleeping]\r\n");
  }
}

void Controller::auto_cycle_start() {
  if (state_ == MachineState::idle && motion_.blocks() > 0 && !motion_.running()) {
    motion_.start(now_);
    state_ = MachineState::run;
  }
}

bool Controller::wait_sync() {
  if (state_ == MachineState::check) return true;
  if (motion_.blocks() == 0 && !motion_.running()) return true;
  auto_cycle_start();
  return false;
}

bool Controller::run_actions() {
  const bool check = state_ == MachineState::check;
  while (!actions_.empty()) {
    Action& a = actions_.front();
    switch (a.kind) {
      case Action::Kind::line: {
        if (!action_checked_) {
          action_checked_ = true;
          if (settings_.soft_limits() && outside_limits(a.target)) {
            // limits_soft_check(): a controlled stop if moving, then the critical alarm. The
            // line is never answered.
            actions_.clear();
            line_active_ = false;
            ok_owed_ = true;  // mc_line() returns after the reset and the line gets its "ok"
            if (motion_.running()) {
              soft_limit_stop_ = true;
              state_ = MachineState::hold;
              motion_.hold(now_);
            } else {
              raise_alarm(kAlarmSoftLimit);
            }
            return false;
          }
        }
        if (check) break;
        if (motion_.full()) {
          auto_cycle_start();
          return false;
        }
        if (!motion_.push(a.target, a.feed, a.rapid, a.inverse_time, a.spindle, a.s) &&
            settings_.laser_mode() && a.spindle == Spindle::cw) {
          // An empty block in M3 still syncs the laser to the block's power (mc_line()).
          a.kind = Action::Kind::spindle;
          action_checked_ = false;
          continue;
        }
        if (jog_line_) {  // jog_execute(): a manual start, state Jog
          if (state_ == MachineState::idle) state_ = MachineState::jog;
          if (!motion_.running()) motion_.start(now_);
        } else {
          auto_cycle_start();
        }
        break;
      }
      case Action::Kind::sync:
        if (!wait_sync()) return false;
        break;
      case Action::Kind::spindle:
        if (check) break;
        if (!wait_sync()) return false;
        motion_.set_spindle(now_, a.spindle, a.s);
        break;
      case Action::Kind::dwell:
        if (check) break;
        if (!wait_sync()) return false;
        if (!dwell_until_) {
          // At most 1e18 ns (31 years): a huge P ("G4 P99999999999") would overflow int64.
          const double ns = std::min(a.seconds * opt_.time_scale * 1e9, 1e18);
          dwell_until_ = now_ + static_cast<int64_t>(ns);
        }
        if (now_ < *dwell_until_) return false;
        dwell_until_.reset();
        break;
      case Action::Kind::wco_change:
        if (!wait_sync()) return false;
        wco_counter_ = 0;
        break;
      case Action::Kind::program_end:
        if (!wait_sync()) return false;
        if (!check) motion_.set_spindle(now_, Spindle::off, 0);
        emit("[MSG:Pgm End]\r\n");
        break;
      case Action::Kind::pause:
        if (check) break;
        if (!wait_sync()) return false;
        actions_.pop_front();
        action_checked_ = false;
        feed_hold();
        return false;  // the "ok" follows the resume
    }
    actions_.pop_front();
    action_checked_ = false;
  }
  return true;
}

bool Controller::outside_limits(const Vec3& t) const {
  // system_check_travel_limits(): stock 1.1h keeps every axis in -max travel..0; built with
  // HOMING_FORCE_SET_ORIGIN an axis homing towards negative ($23 bit set) lives in 0..max travel.
  const int dir_mask = static_cast<int>(settings_.get(23));
  for (int i = 0; i < 3; ++i) {
    const double travel = settings_.max_travel(i);
    if (opt_.force_set_origin && (dir_mask & (1 << i))) {
      if (t[i] < 0 || t[i] > travel) return true;
    } else if (t[i] > 0 || t[i] < -travel) {
      return true;
    }
  }
  return false;
}

// ---------------------------------------------------------------- $ commands

int Controller::system_command(const std::string& line) {
  const bool idle_or_alarm = state_ == MachineState::idle || state_ == MachineState::alarm;
  if (line.size() == 1) {
    emit("[HLP:$$ $# $G $I $N $x=val $Nx=line $J=line $SLP $C $X $H ~ ! ? ctrl-x]\r\n");
    return kOk;
  }
  const char c1 = line[1];
  if (c1 == 'J') {
    if (state_ != MachineState::idle && state_ != MachineState::jog) return kIdleError;
    if (line.size() < 3 || line[2] != '=') return kInvalidStatement;
    return jog_command(line);
  }
  if (c1 == '$' || c1 == 'G' || c1 == 'C' || c1 == 'X') {
    if (line.size() != 2) return kInvalidStatement;
    switch (c1) {
      case '$':
        if (state_ == MachineState::run || state_ == MachineState::hold) return kIdleError;
        emit(settings_.listing());
        return kOk;
      case 'G': emit(gc_.modes_report() + "\r\n"); return kOk;
      case 'C':
        if (state_ == MachineState::check) {
          emit("[MSG:Disabled]\r\n");
          reset_after_response_ = true;  // mc_reset(): the banner follows the ok
        } else {
          if (state_ != MachineState::idle) return kIdleError;
          state_ = MachineState::check;
          emit("[MSG:Enabled]\r\n");
        }
        return kOk;
      case 'X':
        if (state_ == MachineState::alarm) {
          emit("[MSG:Caution: Unlocked]\r\n");
          state_ = MachineState::idle;
        }
        return kOk;
    }
  }
  if (!idle_or_alarm) return kIdleError;
  switch (c1) {
    case '#':
      if (line.size() != 2) return kInvalidStatement;
    {
      // report_ngc_parameters(), in the units $13 reports.
      const bool inches = settings_.get(13) != 0;
      for (int i = 0; i < 6; ++i)
        emit("[G" + std::to_string(54 + i) + ":" + axis_values(gc_.coord_data[i], inches) + "]\r\n");
      emit("[G28:" + axis_values(gc_.coord_data[6], inches) + "]\r\n[G30:" + axis_values(gc_.coord_data[7], inches) +
           "]\r\n");
      char tlo[32];
      std::snprintf(tlo, sizeof tlo, inches ? "%.4f" : "%.3f", inches ? gc_.tlo / kMmPerInch : gc_.tlo);
      emit("[G92:" + axis_values(gc_.g92, inches) + "]\r\n[TLO:" + tlo + "]\r\n[PRB:" +
           axis_values(Vec3{}, inches) + ":0]\r\n");
      return kOk;
    }
    case 'H': {
      if (!settings_.homing()) return kSettingDisabled;
      if (line.size() != 2) return kInvalidStatement;  // HOMING_SINGLE_AXIS_COMMANDS is off in 1.1h
      // mc_homing_cycle(): HOMING_CYCLE_0 (Z), then HOMING_CYCLE_1 (X and Y together). Each
      // cycle seeks the switch at $25, pulls off $27 at $25, locates it again at $24 and pulls
      // off $27 (one locate cycle), with the $26 debounce delay after each of the four moves.
      // Axes in a cycle move at once, each at the homing rate (GRBL scales the vector rate by
      // sqrt(axes)). Before the first homing the switch is taken to be half the travel away.
      motion_.stop(now_);
      const double seek = settings_.get(25), feed = settings_.get(24), pulloff = settings_.get(27);
      const double debounce_s = settings_.get(26) / 1000.0;
      const int dir_mask = static_cast<int>(settings_.get(23));
      const Vec3 from = motion_.position();
      double seconds = 0;
      for (const std::vector<int>& cycle : {std::vector<int>{2}, std::vector<int>{0, 1}}) {
        double search = 0;
        for (const int i : cycle) {
          const double travel = settings_.max_travel(i);
          const bool negative = dir_mask & (1 << i);
          // Machine position of the home position once homed, and of the switch.
          double home = negative ? -travel + pulloff : -pulloff;
          if (opt_.force_set_origin) home = 0;
          homed_position_[i] = home;
          const double switch_at = negative ? home - pulloff : home + pulloff;
          search = std::max(search, homed_once_ ? std::abs(switch_at - from[i]) : travel / 2);
        }
        seconds += 60.0 * (search / seek + 2 * pulloff / seek + pulloff / feed) +
                   (2 * kHomingLocateCycles + 2) * debounce_s;
      }
      state_ = MachineState::home;
      actions_.clear();
      homing_until_ = now_ + static_cast<int64_t>(seconds * opt_.time_scale * 1e9);
      return kPending;
    }
    case 'S':
      if (line != "$SLP") return kInvalidStatement;
      sleep_after_response_ = true;  // EXEC_SLEEP: acted on once the "ok" is out
      return kOk;
    case 'I':
      if (line.size() == 2) {
        emit("[VER:1.1h.20190830:" + build_info_ + "]\r\n[OPT:V" + (opt_.force_set_origin ? "Z" : "") +
             ",15,128]\r\n");
      } else {
        if (line[2] != '=') return kInvalidStatement;
        build_info_ = line.substr(3);  // ENABLE_BUILD_INFO_WRITE_COMMAND
      }
      return kOk;
    case 'R':
      if (line.size() != 6 || line.compare(0, 5, "$RST=") != 0) return kInvalidStatement;
      // settings_restore(): '$' the compiled defaults, '#' the coordinate offsets in EEPROM
      // (G54..G59, G28, G30: all zero in this emulator), '*' both plus the startup lines and
      // the build info. Then mc_reset().
      if (line[5] != '$' && line[5] != '#' && line[5] != '*') return kInvalidStatement;
      if (line[5] != '#') settings_.restore_defaults();
      if (line[5] != '$') gc_.coord_data = {};
      if (line[5] == '*') {
        startup_lines_[0].clear();
        startup_lines_[1].clear();
        build_info_.clear();
      }
      emit("[MSG:Restoring defaults]\r\n");
      reset_after_response_ = true;
      return kOk;
    case 'N':
      if (line.size() == 2) {
        emit("$N0=" + startup_lines_[0] + "\r\n$N1=" + startup_lines_[1] + "\r\n");
        return kOk;
      }
      if (state_ != MachineState::idle) return kIdleError;  // stored only when idle
      {
        size_t pos = 2;
        double index = 0;
        if (!read_grbl_float(line, pos, index)) return kBadNumberFormat;
        if (pos >= line.size() || line[pos++] != '=') return kInvalidStatement;
        // GRBL stores any index (past the two lines' EEPROM slots); only 0 and 1 are kept here.
        const int n = static_cast<int>(std::trunc(index));
        if (index < 0 || n > 1) return kInvalidStatement;
        return store_startup_line(n, line.substr(pos));
      }
    default: break;
  }
  size_t pos = 1;
  double param = 0, value = 0;
  if (!read_grbl_float(line, pos, param)) return kBadNumberFormat;
  if (pos >= line.size() || line[pos++] != '=') return kInvalidStatement;
  if (!read_grbl_float(line, pos, value)) return kBadNumberFormat;
  if (pos != line.size() || param > 255) return kInvalidStatement;
  return settings_.store(param, value);
}

// ---------------------------------------------------------------- real-time and states

void Controller::feed_hold() {
  if (critical_ || state_ == MachineState::alarm || state_ == MachineState::check ||
      state_ == MachineState::home || state_ == MachineState::sleep)
    return;
  if (state_ == MachineState::jog) return jog_cancel();  // a hold cancels a jog
  if (state_ == MachineState::run) {
    record_.add_event(epoch(now_), "hold");
    state_ = MachineState::hold;
    hold_complete_ = false;
    motion_.hold(now_);
  } else if (state_ == MachineState::idle) {
    record_.add_event(epoch(now_), "hold");
    state_ = MachineState::hold;
    hold_complete_ = true;
    motion_.set_hold_beam_off(now_, true);
  }
}

void Controller::cycle_start() {
  if (critical_) return;
  if (state_ == MachineState::hold && hold_complete_ && !soft_limit_stop_) {
    record_.add_event(epoch(now_), "resume");
    hold_complete_ = false;
    motion_.set_hold_beam_off(now_, false);
    state_ = MachineState::idle;
    auto_cycle_start();
  } else if (state_ == MachineState::idle) {
    auto_cycle_start();
  }
}

void Controller::raise_alarm(int code) {
  motion_.stop(now_);  // mc_reset(): steppers killed, laser off
  record_.add_event(epoch(now_), "alarm", code);
  state_ = MachineState::alarm;
  if (line_active_) ok_owed_ = true;
  actions_.clear();
  line_active_ = false;
  dwell_until_.reset();
  homing_until_.reset();
  soft_limit_stop_ = false;
  emit("ALARM:" + std::to_string(code) + "\r\n");
  // report_alarm_message() then busy-waits 500 ms: nothing runs, real-time bytes are lost.
  critical_ = true;
  alarm_critical_ = code == kAlarmHardLimit || code == kAlarmSoftLimit;
  alarm_report_until_ = now_ + kAlarmReportDelayUs * 1000;
}

void Controller::end_alarm_report() {
  alarm_report_until_.reset();
  if (alarm_critical_) {
    // protocol_exec_rt_system(): the critical-event loop clears any pending reset (so a 0x18
    // sent during the delay is lost) and waits for a new one; "?" is not answered meanwhile.
    emit("[MSG:Reset to continue]\r\n");
    return;
  }
  critical_ = false;
  abort_to_reset();  // the reset mc_reset() asked for
}

void Controller::abort_to_reset() {
  motion_.stop(now_);
  // The line under way returns through sys.abort and protocol.c answers it before main()
  // re-initialises.
  if (ok_owed_ || line_active_) {
    ok_owed_ = false;
    line_active_ = false;
    respond(kOk);
  }
  reinitialise();
}

void Controller::soft_reset() {
  if (alarm_report_until_) return;  // see receive_byte()
  record_.add_event(epoch(now_), "reset");
  if (critical_) {
    critical_ = false;
    alarm_critical_ = false;
    abort_to_reset();
    return;
  }
  if (state_ == MachineState::home) {
    raise_alarm(kAlarmHomingReset);  // mc_reset() during homing: homing fail, position lost
    return;
  }
  if (motion_.running()) {  // Run or Hold:1: position lost
    raise_alarm(kAlarmAbortCycle);
    return;
  }
  abort_to_reset();
}

int Controller::jog_command(const std::string& line) {
  // gcode.c with GC_PARSER_JOG_MOTION: G1 and G94 enforced, F required (error:22), S and T
  // unused words (error:36), only G20/G21, G90/G91 and G53 besides axis words, F and N
  // (error:16). The parser's modes are left as they were; only its position follows the jog.
  const std::string words = line.substr(3);
  bool has_f = false, has_s_or_t = false, other_command = false;
  for (size_t pos = 0; pos < words.size();) {
    const char letter = words[pos++];
    double value = 0;
    if (!read_grbl_float(words, pos, value)) break;  // the parser below reports it
    if (letter == 'F') has_f = true;
    if (letter == 'S' || letter == 'T') has_s_or_t = true;
    if (letter == 'M' || (letter == 'G' && value != 20 && value != 21 && value != 90 && value != 91 && value != 53))
      other_command = true;
  }
  // These come before the parser's other checks here (GRBL checks repeated words, negative
  // values and modal conflicts among the line's own words first).
  if (!has_f) return kUndefinedFeedRate;
  if (has_s_or_t) return kUnusedWords;
  if (other_command) return kInvalidJogCommand;
  GcState scratch = gc_;
  LineResult r = execute_gcode_line("G1G94" + words, scratch, settings_);
  if (r.status != kOk) return r.status;
  actions_.clear();
  for (const Action& a : r.actions) {
    if (a.kind != Action::Kind::line) continue;
    // jog_execute(): a target beyond the soft limits is refused, no alarm.
    if (settings_.soft_limits() && outside_limits(a.target)) return kTravelExceeded;
    actions_.push_back(a);
    gc_.position = a.target;
  }
  action_checked_ = true;  // checked above
  jog_line_ = true;
  return kPending;
}

void Controller::jog_cancel() {
  // serial.c: 0x85 acts only while jogging; the jog decelerates, then the planner is flushed.
  if (state_ != MachineState::jog || jog_cancel_) return;
  if (motion_.running()) {
    jog_cancel_ = true;
    motion_.hold(now_);
  } else {
    motion_.stop(now_);
    gc_.position = motion_.position();
    state_ = MachineState::idle;
  }
}

void Controller::finish_homing() {
  homing_until_.reset();
  motion_.set_position(homed_position_);
  homed_once_ = true;
  state_ = MachineState::idle;
  gc_.position = homed_position_;
  run_startup_lines();  // after a successful $H, before its "ok"
}

int Controller::store_startup_line(int index, const std::string& line) {
  // system.c executes the line to check it; only a line that runs is stored.
  LineResult r = execute_gcode_line(line, gc_, settings_);
  if (r.status != kOk) return r.status;
  for (const Action& a : r.actions) {
    if (a.kind == Action::Kind::line && !motion_.full())
      motion_.push(a.target, a.feed, a.rapid, a.inverse_time, a.spindle, a.s);
    else if (a.kind == Action::Kind::spindle)
      motion_.set_spindle(now_, a.spindle, a.s);
  }
  auto_cycle_start();
  startup_lines_[index] = line;
  return kOk;
}

void Controller::run_startup_lines() {
  // system_execute_startup(): each stored line, answered ">LINE:ok" or ">LINE:error:N".
  for (const std::string& line : startup_lines_) {
    if (line.empty()) continue;
    LineResult r = execute_gcode_line(line, gc_, settings_);
    if (r.status == kOk) {
      for (const Action& a : r.actions) {
        if (a.kind == Action::Kind::line && !motion_.full())
          motion_.push(a.target, a.feed, a.rapid, a.inverse_time, a.spindle, a.s);
        else if (a.kind == Action::Kind::spindle)
          motion_.set_spindle(now_, a.spindle, a.s);
      }
      auto_cycle_start();
    }
    emit(">" + line + ":" + (r.status == kOk ? std::string("ok") : "error:" + std::to_string(r.status)) + "\r\n");
  }
}

void Controller::reinitialise(bool announce) {
  rx_.clear();
  line_.clear();
  comment_paren_ = comment_semi_ = line_overflow_ = false;
  actions_.clear();
  line_active_ = false;
  action_checked_ = false;
  dwell_until_.reset();
  homing_until_.reset();
  alarm_report_until_.reset();
  critical_ = alarm_critical_ = ok_owed_ = false;
  reset_after_response_ = false;
  hold_complete_ = false;
  soft_limit_stop_ = false;
  jog_line_ = jog_cancel_ = false;
  wco_counter_ = ovr_counter_ = 0;
  const auto eeprom = gc_.coord_data;  // gc_init(): offsets come back from EEPROM
  gc_ = GcState{};
  gc_.coord_data = eeprom;
  gc_.position = motion_.position();
  // protocol_main_loop(): a reset out of Sleep is locked like one out of an alarm.
  if (state_ == MachineState::sleep) state_ = MachineState::alarm;
  if (state_ != MachineState::alarm) state_ = MachineState::idle;
  sleep_after_response_ = false;
  if (!announce) return;
  emit(kBanner);
  // protocol_main_loop(): locked, or the startup lines.
  if (state_ == MachineState::alarm) emit("[MSG:'$H'|'$X' to unlock]\r\n");
  else run_startup_lines();
}

std::string Controller::state_name() const {
  switch (state_) {
    case MachineState::idle: return "Idle";
    case MachineState::run: return "Run";
    case MachineState::hold: return hold_complete_ ? "Hold:0" : "Hold:1";
    case MachineState::alarm: return "Alarm";
    case MachineState::check: return "Check";
    case MachineState::home: return "Home";
    case MachineState::jog: return "Jog";
    case MachineState::sleep: return "Sleep";
  }
  return "Idle";
}

std::string Controller::status_report() {
  const int mask = settings_.status_mask();
  const bool inches = settings_.get(13) != 0;
  const bool busy = state_ == MachineState::run || state_ == MachineState::hold || state_ == MachineState::jog ||
                    state_ == MachineState::home;
  Vec3 pos = motion_.position();
  const Vec3 wco = gc_.wco();
  std::string r = "<" + state_name();
  if (mask & 1) {
    r += "|MPos:";
  } else {
    for (int i = 0; i < 3; ++i) pos[i] -= wco[i];
    r += "|WPos:";
  }
  r += axis_values(pos, inches);
  if (mask & 2)
    r += "|Bf:" + std::to_string(Motion::kPlannerBlocks - motion_.blocks()) + "," +
         std::to_string(kRxBufferSize - 1 - static_cast<int>(rx_.size()));
  char fs[64];
  const double feed = motion_.speed_mm_min();
  std::snprintf(fs, sizeof fs, "|FS:%.*f,%.0f", inches ? 1 : 0, inches ? feed / kMmPerInch : feed, motion_.laser_s());
  r += fs;
  if (wco_counter_ > 0) {
    --wco_counter_;
  } else {
    wco_counter_ = (busy ? kWcoRefreshBusy : kWcoRefreshIdle) - 1;
    if (ovr_counter_ == 0) ovr_counter_ = 1;  // overrides in the next report
    r += "|WCO:" + axis_values(wco, inches);
  }
  if (ovr_counter_ > 0) {
    --ovr_counter_;
  } else {
    ovr_counter_ = (busy ? kOvrRefreshBusy : kOvrRefreshIdle) - 1;
    r += "|Ov:100,100,100";
    const Spindle on = motion_.laser_spindle();
    if (on == Spindle::cw) r += "|A:S";
    else if (on == Spindle::ccw) r += "|A:C";
  }
  return r + ">\r\n";
}

// ---------------------------------------------------------------- record

Record Controller::snapshot() const {
  Record r = record_;
  if (auto s = motion_.open_segment(now_)) r.segments.push_back(*s);
  return r;
}

void Controller::hangup(int64_t now_us) {
  advance_motion(std::max(now_, now_us * 1000));
  record_.add_event(epoch(now_), "hangup");
  motion_.stop(now_);  // the MCU restarts: steppers and PWM off at once
  motion_.set_position(Vec3{});
  incoming_.clear();
  last_arrival_ns_ = static_cast<double>(now_);
  tx_.clear();
  tx_blocked_ = false;
  isr_lines_ = 0;
  homed_once_ = false;
  state_ = settings_.homing() ? MachineState::alarm : MachineState::idle;
  reinitialise(false);
  banner_owed_ = true;
}

void Controller::host_connected(int64_t now_us) {
  advance_to(now_us);
  if (!banner_owed_) return;
  banner_owed_ = false;
  emit(kBanner);
  if (state_ == MachineState::alarm) emit("[MSG:'$H'|'$X' to unlock]\r\n");
  else run_startup_lines();
}

void Controller::power_off() {
  motion_.stop(now_);
  state_ = MachineState::idle;
}

}  // namespace atelier::laser_emu

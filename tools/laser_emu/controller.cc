#include "tools/laser_emu/controller.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <utility>

namespace atelier::laser_emu {
namespace {

enum : int {
  kOk = 0, kBadNumberFormat = 2, kInvalidStatement = 3, kSettingDisabled = 5, kIdleError = 8,
  kSystemGcLock = 9, kOverflow = 11, kTravelExceeded = 15,
};
constexpr uint8_t kCmdSafetyDoor = 0x84, kCmdJogCancel = 0x85;
// Override flags (system.h EXEC_*_OVR_*), in the order protocol_exec_rt_system() applies them.
enum : unsigned {
  kFeedReset = 1, kFeedCoarsePlus = 2, kFeedCoarseMinus = 4, kFeedFinePlus = 8, kFeedFineMinus = 16,
  kRapidReset = 32, kRapidMedium = 64, kRapidLow = 128,
};
enum : unsigned {
  kSpindleReset = 1, kSpindleCoarsePlus = 2, kSpindleCoarseMinus = 4, kSpindleFinePlus = 8,
  kSpindleFineMinus = 16, kSpindleStop = 32, kFloodToggle = 64,
};
// sys.spindle_stop_ovr (system.h SPINDLE_STOP_OVR_*).
enum : unsigned { kStopInitiate = 1, kStopEnabled = 2, kStopRestore = 4, kStopRestoreCycle = 8 };
constexpr double kDoorSpindleDelayS = 4.0, kDoorCoolantDelayS = 1.0;  // SAFETY_DOOR_*_DELAY
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
    case kCmdSafetyDoor: safety_door(); return;
    default: break;
  }
  if (c >= 0x80) {  // the other extended real-time commands only set flags; never buffered
    switch (c) {
      case 0x90: motion_ovr_flags_ |= kFeedReset; break;
      case 0x91: motion_ovr_flags_ |= kFeedCoarsePlus; break;
      case 0x92: motion_ovr_flags_ |= kFeedCoarseMinus; break;
      case 0x93: motion_ovr_flags_ |= kFeedFinePlus; break;
      case 0x94: motion_ovr_flags_ |= kFeedFineMinus; break;
      case 0x95: motion_ovr_flags_ |= kRapidReset; break;
      case 0x96: motion_ovr_flags_ |= kRapidMedium; break;
      case 0x97: motion_ovr_flags_ |= kRapidLow; break;
      case 0x99: accessory_ovr_flags_ |= kSpindleReset; break;
      case 0x9A: accessory_ovr_flags_ |= kSpindleCoarsePlus; break;
      case 0x9B: accessory_ovr_flags_ |= kSpindleCoarseMinus; break;
      case 0x9C: accessory_ovr_flags_ |= kSpindleFinePlus; break;
      case 0x9D: accessory_ovr_flags_ |= kSpindleFineMinus; break;
      case 0x9E: accessory_ovr_flags_ |= kSpindleStop; break;
      case 0xA0: accessory_ovr_flags_ |= kFloodToggle; break;
      default: break;  // 0xA1 (mist, ENABLE_M7) and unassigned bytes are thrown away
    }
    return;
  }
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
    ++rx_pushed_;
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
  if (door_restore_until_) next = std::min(next, *door_restore_until_);
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
      if (door_after_jog_) {  // SUSPEND_SAFETY_DOOR_AJAR: the door opened during the cancel
        door_after_jog_ = false;
        state_ = MachineState::door;
        hold_complete_ = true;
        door_stopped();
      }
    } else if (soft_limit_stop_) {
      soft_limit_stop_ = false;
      state_ = MachineState::idle;
      raise_alarm(kAlarmSoftLimit);
    } else {
      hold_complete_ = true;
      if (state_ == MachineState::door) door_stopped();
      else spindle_stop_step();  // DISABLE_LASER_DURING_HOLD: the beam goes off now
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
    if (door_restore_until_) next = std::min(next, std::max(*door_restore_until_, now_));
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
    if (door_restore_until_ && now_ >= *door_restore_until_) finish_door_restore();
    run_main();
  }
  advance_motion(std::max(target, now_));
  if (alarm_report_until_ && now_ >= *alarm_report_until_) end_alarm_report();
  if (door_restore_until_ && now_ >= *door_restore_until_) finish_door_restore();
  run_main();
}

// ---------------------------------------------------------------- main loop

void Controller::run_main() {
  // protocol_execute_realtime(): overrides flagged by the ISR are applied whenever the main
  // loop polls - not while it is stuck writing to a full TX buffer, homing or in an alarm.
  if ((motion_ovr_flags_ || accessory_ovr_flags_) && !halted_ && !critical_ && state_ != MachineState::home &&
      tx_backlog() <= static_cast<size_t>(kTxBufferSize))
    apply_overrides();
  for (;;) {
    if (halted_ || critical_ || state_ == MachineState::hold || state_ == MachineState::sleep ||
        state_ == MachineState::door || soft_limit_stop_)
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
    set_flood(false);
    ovr_counter_ = 0;
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
        if (!motion_.push(a.target, a.feed, a.rapid, a.inverse_time, a.spindle, a.s, /*no_feed_override=*/jog_line_) &&
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
        if (!check) set_flood(gc_.flood);  // coolant_sync() (M8/M9), or another sync: no change
        break;
      case Action::Kind::spindle:
        if (check) break;
        if (!wait_sync()) return false;
        motion_.set_spindle(now_, a.spindle, a.s);
        ovr_counter_ = 0;  // spindle_set_state(): overrides in the next report
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
        if (!check) {
          motion_.set_spindle(now_, Spindle::off, 0);
          set_flood(false);
          ovr_counter_ = 0;
          wco_counter_ = 0;  // system_flag_wco_change(): WCO in the next report
        }
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
      case 'G': emit(gc_.modes_report(settings_.get(13) != 0) + "\r\n"); return kOk;
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
      // At most 1e18 ns: a zero or tiny rate ($24/$25) would make it infinite.
      const double ns = seconds * opt_.time_scale * 1e9;
      homing_until_ = now_ + static_cast<int64_t>(std::isfinite(ns) ? std::min(ns, 1e18) : 1e18);
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
        // GRBL checks the line and stores it at any index (uint8 of trunc(index)), past the two
        // lines' EEPROM slots too; only $N0 and $N1 are listed and run, so here another index is
        // checked, answered and forgotten.
        const double n = std::trunc(index);
        if (n != 0 && n != 1) {
          GcState scratch = gc_;
          return execute_gcode_line(line.substr(pos), scratch, settings_).status;
        }
        return store_startup_line(static_cast<int>(n), line.substr(pos));
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
      state_ == MachineState::home || state_ == MachineState::sleep || state_ == MachineState::door)
    return;
  if (state_ == MachineState::jog) return jog_cancel();  // a hold cancels a jog
  if (state_ != MachineState::run && state_ != MachineState::idle) return;
  record_.add_event(epoch(now_), "hold");
  const bool moving = state_ == MachineState::run;
  state_ = MachineState::hold;
  hold_complete_ = !moving;
  // protocol_exec_rt_suspend(), DISABLE_LASER_DURING_HOLD: in laser mode a spindle stop is
  // requested as the hold begins; it acts once the head has stopped.
  if (settings_.laser_mode() && spindle_stop_ == 0) spindle_stop_ = kStopInitiate;
  if (moving) motion_.hold(now_);
  else spindle_stop_step();
}

void Controller::spindle_stop_step() {
  // protocol_exec_rt_suspend(), a completed hold outside a door: the spindle stop override.
  if (state_ != MachineState::hold || !hold_complete_) return;
  if (spindle_stop_ & kStopInitiate) {
    if (gc_.spindle != Spindle::off) {
      motion_.set_hold_beam_off(now_, true);  // spindle_set_state(SPINDLE_DISABLE)
      ovr_counter_ = 0;
      spindle_stop_ = kStopEnabled;
    } else {
      spindle_stop_ = 0;
    }
  } else if (spindle_stop_ & (kStopRestore | kStopRestoreCycle)) {
    const bool cycle = spindle_stop_ & kStopRestoreCycle;
    if (gc_.spindle != Spindle::off) {
      emit("[MSG:Restoring spindle]\r\n");
      const bool laser = settings_.laser_mode();
      if (cycle && laser) {
        // STEP_CONTROL_UPDATE_SPINDLE_PWM and the resume: the stepper sets the power with the
        // next block; standing still the beam stays off.
        motion_.set_spindle(now_, gc_.spindle, 0);
      } else {
        // spindle_set_state(restore): the held block's power, or the parser's S without one
        // (a laser's M4 forced to 0).
        if (motion_.blocks() == 0)
          motion_.set_spindle(now_, gc_.spindle, laser && gc_.spindle == Spindle::ccw ? 0.0 : gc_.s);
        ovr_counter_ = 0;
      }
      motion_.set_hold_beam_off(now_, false);
    }
    spindle_stop_ = 0;
    if (cycle) cycle_start();
  }
}

void Controller::cycle_start() {
  if (critical_) return;
  if (state_ == MachineState::door) {
    // The door reads closed: once retracted, "~" restores (Door:3), then resumes.
    if (!door_retracted_ || door_restore_until_) return;
    double delay_s = 0;
    if (gc_.spindle != Spindle::off && !settings_.laser_mode()) {
      motion_.set_hold_beam_off(now_, false);  // spindle_set_state(restore), then its delay
      ovr_counter_ = 0;
      delay_s += kDoorSpindleDelayS;
    }
    if (gc_.flood) {
      set_flood(true);
      delay_s += kDoorCoolantDelayS;
    }
    door_restore_until_ = now_ + static_cast<int64_t>(delay_s * opt_.time_scale * 1e9);
    if (delay_s == 0) finish_door_restore();
    return;
  }
  if (state_ == MachineState::hold && hold_complete_ && !soft_limit_stop_ && spindle_stop_) {
    // A spindle stopped in the hold is restored first ("[MSG:Restoring spindle]"), then resumed.
    spindle_stop_ |= kStopRestoreCycle;
    spindle_stop_step();
    return;
  }
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

void Controller::apply_overrides() {
  // protocol_exec_rt_system(): all flags pending since the last poll at once, in uint8
  // arithmetic as GRBL does, then clamped.
  if (const unsigned f = std::exchange(motion_ovr_flags_, 0u)) {
    uint8_t feed = static_cast<uint8_t>(feed_ovr_);
    if (f & kFeedReset) feed = 100;
    if (f & kFeedCoarsePlus) feed += 10;
    if (f & kFeedCoarseMinus) feed -= 10;
    if (f & kFeedFinePlus) feed += 1;
    if (f & kFeedFineMinus) feed -= 1;
    feed = std::clamp<uint8_t>(feed, 10, 200);
    int rapid = rapid_ovr_;
    if (f & kRapidReset) rapid = 100;
    if (f & kRapidMedium) rapid = 50;
    if (f & kRapidLow) rapid = 25;
    if (feed != feed_ovr_ || rapid != rapid_ovr_) {
      feed_ovr_ = feed;
      rapid_ovr_ = rapid;
      ovr_counter_ = 0;
      motion_.set_feed_overrides(now_, feed_ovr_ / 100.0, rapid_ovr_ / 100.0);
    }
  }
  if (const unsigned f = std::exchange(accessory_ovr_flags_, 0u)) {
    uint8_t sp = static_cast<uint8_t>(spindle_ovr_);
    if (f & kSpindleReset) sp = 100;
    if (f & kSpindleCoarsePlus) sp += 10;
    if (f & kSpindleCoarseMinus) sp -= 10;
    if (f & kSpindleFinePlus) sp += 1;
    if (f & kSpindleFineMinus) sp -= 1;
    sp = std::clamp<uint8_t>(sp, 10, 200);
    if (sp != spindle_ovr_) {
      spindle_ovr_ = sp;
      motion_.set_spindle_override(now_, spindle_ovr_ / 100.0);
      // Idle: spindle_set_state(modal spindle, S) at once - in laser mode with M3 that turns
      // the beam on at S while standing still, as the real one does (M4 is forced to 0).
      if (state_ == MachineState::idle && gc_.spindle != Spindle::off)
        motion_.set_spindle(now_, gc_.spindle,
                            settings_.laser_mode() && gc_.spindle == Spindle::ccw ? 0.0 : gc_.s);
      ovr_counter_ = 0;
    }
    if ((f & kSpindleStop) && state_ == MachineState::hold) {  // only in a hold
      if (spindle_stop_ == 0) spindle_stop_ = kStopInitiate;
      else if (spindle_stop_ & kStopEnabled) spindle_stop_ |= kStopRestore;
      spindle_stop_step();
    }
    if ((f & kFloodToggle) && (state_ == MachineState::idle || state_ == MachineState::run ||
                               state_ == MachineState::hold || state_ == MachineState::jog)) {
      gc_.flood = !gc_.flood;  // the parser's modal state follows (M8/M9 in $G)
      set_flood(gc_.flood);
      ovr_counter_ = 0;
    }
  }
}

void Controller::set_flood(bool on) {
  if (on == flood_on_) return;
  flood_on_ = on;
  ovr_counter_ = 0;  // coolant_set_state(): overrides (and A:F) in the next report
}

void Controller::safety_door() {
  // protocol_exec_rt_system(), EXEC_SAFETY_DOOR (no door switch: it reads closed at once).
  if (critical_ || state_ == MachineState::alarm || state_ == MachineState::check ||
      state_ == MachineState::home || soft_limit_stop_)
    return;
  emit("[MSG:Check Door]\r\n");
  if (state_ == MachineState::sleep) return;
  record_.add_event(epoch(now_), "door");
  if (state_ == MachineState::jog) {  // the jog is cancelled first, then the door takes over
    door_after_jog_ = true;
    jog_cancel();
    return;
  }
  if (state_ == MachineState::door) {
    if (door_restore_until_) {  // re-opened while restoring: retract again
      door_restore_until_.reset();
      door_stopped();
    }
    return;
  }
  const bool moving = motion_.running();
  state_ = MachineState::door;
  door_retracted_ = false;
  if (moving) {
    if (!motion_.decelerating()) motion_.hold(now_);
    hold_complete_ = false;
  } else {
    hold_complete_ = true;
    door_stopped();
  }
}

void Controller::door_stopped() {
  // The door's hold is complete: spindle (laser) and coolant off, ready to restore ("Door:0").
  spindle_stop_ = 0;
  motion_.set_hold_beam_off(now_, true);
  set_flood(false);
  ovr_counter_ = 0;
  door_retracted_ = true;
}

void Controller::finish_door_restore() {
  // SUSPEND_RESTORE_COMPLETE and a cycle start: Idle, and the program resumes if it was moving.
  door_restore_until_.reset();
  door_retracted_ = false;
  hold_complete_ = false;
  // A laser's power comes back with the next block (the stepper sets it); nothing at rest.
  if (settings_.laser_mode()) motion_.set_spindle(now_, gc_.spindle, 0);
  motion_.set_hold_beam_off(now_, false);
  record_.add_event(epoch(now_), "resume");
  state_ = MachineState::idle;
  auto_cycle_start();
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
  // gcode.c with GC_PARSER_JOG_MOTION (every check where gcode.c makes it), then jog_execute():
  // a target beyond the soft limits is error:15, no alarm. The parser's modes stay as they
  // were; only its position follows the jog.
  GcState scratch = gc_;
  LineResult r = execute_gcode_line(line.substr(3), scratch, settings_, /*jog=*/true);
  if (r.status != kOk) return r.status;
  actions_.clear();
  for (const Action& a : r.actions) {
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
  // main(): sys is cleared (overrides back to 100 %, flags dropped), coolant_init().
  motion_ovr_flags_ = accessory_ovr_flags_ = 0;
  if (feed_ovr_ != 100 || rapid_ovr_ != 100) motion_.set_feed_overrides(now_, 1, 1);
  if (spindle_ovr_ != 100) motion_.set_spindle_override(now_, 1);
  feed_ovr_ = rapid_ovr_ = spindle_ovr_ = 100;
  flood_on_ = false;
  spindle_stop_ = 0;
  door_retracted_ = door_after_jog_ = false;
  door_restore_until_.reset();
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
    case MachineState::door: return door_restore_until_ ? "Door:3" : door_retracted_ ? "Door:0" : "Door:2";
  }
  return "Idle";
}

std::string Controller::status_report() {
  const int mask = settings_.status_mask();
  const bool inches = settings_.get(13) != 0;
  const bool busy = state_ == MachineState::run || state_ == MachineState::hold || state_ == MachineState::jog ||
                    state_ == MachineState::home || state_ == MachineState::door;
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
  if (mask & 2) {
    // serial_get_rx_buffer_available(): 128 - used while the ring's head is at or past its
    // tail, 127 - used once it has wrapped (GRBL's own off-by-one; 128 when empty).
    const long used = static_cast<long>(rx_.size());
    const long head = rx_pushed_ % kRxBufferSize, tail = ((rx_pushed_ - used) % kRxBufferSize + kRxBufferSize) % kRxBufferSize;
    const long available = head >= tail ? kRxBufferSize - used : kRxBufferSize - 1 - used;
    r += "|Bf:" + std::to_string(Motion::kPlannerBlocks - motion_.blocks()) + "," + std::to_string(available);
  }
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
    r += "|Ov:" + std::to_string(feed_ovr_) + "," + std::to_string(rapid_ovr_) + "," + std::to_string(spindle_ovr_);
    const Spindle on = motion_.laser_spindle();
    if (on != Spindle::off || flood_on_) r += "|A:";
    if (on == Spindle::cw) r += "S";
    else if (on == Spindle::ccw) r += "C";
    if (flood_on_) r += "F";
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

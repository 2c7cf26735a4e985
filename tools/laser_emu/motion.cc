#include "tools/laser_emu/motion.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace atelier::laser_emu {
namespace {

// A phase shorter than this (a cruise of zero length, left by rounding) is merged into the
// next one rather than recorded as a piece of its own.
constexpr int64_t kPhaseSlackNs = 1000;


double distance(const Vec3& a, const Vec3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

// Steps to mm on an axis. With $100..$102 = 0 (accepted, as GRBL does) the axis makes no steps
// and stays at 0 instead of 0/0 = NaN mm (found by fuzz_laser_emu_gcode).
double steps_to_mm(long steps, double steps_per_mm) {
  return steps_per_mm > 0 ? static_cast<double>(steps) / steps_per_mm : 0.0;
}

}  // namespace

Motion::Motion(const Settings& settings, double time_scale, Record& record, double epoch_at_zero_s)
    : settings_(settings), time_scale_(time_scale), record_(record), epoch0_(epoch_at_zero_s) {}

Vec3 Motion::planner_position() const {
  Vec3 p;
  for (int i = 0; i < 3; ++i) p[i] = steps_to_mm(planner_steps_[i], settings_.steps_per_mm(i));
  return p;
}

bool Motion::push(const Vec3& target, double feed, bool rapid, bool inverse_time, Spindle spindle, double s,
                  bool no_feed_override) {
  std::array<long, 3> steps{};
  bool moves = false;
  for (int i = 0; i < 3; ++i) {
    steps[i] = std::lround(target[i] * settings_.steps_per_mm(i));
    moves |= steps[i] != planner_steps_[i];
  }
  if (!moves) return false;  // PLAN_EMPTY_BLOCK
  Block b;
  b.start = planner_position();
  for (int i = 0; i < 3; ++i) b.end[i] = steps_to_mm(steps[i], settings_.steps_per_mm(i));
  b.length = distance(b.start, b.end);
  laser::MotionSettings ms;
  for (int i = 0; i < 3; ++i) {
    ms.max_rate_mm_min[i] = settings_.max_rate(i);
    ms.accel_mm_s2[i] = settings_.accel(i);
    ms.steps_per_mm[i] = settings_.steps_per_mm(i);
  }
  ms.junction_deviation_mm = settings_.get(11);
  if (queue_.empty()) {  // an empty planner: this block starts from rest
    planner_.sync();
    last_nominal100_ = 0;
  }
  const double programmed = inverse_time ? feed * b.length : feed;
  b.plan = planner_.add(ms, {b.end[0] - b.start[0], b.end[1] - b.start[1], b.end[2] - b.start[2]}, programmed,
                        rapid);
  // The rapid rate along the block: the axis limits ($110..$112) scaled by the direction.
  b.rapid_mm_min = std::numeric_limits<double>::max();
  for (int i = 0; i < 3; ++i) {
    const double u = b.length > 0 ? std::fabs(b.end[i] - b.start[i]) / b.length : 0;
    if (u > 0) b.rapid_mm_min = std::min(b.rapid_mm_min, settings_.max_rate(i) / u);
  }
  b.rapid = rapid;
  b.no_override = no_feed_override;
  b.programmed_mm_min = rapid ? b.rapid_mm_min : programmed;
  // The junction's own limit: below the nominal cap it is what the planner found, above it unknown.
  const double cap = std::min(b.plan.nominal_mm_min, last_nominal100_) / 60;
  b.junction_sqr = b.plan.max_entry_sqr < cap * cap * (1 - 1e-9) ? b.plan.max_entry_sqr : 1e300;
  last_nominal100_ = b.plan.nominal_mm_min;
  b.rate = b.plan.nominal_mm_min;
  b.accel = b.plan.accel_mm_s2;
  b.spindle = spindle;
  b.s = s;
  queue_.push_back(b);
  if (feed_ovr_ != 1 || rapid_ovr_ != 1) apply_overrides(queue_.size() - 1);
  planner_steps_ = steps;
  // The running block may now leave faster: replan it from where the head is (GRBL's stepper
  // takes the new plan at its next segment).
  if (running_ && !decel_ && queue_.size() >= 2) {
    const double d = distance_at(now_), v = speed_at(now_);
    close_piece(now_);
    d0_ = d;
    profile_front(now_, v);
    begin_piece(now_);
  }
  return true;
}

void Motion::apply_overrides(size_t i) {
  Block& b = queue_[i];
  // plan_compute_profile_nominal_speed(): the programmed rate times the override, at most the
  // rapid rate, at least MINIMUM_FEED_RATE (1 mm/min).
  double nominal = b.programmed_mm_min;
  if (b.rapid) nominal *= rapid_ovr_;
  else if (!b.no_override) nominal *= feed_ovr_;
  nominal = std::max(1.0, std::min(nominal, b.rapid_mm_min));
  b.rate = nominal;
  b.plan.nominal_mm_min = nominal;
  if (i > 0) {  // plan_compute_profile_parameters(): never enter faster than either nominal
    const double cap = std::min(nominal, queue_[i - 1].rate) / 60;
    b.plan.max_entry_sqr = std::min(b.junction_sqr, cap * cap);
  }
}

void Motion::set_feed_overrides(int64_t now, double feed, double rapid) {
  now_ = std::max(now_, now);
  feed_ovr_ = feed;
  rapid_ovr_ = rapid;
  for (size_t i = 0; i < queue_.size(); ++i) apply_overrides(i);
  if (running_ && !decel_ && !queue_.empty()) {
    const double d = distance_at(now_), v = speed_at(now_);
    close_piece(now_);
    d0_ = d;
    profile_front(now_, v);
    begin_piece(now_);
  }
}

void Motion::set_spindle_override(int64_t now, double factor) {
  now_ = std::max(now_, now);
  close_piece(now_);
  spindle_ovr_ = factor;
  begin_piece(now_);
}

void Motion::profile_front(int64_t now, double entry_mm_min) {
  t0_ = now;
  phase_ = 0;
  const size_t n = std::min<size_t>(queue_.size(), kPlannerBlocks);
  std::vector<laser::PlannerBlock> plan(n);
  for (size_t i = 0; i < n; ++i) plan[i] = queue_[i].plan;
  const Block& b = queue_.front();
  plan[0].length_mm = std::max(0.0, b.length - d0_);
  const double exit = laser::planned_exit(plan.data(), n, entry_mm_min);
  prof_ = laser::trapezoid(plan[0].length_mm, entry_mm_min, b.rate, exit, b.accel);
  while (phase_ < 2 && phase_end(phase_) <= now + kPhaseSlackNs) ++phase_;
}

int64_t Motion::phase_end(int phase) const {
  const double a = prof_.accel_mm_s2 * 60;  // mm/min per s
  double secs = prof_.seconds;
  if (a > 0 && phase == 0) secs = (prof_.peak_mm_min - prof_.entry_mm_min) / a;
  if (a > 0 && phase == 1) secs = prof_.seconds - (prof_.peak_mm_min - prof_.exit_mm_min) / a;
  return t0_ + static_cast<int64_t>(std::ceil(std::clamp(secs, 0.0, prof_.seconds) * time_scale_ * 1e9));
}

Vec3 Motion::position() const {
  if (!running_ || queue_.empty()) return head_;
  const Block& b = queue_.front();
  const double f = b.length > 0 ? distance_at(now_) / b.length : 1.0;
  Vec3 p;
  for (int i = 0; i < 3; ++i) p[i] = b.start[i] + (b.end[i] - b.start[i]) * f;
  return p;
}

void Motion::set_position(const Vec3& mm) {
  for (int i = 0; i < 3; ++i) {
    planner_steps_[i] = std::lround(mm[i] * settings_.steps_per_mm(i));
    head_[i] = steps_to_mm(planner_steps_[i], settings_.steps_per_mm(i));
  }
  piece_p0_ = head_;
}

double Motion::distance_at(int64_t t) const {
  if (!running_ || queue_.empty()) return 0;
  const Block& b = queue_.front();
  const double tau = static_cast<double>(std::max<int64_t>(0, (decel_ ? std::min(t, stop_t_) : t) - t0_)) * 1e-9 / time_scale_;
  if (decel_) return std::min(stop_d_, d0_ + decel_v0_ * tau - 0.5 * decel_a_ * tau * tau);
  return std::min(b.length, d0_ + prof_.distance_at(tau));
}

double Motion::speed_at(int64_t t) const {
  if (!running_ || queue_.empty()) return 0;
  const double tau = static_cast<double>(std::max<int64_t>(0, (decel_ ? std::min(t, stop_t_) : t) - t0_)) * 1e-9 / time_scale_;
  if (decel_) return std::max(0.0, decel_v0_ - decel_a_ * tau) * 60.0;
  return prof_.speed_at(tau);
}

Motion::Output Motion::output_at(int64_t t) const {
  if (running_ && !queue_.empty()) {
    const Block& b = queue_.front();
    return Output{b.spindle, b.s, b.rate, speed_at(t)};
  }
  if (hold_beam_off_) return Output{};
  return idle_;
}

double Motion::power_of(const Output& o) const {
  if (o.spindle == Spindle::off || o.s <= 0) return 0;
  // spindle_compute_pwm_value(): S (M4: times the speed ratio) times the override, capped at $30.
  double s = o.s;
  if (o.spindle == Spindle::ccw && settings_.laser_mode())
    s *= o.programmed_rate > 0 ? o.speed / o.programmed_rate : 0.0;  // M4
  const double p = std::min(s * spindle_ovr_, settings_.s_max()) / std::max(1e-9, settings_.s_max());
  return std::clamp(p, 0.0, 1.0);
}

std::optional<Segment> Motion::open_segment(int64_t now) const {
  const Vec3 p1 = position();
  const Output start = output_at(piece_t0_), end = output_at(now);
  // M3 power is constant over a piece; M4 follows the speed, which changes linearly (decel).
  double power = power_of(start);
  if (start.spindle == Spindle::ccw) power = 0.5 * (power_of(start) + power_of(end));
  const bool moved = distance(piece_p0_, p1) > 1e-9;
  if (!moved && (power <= 0 || now <= piece_t0_)) return std::nullopt;
  Segment s;
  s.t0 = epoch(piece_t0_);
  s.t1 = epoch(now);
  s.x0 = piece_p0_[0], s.y0 = piece_p0_[1], s.x1 = p1[0], s.y1 = p1[1];
  s.s = start.s;
  s.power = power;
  s.mode = power > 0 ? (start.spindle == Spindle::cw ? "M3" : "M4") : "off";
  s.feed = moved ? start.programmed_rate : 0.0;
  return s;
}

void Motion::close_piece(int64_t now) {
  now_ = std::max(now_, now);
  if (auto s = open_segment(now_)) record_.add_segment(*s);
}

// After a state change: start the next piece and note the beam going off.
void Motion::begin_piece(int64_t now) {
  piece_t0_ = now;
  piece_p0_ = position();
  const bool on = power_of(output_at(now)) > 0;
  if (beam_was_on_ && !on) record_.add_event(epoch(now), "beam_off");
  beam_was_on_ = on;
}

void Motion::finish_block(int64_t t) {
  close_piece(t);
  const Block b = queue_.front();
  queue_.pop_front();
  head_ = b.end;
  t0_ = t;
  d0_ = 0;
  if (!queue_.empty()) profile_front(t, prof_.exit_mm_min);
  if (queue_.empty()) {
    running_ = false;
    planner_.sync();
    // Cycle end: a laser's M4 output follows the speed (now 0); M3 keeps the last block's power.
    const bool m4_laser = b.spindle == Spindle::ccw && settings_.laser_mode();
    idle_ = Output{b.spindle, m4_laser ? 0.0 : b.s, 0, 0};
  }
  begin_piece(t);
}

std::optional<int64_t> Motion::next_event() const {
  if (!running_ || queue_.empty()) return std::nullopt;
  if (decel_) return stop_t_;
  return phase_end(phase_);
}

void Motion::advance(int64_t now) {
  while (running_) {
    const auto due = next_event();
    if (!due || *due > now) break;
    now_ = std::max(now_, *due);
    if (decel_) {
      // Hold complete: the rest of the block stays queued for the resume.
      close_piece(*due);
      Block& b = queue_.front();
      const double f = b.length > 0 ? stop_d_ / b.length : 1.0;
      for (int i = 0; i < 3; ++i) head_[i] = b.start[i] + (b.end[i] - b.start[i]) * f;
      running_ = decel_ = false;
      if (b.length - stop_d_ <= 1e-9) {
        head_ = b.end;
        queue_.pop_front();
      } else {
        b.start = head_;
        b.length -= stop_d_;
      }
      d0_ = 0;
      // The head stands still: a laser's M4 is off, M3 keeps its power (the controller's
      // spindle stop turns it off); outside laser mode the spindle runs on.
      const bool m4_laser = b.spindle == Spindle::ccw && settings_.laser_mode();
      idle_ = Output{b.spindle, m4_laser ? 0.0 : b.s, 0, 0};
      begin_piece(*due);
    } else if (phase_ < 2) {
      // From accelerating to cruising to decelerating: a new piece, so M4's power stays exact.
      close_piece(*due);
      ++phase_;
      while (phase_ < 2 && phase_end(phase_) <= *due + kPhaseSlackNs) ++phase_;
      begin_piece(*due);
    } else {
      finish_block(*due);
    }
  }
  now_ = std::max(now_, now);
}

void Motion::start(int64_t now) {
  now_ = std::max(now_, now);
  if (running_ || queue_.empty()) return;
  close_piece(now_);
  head_ = queue_.front().start;
  running_ = true;
  decel_ = false;
  d0_ = 0;
  profile_front(now_, 0);  // from rest (a cycle start, or the resume after a hold)
  begin_piece(now_);
}

void Motion::hold(int64_t now) {
  now_ = std::max(now_, now);
  if (!running_ || decel_) return;
  close_piece(now_);
  const Block& b = queue_.front();
  const double d = distance_at(now_), v = speed_at(now_) / 60.0, a = b.accel;
  d0_ = d;
  t0_ = now_;
  decel_ = true;
  decel_a_ = a;
  decel_v0_ = v;
  double tau = 0;
  if (a > 0 && std::isfinite(a)) {
    const double stopping = v * v / (2 * a);
    if (d + stopping <= b.length) {
      stop_d_ = d + stopping;
      tau = v / a;
    } else {  // the deceleration is cut short at the block's end
      stop_d_ = b.length;
      const double r = b.length - d;
      tau = (v - std::sqrt(std::max(0.0, v * v - 2 * a * r))) / a;
    }
  } else {
    stop_d_ = d;
  }
  stop_t_ = now_ + static_cast<int64_t>(std::ceil(tau * time_scale_ * 1e9));
  begin_piece(now_);
}

void Motion::stop(int64_t now) {
  now_ = std::max(now_, now);
  close_piece(now_);
  head_ = position();  // where the head stopped, between steps as likely as not
  running_ = decel_ = false;
  queue_.clear();
  planner_.sync();
  for (int i = 0; i < 3; ++i) planner_steps_[i] = std::lround(head_[i] * settings_.steps_per_mm(i));
  idle_ = Output{};
  hold_beam_off_ = false;
  begin_piece(now_);
}

void Motion::set_spindle(int64_t now, Spindle spindle, double s) {
  now_ = std::max(now_, now);
  close_piece(now_);
  idle_ = Output{spindle, spindle == Spindle::off ? 0.0 : s, 0, 0};
  begin_piece(now_);
}

void Motion::set_hold_beam_off(int64_t now, bool off) {
  now_ = std::max(now_, now);
  close_piece(now_);
  hold_beam_off_ = off;
  begin_piece(now_);
}

double Motion::speed_mm_min() const { return speed_at(now_); }

double Motion::laser_s() const {
  const Output o = output_at(now_);
  if (power_of(o) <= 0) return 0;
  double s = o.s;
  if (o.spindle == Spindle::ccw && settings_.laser_mode()) s *= o.programmed_rate > 0 ? o.speed / o.programmed_rate : 0.0;
  return std::min(s * spindle_ovr_, settings_.s_max());  // sys.spindle_speed
}

Spindle Motion::laser_spindle() const {
  const Output o = output_at(now_);
  return power_of(o) > 0 ? o.spindle : Spindle::off;
}

}  // namespace atelier::laser_emu

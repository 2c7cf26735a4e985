#include "algorithms/laser/motion_planner.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace atelier::laser {
namespace {

constexpr double kMinFeed = 1.0 / 60;  // MINIMUM_FEED_RATE 1 mm/min, in mm/s
constexpr double kHuge = std::numeric_limits<double>::max() / 4;

// limit_value_by_axis_maximum(): the largest value along `unit` no axis exceeds.
double limit_along(const std::array<double, 3>& max, const std::array<double, 3>& unit) {
  double v = kHuge;
  for (int i = 0; i < 3; ++i)
    if (unit[i] != 0) v = std::min(v, max[i] / std::fabs(unit[i]));
  return v;
}

}  // namespace

MotionSettings motion_settings_from(const std::map<int, double>& dollar) {
  MotionSettings s;
  auto take = [&](int id, double& into) {
    if (auto it = dollar.find(id); it != dollar.end() && it->second > 0) into = it->second;
  };
  take(11, s.junction_deviation_mm);
  for (int i = 0; i < 3; ++i) {
    take(100 + i, s.steps_per_mm[i]);
    take(110 + i, s.max_rate_mm_min[i]);
    take(120 + i, s.accel_mm_s2[i]);
  }
  return s;
}

double MoveProfile::speed_at(double t) const {
  const double a = accel_mm_s2 * 60;  // mm/min per second
  if (t <= 0) return entry_mm_min;
  if (t >= seconds) return exit_mm_min;
  const double t_acc = a > 0 ? (peak_mm_min - entry_mm_min) / a : 0;
  const double t_dec = a > 0 ? (peak_mm_min - exit_mm_min) / a : 0;
  if (t < t_acc) return entry_mm_min + a * t;
  const double t_cruise_end = seconds - t_dec;
  if (t < t_cruise_end) return peak_mm_min;
  return std::max(exit_mm_min, peak_mm_min - a * (t - t_cruise_end));
}

double MoveProfile::distance_at(double t) const {
  if (t <= 0) return 0;
  if (t >= seconds) return length_mm;
  const double a = accel_mm_s2;  // mm/s^2
  const double v0 = entry_mm_min / 60, vp = peak_mm_min / 60, v1 = exit_mm_min / 60;
  const double t_acc = a > 0 ? (vp - v0) / a : 0;
  const double t_dec = a > 0 ? (vp - v1) / a : 0;
  const double t_cruise_end = seconds - t_dec;
  double d;
  if (t < t_acc) {
    d = v0 * t + 0.5 * a * t * t;
  } else if (t < t_cruise_end) {
    d = accel_mm + vp * (t - t_acc);
  } else {
    const double u = t - t_cruise_end;
    d = length_mm - decel_mm + vp * u - 0.5 * a * u * u;
  }
  return std::clamp(d, 0.0, length_mm);
}

MoveProfile trapezoid(double length_mm, double entry_mm_min, double nominal_mm_min, double exit_mm_min,
                      double accel_mm_s2) {
  MoveProfile p;
  p.length_mm = length_mm;
  p.accel_mm_s2 = accel_mm_s2;
  if (!(length_mm > 0)) return p;
  const double a = accel_mm_s2;
  const double vn = std::max(nominal_mm_min / 60, kMinFeed);
  double v0 = std::clamp(entry_mm_min / 60, 0.0, vn);
  double v1 = std::clamp(exit_mm_min / 60, 0.0, vn);
  if (!(a > 0)) {  // no acceleration limit: the whole move at nominal speed
    p.entry_mm_min = p.exit_mm_min = p.peak_mm_min = p.nominal_mm_min = vn * 60;
    p.seconds = length_mm / vn;
    return p;
  }
  // What the length allows between the two ends.
  v1 = std::min(v1, std::sqrt(v0 * v0 + 2 * a * length_mm));
  v0 = std::min(v0, std::sqrt(v1 * v1 + 2 * a * length_mm));
  const double peak = std::min(vn, std::sqrt((2 * a * length_mm + v0 * v0 + v1 * v1) / 2));
  const double d_acc = std::max(0.0, (peak * peak - v0 * v0) / (2 * a));
  const double d_dec = std::max(0.0, (peak * peak - v1 * v1) / (2 * a));
  const double cruise = std::max(0.0, length_mm - d_acc - d_dec);
  p.entry_mm_min = v0 * 60;
  p.exit_mm_min = v1 * 60;
  p.nominal_mm_min = vn * 60;
  p.peak_mm_min = peak * 60;
  p.accel_mm = d_acc;
  p.decel_mm = length_mm - d_acc - cruise;
  p.seconds = (peak - v0) / a + (peak - v1) / a + (peak > 0 ? cruise / peak : 0);
  return p;
}

PlannerBlock BlockPlanner::add(const MotionSettings& settings, const std::array<double, 3>& delta, double feed_mm_min,
                               bool rapid) {
  std::array<double, 3> max_rate{}, accel{};
  for (int i = 0; i < 3; ++i) {
    max_rate[i] = settings.max_rate_mm_min[i] / 60;
    accel[i] = settings.accel_mm_s2[i];
  }
  const double length = std::sqrt(delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2]);
  std::array<double, 3> unit{};
  for (int i = 0; i < 3; ++i) unit[i] = length > 0 ? delta[i] / length : 0;

  PlannerBlock b;
  b.length_mm = length;
  b.accel_mm_s2 = limit_along(accel, unit);
  const double rapid_rate = limit_along(max_rate, unit);
  const double nominal = std::max(kMinFeed, rapid ? rapid_rate : std::min(feed_mm_min / 60, rapid_rate));
  b.nominal_mm_min = nominal * 60;
  double max_junction_sqr = 0;
  if (!at_rest_) {
    double cos_theta = 0;
    std::array<double, 3> junction{};
    for (int i = 0; i < 3; ++i) {
      cos_theta -= prev_unit_[i] * unit[i];
      junction[i] = unit[i] - prev_unit_[i];
    }
    if (cos_theta > 0.999999) {
      max_junction_sqr = 0;  // a full reversal: MINIMUM_JUNCTION_SPEED 0
    } else if (cos_theta < -0.999999) {
      max_junction_sqr = kHuge;  // straight on
    } else {
      const double jl = std::sqrt(junction[0] * junction[0] + junction[1] * junction[1] + junction[2] * junction[2]);
      for (double& v : junction) v /= jl;
      const double junction_accel = limit_along(accel, junction);
      const double sin_half = std::sqrt(0.5 * (1.0 - cos_theta));
      max_junction_sqr = junction_accel * settings.junction_deviation_mm * sin_half / (1.0 - sin_half);
    }
    // plan_compute_profile_parameters(): never enter faster than either nominal speed.
    const double nominal_cap = nominal > prev_nominal_ ? prev_nominal_ : nominal;
    b.max_entry_sqr = std::min(nominal_cap * nominal_cap, max_junction_sqr);
  }
  prev_nominal_ = nominal;
  prev_unit_ = unit;
  at_rest_ = false;
  return b;
}

double planned_exit(const PlannerBlock* queue, size_t count, double entry_mm_min) {
  if (count < 2) return 0;
  // Reverse pass from the newest block (planner_recalculate), then the forward limit.
  double next_sqr = 0;
  for (size_t j = count - 1; j > 0; --j)
    next_sqr = std::min(queue[j].max_entry_sqr, next_sqr + 2 * queue[j].accel_mm_s2 * queue[j].length_mm);
  const double entry = entry_mm_min / 60;
  return 60 * std::sqrt(std::min(next_sqr, entry * entry + 2 * queue[0].accel_mm_s2 * queue[0].length_mm));
}

std::vector<MoveProfile> plan_moves(const std::vector<PlannedMove>& moves, const MotionSettings& settings,
                                    std::array<double, 3> start) {
  std::vector<MoveProfile> out(moves.size());
  std::vector<PlannerBlock> blocks;
  std::vector<bool> at_rest;    // blocks[k] starts at rest (a sync before it, or the first)
  std::vector<size_t> move_of;  // blocks[k] is moves[move_of[k]]
  blocks.reserve(moves.size());
  BlockPlanner planner;
  std::array<long, 3> steps{};
  for (int i = 0; i < 3; ++i) steps[i] = std::lround(start[i] * settings.steps_per_mm[i]);
  bool pending_sync = true;  // the planner starts empty
  for (size_t m = 0; m < moves.size(); ++m) {
    const PlannedMove& mv = moves[m];
    if (mv.from_rest) pending_sync = true;
    std::array<double, 3> delta{};
    bool any = false;
    for (int i = 0; i < 3; ++i) {
      const long target = std::lround(mv.target[i] * settings.steps_per_mm[i]);
      if (target != steps[i]) any = true;
      delta[i] = static_cast<double>(target - steps[i]) / settings.steps_per_mm[i];
      steps[i] = target;
    }
    if (!any) continue;  // no steps: GRBL drops the block
    if (pending_sync) planner.sync();
    at_rest.push_back(pending_sync);
    pending_sync = false;
    blocks.push_back(planner.add(settings, delta, mv.feed_mm_min, mv.rapid));
    move_of.push_back(m);
  }

  const size_t n = blocks.size();
  const size_t window = static_cast<size_t>(std::max(1, settings.planner_blocks));
  double entry = 0;  // mm/min, of the block about to run
  for (size_t k = 0; k < n; ++k) {
    // The planner when block k starts: blocks k..last (the host keeps it full); the last
    // must be able to stop, a sync ends the window early.
    size_t last = std::min(n - 1, k + window - 1);
    for (size_t j = k + 1; j <= last; ++j)
      if (at_rest[j]) {
        last = j - 1;
        break;
      }
    const PlannerBlock& b = blocks[k];
    const double exit = planned_exit(&blocks[k], last - k + 1, entry);
    out[move_of[k]] = trapezoid(b.length_mm, entry, b.nominal_mm_min, exit, b.accel_mm_s2);
    entry = out[move_of[k]].exit_mm_min;
  }
  return out;
}

std::vector<double> move_seconds(const std::vector<PlannedMove>& moves, const MotionSettings& settings,
                                 std::array<double, 3> start) {
  std::vector<double> out;
  out.reserve(moves.size());
  for (const MoveProfile& p : plan_moves(moves, settings, start)) out.push_back(p.seconds);
  return out;
}

}  // namespace atelier::laser

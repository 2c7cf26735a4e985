#include "algorithms/laser/motion_planner.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace atelier::laser {
namespace {

constexpr double kMinimumFeedRate = 1.0;          // mm/min, config.h MINIMUM_FEED_RATE
constexpr double kMinimumJunctionSpeed = 0.0;     // mm/min, config.h MINIMUM_JUNCTION_SPEED
constexpr double kSomeLargeValue = 1.0e38;        // planner.h SOME_LARGE_VALUE

// A block as plan_buffer_line stores it (speeds squared, mm/min and mm/min^2).
struct Block {
  size_t move = 0;  // index of the move it came from
  double millimeters = 0, acceleration = 0, nominal_speed = 0;
  double max_entry_speed_sqr = 0;
};

// planner.c limit_value_by_axis_maximum: the largest value along `unit` no axis exceeds.
double limit_by_axis(const std::array<double, 3>& max, const std::array<double, 3>& unit) {
  double limit = kSomeLargeValue;
  for (int i = 0; i < 3; ++i)
    if (unit[i] != 0) limit = std::min(limit, std::fabs(max[i] / unit[i]));
  return limit;
}

void check(const MotionSettings& s) {
  for (int i = 0; i < 3; ++i)
    if (!(s.max_rate_mm_min[i] > 0) || !(s.accel_mm_s2[i] > 0) || !(s.steps_per_mm[i] > 0))
      throw std::invalid_argument("motion settings: axis " + std::string(1, "XYZ"[i]) +
                                  " needs positive max rate, acceleration and steps/mm");
  if (!(s.junction_deviation_mm >= 0))
    throw std::invalid_argument("motion settings: junction deviation ($11) must be >= 0");
  if (s.planner_blocks < 1) throw std::invalid_argument("motion settings: planner_blocks < 1");
}

}  // namespace

MotionSettings motion_settings_from(const std::map<int, double>& dollar) {
  MotionSettings s;
  auto take = [&](int id, double& into) {
    if (auto it = dollar.find(id); it != dollar.end()) into = it->second;
  };
  take(11, s.junction_deviation_mm);
  for (int i = 0; i < 3; ++i) {
    take(100 + i, s.steps_per_mm[i]);
    take(110 + i, s.max_rate_mm_min[i]);
    take(120 + i, s.accel_mm_s2[i]);
  }
  return s;
}

double trapezoid_seconds(double mm, double entry, double nominal, double exit, double accel) {
  if (!(mm > 0)) return 0;
  const double e2 = entry * entry, x2 = exit * exit;
  double n2 = nominal * nominal;
  // Peak speed a triangle reaches on this length; below nominal there is no cruise.
  const double peak2 = std::max({(e2 + x2 + 2 * accel * mm) / 2, e2, x2});
  double minutes;
  if (peak2 <= n2) {
    const double peak = std::sqrt(peak2);
    minutes = (peak - entry) / accel + (peak - exit) / accel;
  } else {
    n2 = std::max({n2, e2, x2});
    const double n = std::sqrt(n2);
    const double ramps = (n2 - e2) / (2 * accel) + (n2 - x2) / (2 * accel);
    minutes = (n - entry) / accel + (n - exit) / accel + std::max(0.0, mm - ramps) / n;
  }
  return minutes * 60;
}

std::vector<BlockProfile> plan_profiles(const std::vector<PlannedMove>& moves,
                                        const MotionSettings& s, std::array<double, 3> start) {
  check(s);
  std::array<double, 3> accel_mm_min2;  // GRBL keeps acceleration in mm/min^2
  for (int i = 0; i < 3; ++i) accel_mm_min2[i] = s.accel_mm_s2[i] * 3600;

  // plan_buffer_line for every move: blocks, and where the planner was empty before one.
  std::vector<Block> blocks;
  std::vector<bool> group_start;  // this block enters with an empty planner
  std::array<int64_t, 3> position;
  for (int i = 0; i < 3; ++i) position[i] = std::lround(start[i] * s.steps_per_mm[i]);
  std::array<double, 3> previous_unit{};
  double previous_nominal = 0;
  bool rest = true;  // the planner starts empty
  for (size_t m = 0; m < moves.size(); ++m) {
    const PlannedMove& mv = moves[m];
    rest = rest || mv.from_rest;
    std::array<int64_t, 3> target;
    std::array<double, 3> unit;
    bool steps = false;
    for (int i = 0; i < 3; ++i) {
      target[i] = std::lround(mv.target[i] * s.steps_per_mm[i]);
      steps = steps || target[i] != position[i];
      unit[i] = double(target[i] - position[i]) / s.steps_per_mm[i];
    }
    if (!steps) continue;  // PLAN_EMPTY_BLOCK: nothing enters the planner
    const double mm = std::sqrt(unit[0] * unit[0] + unit[1] * unit[1] + unit[2] * unit[2]);
    for (double& u : unit) u /= mm;
    Block b;
    b.move = m;
    b.millimeters = mm;
    b.acceleration = limit_by_axis(accel_mm_min2, unit);
    const double rapid_rate = limit_by_axis(s.max_rate_mm_min, unit);
    double nominal = mv.rapid ? rapid_rate : std::min(mv.feed_mm_min, rapid_rate);
    b.nominal_speed = std::max(nominal, kMinimumFeedRate);
    double junction_sqr;
    if (rest) {
      junction_sqr = 0;  // starting from rest
    } else {
      double cos_theta = 0;
      std::array<double, 3> junction_unit;
      for (int i = 0; i < 3; ++i) {
        cos_theta -= previous_unit[i] * unit[i];
        junction_unit[i] = unit[i] - previous_unit[i];
      }
      if (cos_theta > 0.999999) {  // a reversal: 180 degrees
        junction_sqr = kMinimumJunctionSpeed * kMinimumJunctionSpeed;
      } else if (cos_theta < -0.999999) {  // straight on
        junction_sqr = kSomeLargeValue;
      } else {
        const double len = std::sqrt(junction_unit[0] * junction_unit[0] +
                                     junction_unit[1] * junction_unit[1] +
                                     junction_unit[2] * junction_unit[2]);
        for (double& u : junction_unit) u /= len;
        const double junction_accel = limit_by_axis(accel_mm_min2, junction_unit);
        const double sin_theta_d2 = std::sqrt(0.5 * (1.0 - cos_theta));
        junction_sqr = std::max(kMinimumJunctionSpeed * kMinimumJunctionSpeed,
                                junction_accel * s.junction_deviation_mm * sin_theta_d2 /
                                    (1.0 - sin_theta_d2));
      }
    }
    // plan_compute_profile_parameters
    const double slower = std::min(b.nominal_speed, previous_nominal);
    b.max_entry_speed_sqr = std::min(slower * slower, junction_sqr);
    previous_nominal = b.nominal_speed;
    previous_unit = unit;
    position = target;
    blocks.push_back(b);
    group_start.push_back(rest);
    rest = false;
  }

  // The stepper prepares block i while blocks i..i+planner_blocks-1 are in the planner (the
  // host keeps it full; a sync empties it). Its exit speed is what planner_recalculate's
  // reverse pass (the last block stops) and forward pass (block i's entry is fixed) give.
  std::vector<BlockProfile> out(moves.size());
  const size_t window = size_t(s.planner_blocks);
  double entry_sqr = 0;
  for (size_t i = 0; i < blocks.size(); ++i) {
    if (group_start[i]) entry_sqr = 0;
    size_t end = i + 1;  // one past the last block in the planner with block i
    while (end < blocks.size() && end < i + window && !group_start[end]) ++end;
    double next_entry_sqr = 0;  // the last block in the buffer plans to stop
    for (size_t j = end - 1; j > i; --j)
      next_entry_sqr = std::min(blocks[j].max_entry_speed_sqr,
                                next_entry_sqr + 2 * blocks[j].acceleration * blocks[j].millimeters);
    const Block& b = blocks[i];
    const double exit_sqr =
        std::min(next_entry_sqr, entry_sqr + 2 * b.acceleration * b.millimeters);
    BlockProfile& p = out[b.move];
    p.millimeters = b.millimeters;
    p.entry_mm_min = std::sqrt(entry_sqr);
    p.exit_mm_min = std::sqrt(exit_sqr);
    p.nominal_mm_min = b.nominal_speed;
    p.accel_mm_min2 = b.acceleration;
    p.seconds = trapezoid_seconds(b.millimeters, p.entry_mm_min, b.nominal_speed,
                                  p.exit_mm_min, b.acceleration);
    entry_sqr = exit_sqr;
  }
  return out;
}

std::vector<double> move_seconds(const std::vector<PlannedMove>& moves, const MotionSettings& s,
                                 std::array<double, 3> start) {
  std::vector<double> seconds;
  seconds.reserve(moves.size());
  for (const BlockProfile& p : plan_profiles(moves, s, start)) seconds.push_back(p.seconds);
  return seconds;
}

}  // namespace atelier::laser

#include "daemon/laser_job_checks.h"

#include <algorithm>
#include <cstdio>

namespace atelier {
namespace {

std::string mm(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

// Whether [lo, hi] lies within the travel of one axis, in either sign convention.
bool axis_fits(double lo, double hi, double travel) {
  const double slack = 1e-3;  // G-code rounds to 3 decimals
  if (lo >= -slack) return hi <= travel + slack;
  if (hi <= slack) return lo >= -travel - slack;
  return false;
}

}  // namespace

std::optional<std::string> job_fit_problem(const grbl::Program& program, const grbl::MachineInfo& info,
                                           const std::string& file) {
  if (program.s_max && std::abs(*program.s_max - info.s_max) > 0.5) {
    return file + " scales the beam power to S" + mm(*program.s_max) + " but the controller's $30 is " +
           mm(info.s_max) + ": set s_max = " + mm(info.s_max) + " in [laser] and retry the job";
  }
  if (program.bounds && info.max_travel_x > 0 && info.max_travel_y > 0) {
    const grbl::Bounds& b = *program.bounds;
    if (!axis_fits(b.min_x, b.max_x, info.max_travel_x) || !axis_fits(b.min_y, b.max_y, info.max_travel_y)) {
      return file + " spans X " + mm(b.min_x) + ".." + mm(b.max_x) + " mm, Y " + mm(b.min_y) + ".." +
             mm(b.max_y) + " mm, beyond the controller's travel of " + mm(info.max_travel_x) + " x " +
             mm(info.max_travel_y) + " mm ($130/$131)";
    }
  }
  return std::nullopt;
}

double rapid_rate(const grbl::MachineInfo& info) {
  double rate = 0;
  for (int key : {110, 111}) {
    auto it = info.settings.find(key);
    if (it != info.settings.end() && it->second > 0) rate = rate > 0 ? std::min(rate, it->second) : it->second;
  }
  return rate > 0 ? rate : 6000;
}

}  // namespace atelier

#include "drivers/grbl/machine_space.h"

#include <cmath>
#include <cstdio>

namespace atelier::grbl {
namespace {

// GRBL compares targets in whole steps; a job edge on the limit must not be refused for the
// rounding of its decimal text.
constexpr double kSlackMm = 0.001;

std::string mm(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", std::abs(v) < 0.05 ? 0.0 : v);
  return buf;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", std::abs(v) < 0.0005 ? 0.0 : v);
  return buf;
}

double setting(const MachineInfo& info, int n, double fallback) {
  auto it = info.settings.find(n);
  return it == info.settings.end() ? fallback : it->second;
}

}  // namespace

std::optional<StartFrom> parse_start_from(std::string_view name) {
  if (name == "bed") return StartFrom::bed;
  if (name == "origin") return StartFrom::origin;
  if (name == "here") return StartFrom::here;
  return std::nullopt;
}

const char* start_from_name(StartFrom from) {
  switch (from) {
    case StartFrom::bed: return "bed";
    case StartFrom::origin: return "origin";
    case StartFrom::here: return "here";
  }
  return "bed";
}

MachineSpace machine_space(const MachineInfo& info) {
  MachineSpace s;
  s.homed_space = info.homing;
  for (int i = 0; i < 3; ++i) {
    const double travel = std::abs(setting(info, 130 + i, 0));
    // limits.c / system.c (system_check_travel_limits) of GRBL 1.1h.
    const bool towards_negative = (info.homing_dir_mask >> i) & 1;
    if (!info.homing || (info.force_set_origin && towards_negative)) s.axis[i] = {0, travel};
    else s.axis[i] = {-travel, 0};
  }
  return s;
}

std::array<double, 2> bed_corner(const MachineSpace& s) { return {s.axis[0].min, s.axis[1].min}; }

std::array<double, 2> placement_offset(StartFrom from, const MachineSpace& s, const Status& now,
                                       const std::array<double, 3>& wco) {
  switch (from) {
    case StartFrom::bed: return bed_corner(s);
    case StartFrom::origin: return {wco[0], wco[1]};
    case StartFrom::here: return {now.x, now.y};
  }
  return bed_corner(s);
}

std::vector<std::string> placement_lines(StartFrom from, const MachineSpace& s, const Status& now,
                                         const std::array<double, 3>&) {
  switch (from) {
    case StartFrom::bed: {
      // G92 names the work coordinates of where the head is now: machine - corner.
      const auto c = bed_corner(s);
      return {"G92X" + number(now.x - c[0]) + "Y" + number(now.y - c[1])};
    }
    case StartFrom::origin: return {};
    case StartFrom::here: return {"G92X0Y0"};
  }
  return {};
}

std::string check_fits(const Bounds& job, StartFrom from, const MachineSpace& s, const MachineInfo& info,
                       const Status& now, const std::array<double, 3>& wco) {
  if (!info.soft_limits) return "";
  const auto off = placement_offset(from, s, now, wco);
  const double lo[2] = {job.min_x + off[0], job.min_y + off[1]};
  const double hi[2] = {job.max_x + off[0], job.max_y + off[1]};
  std::string out;
  for (int i = 0; i < 2; ++i) {
    const AxisRange& r = s.axis[i];
    if (r.max - r.min <= 0) continue;  // $13x unknown (0): nothing to check against
    if (lo[i] >= r.min - kSlackMm && hi[i] <= r.max + kSlackMm) continue;
    const char* axis = i == 0 ? "X" : "Y";
    if (!out.empty()) out += "; ";
    out += std::string("the job spans ") + axis + " " + mm(lo[i]) + ".." + mm(hi[i]) +
           " mm in the machine's space but the machine reaches " + axis + " " + mm(r.min) + ".." + mm(r.max) +
           " mm";
  }
  if (out.empty()) return "";
  switch (from) {
    case StartFrom::bed:
      out += " (start from bed: the bed's front-left corner is machine X " + mm(off[0]) + " Y " + mm(off[1]) +
             "; the job's bounds go past the work area)";
      break;
    case StartFrom::origin:
      out += " (start from origin: work zero is at machine X " + mm(off[0]) + " Y " + mm(off[1]) +
             "; set it elsewhere with 'atelierctl laser origin' or start from bed)";
      break;
    case StartFrom::here:
      out += " (start from here: the head is at machine X " + mm(off[0]) + " Y " + mm(off[1]) +
             "; jog it elsewhere or start from bed)";
      break;
  }
  return out;
}

}  // namespace atelier::grbl

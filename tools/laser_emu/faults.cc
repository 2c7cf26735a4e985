#include "tools/laser_emu/faults.h"

#include <cstdlib>

namespace atelier::laser_emu {
namespace {

bool parse_long(const std::string& s, long& out) {
  if (s.empty()) return false;
  char* end = nullptr;
  out = std::strtol(s.c_str(), &end, 10);
  return end && *end == '\0';
}

bool parse_positive(const std::string& s, double& out) {
  if (s.empty()) return false;
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return end && *end == '\0' && out > 0;
}

}  // namespace

std::string apply_fault(const std::string& spec, Faults& faults) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos)
    return "--fault " + spec + ": expected NAME=VALUE (drop-at-line=N, stall-at-line=N, alarm-at-line=N[:CODE])";
  const std::string name = spec.substr(0, eq), value = spec.substr(eq + 1);
  long line = 0;
  if (name == "drop-at-line" || name == "stall-at-line") {
    if (!parse_long(value, line) || line < 1) return "--fault " + spec + ": N must be a line number >= 1";
    (name == "drop-at-line" ? faults.drop_at_line : faults.stall_at_line) = line;
    return "";
  }
  if (name == "alarm-at-line") {
    const auto colon = value.find(':');
    long code = 1;
    if (!parse_long(value.substr(0, colon), line) || line < 1)
      return "--fault " + spec + ": N must be a line number >= 1";
    if (colon != std::string::npos && (!parse_long(value.substr(colon + 1), code) || code < 1 || code > 10))
      return "--fault " + spec + ": CODE must be a GRBL alarm code 1..10";
    faults.alarm_at_line = line;
    faults.alarm_code = static_cast<int>(code);
    return "";
  }
  return "--fault " + spec + ": unknown fault '" + name + "' (drop-at-line, stall-at-line, alarm-at-line)";
}

std::optional<std::pair<double, double>> parse_work_area(const std::string& text) {
  const auto x = text.find_first_of("xX");
  if (x == std::string::npos) return std::nullopt;
  double w = 0, h = 0;
  if (!parse_positive(text.substr(0, x), w) || !parse_positive(text.substr(x + 1), h)) return std::nullopt;
  return std::make_pair(w, h);
}

}  // namespace atelier::laser_emu

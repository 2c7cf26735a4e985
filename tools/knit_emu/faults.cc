#include "tools/knit_emu/faults.h"

#include <charconv>

namespace atelier::knit_emu {
namespace {

// Whole-string integer parse; false on junk, overflow or a value below `min`.
bool parse_int(const std::string& s, int64_t min, int64_t& out) {
  const char* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, out);
  return ec == std::errc() && p == end && out >= min;
}

}  // namespace

std::string apply_fault(const std::string& spec, Faults& f) {
  const std::string where = "--fault " + spec + ": ";
  if (spec == "no-dtr-reset") {
    f.dtr_reset = false;
    return "";
  }
  if (spec == "impatient-knitter") {
    f.impatient_knitter = true;
    return "";
  }
  const auto eq = spec.find('=');
  if (eq == std::string::npos) return where + "expected NAME=VALUE";
  const std::string name = spec.substr(0, eq), value = spec.substr(eq + 1);
  int64_t n = 0;
  if (name == "drop-after-row") {
    const auto colon = value.find(':');
    if (!parse_int(value.substr(0, colon), 1, n)) return where + "row must be an integer >= 1";
    f.drop_after_row = static_cast<int>(n);
    if (colon != std::string::npos) {
      if (!parse_int(value.substr(colon + 1), 0, n)) return where + "replug delay must be ms >= 0";
      f.replug_ms = n;
    }
    return "";
  }
  if (name == "replug-ms") {
    if (!parse_int(value, 0, n)) return where + "replug delay must be ms >= 0";
    f.replug_ms = n;
    return "";
  }
  if (name == "corrupt") {
    size_t used = 0;
    double v = -1;
    try {
      v = std::stod(value, &used);
    } catch (const std::exception&) {
      return where + "fraction must be a number in [0,1]";
    }
    if (used != value.size() || !(v >= 0.0 && v <= 1.0)) return where + "fraction must be in [0,1]";
    f.corrupt = v;
    return "";
  }
  if (name == "seed") {
    if (!parse_int(value, 0, n)) return where + "seed must be an integer >= 0";
    f.seed = static_cast<uint64_t>(n);
    return "";
  }
  if (name == "silent-after-row") {
    if (!parse_int(value, 0, n)) return where + "row must be an integer >= 0";
    f.silent_after_row = static_cast<int>(n);
    return "";
  }
  if (name == "corrupt-line") {
    if (!parse_int(value, 1, n) || n > 1000000000) return where + "line count must be an integer >= 1";
    f.corrupt_line = static_cast<int>(n);
    return "";
  }
  if (name == "bad-escape-after-row") {
    if (!parse_int(value, 0, n) || n > 1000000000) return where + "row must be an integer >= 0";
    f.bad_escape_after_row = static_cast<int>(n);
    return "";
  }
  if (name == "knitter-pause-ms") {
    if (!parse_int(value, 0, n)) return where + "pause must be ms >= 0";
    f.knitter_pause_ms = n;
    return "";
  }
  if (name == "knitter-patience-ms") {
    if (!parse_int(value, 0, n)) return where + "patience must be ms >= 0";
    f.knitter_patience_ms = n;
    return "";
  }
  if (name == "api") {
    if (!parse_int(value, 0, n) || n > 255) return where + "API version must be 0..255";
    f.api = static_cast<uint8_t>(n);
    return "";
  }
  if (name == "delay-ms") {
    if (!parse_int(value, 0, n)) return where + "delay must be ms >= 0";
    f.delay_ms = n;
    return "";
  }
  return where +
         "unknown fault (drop-after-row, replug-ms, corrupt, seed, corrupt-line, bad-escape-after-row, "
         "silent-after-row, api, delay-ms, no-dtr-reset, knitter-pause-ms, knitter-patience-ms, impatient-knitter)";
}

}  // namespace atelier::knit_emu

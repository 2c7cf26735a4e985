#include "drivers/grbl/messages.h"

#include <charconv>
#include <vector>

namespace atelier::grbl {
namespace {

bool starts_with(std::string_view s, std::string_view p) { return s.substr(0, p.size()) == p; }

std::optional<int> to_int(std::string_view s) {
  int v = 0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return v;
}

std::optional<double> to_double(std::string_view s) {
  double v = 0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

std::vector<std::string_view> split(std::string_view s, char sep) {
  std::vector<std::string_view> out;
  for (;;) {
    const size_t p = s.find(sep);
    out.push_back(s.substr(0, p));
    if (p == std::string_view::npos) return out;
    s.remove_prefix(p + 1);
  }
}

// "1.000,-2.5,0" -> three numbers.
std::optional<std::array<double, 3>> triple(std::string_view s) {
  const auto parts = split(s, ',');
  if (parts.size() < 3) return std::nullopt;
  std::array<double, 3> v{};
  for (int i = 0; i < 3; ++i) {
    auto d = to_double(parts[i]);
    if (!d) return std::nullopt;
    v[i] = *d;
  }
  return v;
}

void set_xyz(Status& s, const std::array<double, 3>& v) {
  s.x = v[0];
  s.y = v[1];
  s.z = v[2];
}

}  // namespace

Reply classify(std::string_view line) {
  // Tolerate a stray '\r' (the caller splits on '\n') and leading boot noise.
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.remove_suffix(1);
  Reply r;
  if (line == "ok") {
    r.kind = Reply::ok;
  } else if (starts_with(line, "error:")) {
    r.kind = Reply::error;
    r.code = to_int(line.substr(6)).value_or(0);
  } else if (starts_with(line, "ALARM:")) {
    r.kind = Reply::alarm;
    r.code = to_int(line.substr(6)).value_or(0);
  } else if (line.size() >= 2 && line.front() == '<' && line.back() == '>') {
    r.kind = Reply::status;
    r.text = std::string(line);
  } else if (line.size() >= 2 && line.front() == '[' && line.back() == ']') {
    r.kind = Reply::feedback;
    r.text = std::string(line.substr(1, line.size() - 2));
  } else if (auto s = parse_setting(line)) {
    r.kind = Reply::setting;
    r.code = s->first;
    r.text = std::string(line.substr(line.find('=') + 1));
  } else if (starts_with(line, ">") && (line.find(":ok") != std::string_view::npos ||
                                         line.find(":error:") != std::string_view::npos)) {
    r.kind = Reply::startup;
    r.text = std::string(line);
  } else if (const size_t g = line.find("Grbl "); g != std::string_view::npos &&
                                                  line.find("['$' for help]") != std::string_view::npos) {
    // The banner; noise may precede it on the same line right after the board resets.
    r.kind = Reply::banner;
    std::string_view v = line.substr(g + 5);
    r.text = std::string(v.substr(0, v.find(' ')));
  } else {
    r.kind = Reply::other;
    r.text = std::string(line);
  }
  return r;
}

std::optional<Status> parse_status(std::string_view line) {
  while (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  if (line.size() < 3 || line.front() != '<' || line.back() != '>') return std::nullopt;
  const auto fields = split(line.substr(1, line.size() - 2), '|');
  Status s;
  const std::string_view state = fields[0];
  const size_t colon = state.find(':');
  s.state = std::string(state.substr(0, colon));
  if (s.state.empty()) return std::nullopt;
  if (colon != std::string_view::npos) s.substate = to_int(state.substr(colon + 1)).value_or(-1);
  std::optional<std::array<double, 3>> wpos;
  for (size_t i = 1; i < fields.size(); ++i) {
    const std::string_view f = fields[i];
    const size_t c = f.find(':');
    if (c == std::string_view::npos) continue;
    const std::string_view key = f.substr(0, c), value = f.substr(c + 1);
    if (key == "MPos") {
      if (auto v = triple(value)) set_xyz(s, *v);
    } else if (key == "WPos") {
      wpos = triple(value);
    } else if (key == "WCO") {
      s.wco = triple(value);
    } else if (key == "FS" || key == "F") {
      const auto parts = split(value, ',');
      s.feed = to_double(parts[0]).value_or(0);
      if (parts.size() > 1) s.spindle = to_double(parts[1]).value_or(0);
    } else if (key == "Bf") {
      const auto parts = split(value, ',');
      if (parts.size() == 2) {
        s.planner_free = to_int(parts[0]).value_or(-1);
        s.rx_free = to_int(parts[1]).value_or(-1);
      }
    } else if (key == "Ln") {
      s.line = to_int(value).value_or(-1);
    }
  }
  if (wpos) {
    set_xyz(s, *wpos);
    s.has_wpos = true;
    if (s.wco) apply_wco(s, *s.wco);
  }
  return s;
}

void apply_wco(Status& s, const std::array<double, 3>& wco) {
  if (!s.has_wpos) return;
  // GRBL: WPos = MPos - WCO.
  s.x += wco[0];
  s.y += wco[1];
  s.z += wco[2];
  s.has_wpos = false;
}

std::optional<std::pair<int, int>> parse_opt(std::string_view line) {
  while (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  if (!starts_with(line, "[OPT:") || line.back() != ']') return std::nullopt;
  const auto parts = split(line.substr(5, line.size() - 6), ',');
  // "[OPT:codes,blocks,bytes]"; GRBL 1.1 before 1.1d printed only the codes.
  if (parts.size() < 3) return std::nullopt;
  auto blocks = to_int(parts[1]);
  auto bytes = to_int(parts[2]);
  if (!blocks || !bytes || *blocks <= 0 || *bytes <= 0) return std::nullopt;
  return std::pair(*blocks, *bytes);
}

std::optional<std::pair<int, double>> parse_setting(std::string_view line) {
  while (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  if (!starts_with(line, "$")) return std::nullopt;
  const size_t eq = line.find('=');
  if (eq == std::string_view::npos) return std::nullopt;
  auto n = to_int(line.substr(1, eq - 1));
  // GRBL 1.0 and earlier appended " (description)"; 1.1 prints the bare value.
  std::string_view value = line.substr(eq + 1);
  value = value.substr(0, value.find(' '));
  auto v = to_double(value);
  if (!n || !v) return std::nullopt;
  return std::pair(*n, *v);
}

}  // namespace atelier::grbl

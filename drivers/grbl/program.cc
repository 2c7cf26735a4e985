#include "drivers/grbl/program.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "base/error.h"
#include "algorithms/laser/motion_planner.h"

namespace atelier::grbl {
namespace {

constexpr double kPi = 3.14159265358979323846;

[[noreturn]] void fail(int line, const std::string& what) {
  throw BadInput("line " + std::to_string(line) + ": " + what);
}

std::string hex_byte(unsigned char c) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", c);
  return buf;
}

// One source line split the way GRBL's protocol loop does it: what it would execute, and
// the comment text (for header keys).
struct Stripped {
  std::string code;
  std::string comment;
};

Stripped strip(std::string_view raw, int line_no) {
  Stripped s;
  bool paren = false, semicolon = false;
  for (const char ch : raw) {
    const auto c = static_cast<unsigned char>(ch);
    if (semicolon || paren) {
      if (paren && c == ')') paren = false;
      else s.comment += ch;
      continue;
    }
    if (c == '(') {
      paren = true;
      s.comment += ' ';
    } else if (c == ';') {
      semicolon = true;
      s.comment += ' ';
    } else if (c >= 0x80) {
      fail(line_no, "byte " + hex_byte(c) + " outside a comment: GRBL reads 0x80-0xFF as real-time commands");
    } else if (c == '?' || c == '!' || c == '~') {
      fail(line_no, std::string("'") + ch + "' outside a comment: GRBL reads it as a real-time command");
    } else if (c <= ' ' || c == '/') {
      // GRBL drops spaces, control characters and the (unsupported) block-delete slash.
    } else {
      s.code += static_cast<char>(std::toupper(c));
    }
  }
  return s;
}

std::optional<double> number(std::string_view s) {
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double v = 0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty() || !std::isfinite(v)) return std::nullopt;
  return v;
}

// "key=value" pairs of a header comment, e.g. " s_max=1000 bounds=0,0,100,50".
void read_header(const std::string& comment, int line_no, Program& p) {
  std::string text = comment;
  for (char& c : text)
    if (c == '\t') c = ' ';
  size_t pos = 0;
  while ((pos = text.find('=', pos)) != std::string::npos) {
    size_t k = pos;
    while (k > 0 && text[k - 1] == ' ') --k;
    size_t kb = k;
    while (kb > 0 && (std::isalnum(static_cast<unsigned char>(text[kb - 1])) || text[kb - 1] == '_')) --kb;
    std::string key = text.substr(kb, k - kb);
    for (char& c : key) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    size_t vb = pos + 1;
    while (vb < text.size() && text[vb] == ' ') ++vb;
    size_t ve = vb;
    while (ve < text.size() && text[ve] != ' ') ++ve;
    const std::string value = text.substr(vb, ve - vb);
    pos = ve;
    if (key == "s_max") {
      auto v = number(value);
      if (!v || *v <= 0) fail(line_no, "header s_max=" + value + " is not a positive number");
      p.s_max = *v;
    } else if (key == "bounds") {
      std::array<double, 4> v{};
      size_t from = 0;
      for (int i = 0; i < 4; ++i) {
        const size_t comma = value.find(',', from);
        if ((i < 3) != (comma != std::string::npos)) fail(line_no, "header bounds=" + value + " is not min_x,min_y,max_x,max_y");
        auto d = number(std::string_view(value).substr(from, comma == std::string::npos ? std::string::npos : comma - from));
        if (!d) fail(line_no, "header bounds=" + value + " is not min_x,min_y,max_x,max_y");
        v[i] = *d;
        from = comma + 1;
      }
      if (v[0] > v[2] || v[1] > v[3]) fail(line_no, "header bounds=" + value + ": a minimum exceeds its maximum");
      p.bounds = Bounds{v[0], v[1], v[2], v[3]};
    }
  }
}

// The G-code words of one stripped line ("G1X10Y-2.5F600"): letter and value.
struct Word {
  char letter;
  double value;
};
std::vector<Word> words(const std::string& code) {
  std::vector<Word> out;
  size_t i = 0;
  while (i < code.size()) {
    const char letter = code[i++];
    size_t j = i;
    while (j < code.size() && (std::isdigit(static_cast<unsigned char>(code[j])) || code[j] == '.' || code[j] == '-' ||
                               code[j] == '+'))
      ++j;
    // Malformed words are GRBL's to refuse (error:1/2); the estimate just skips them.
    if (auto v = number(std::string_view(code).substr(i, j - i)); v && std::isalpha(static_cast<unsigned char>(letter)))
      out.push_back({letter, *v});
    i = j;
  }
  return out;
}

// Modal state followed for the estimate and the extent.
struct Machine {
  std::array<double, 3> pos{0, 0, 0};  // mm, work coordinates
  int motion = 0;                      // 0, 1, 2, 3; -1 after G80
  bool absolute = true;
  double unit = 1;   // mm per program unit (25.4 under G20)
  double feed = 0;   // mm/min
  int spindle = 5;   // 3, 4 or 5 (M5: off)
  double s_word = 0;
  bool sync_pending = false;  // a buffer sync since the last move: the next move starts at rest
  std::optional<Bounds> extent;
  std::vector<laser::PlannedMove> moves;  // every move so far, for the planner model

  void include(double x, double y) {
    if (!extent) extent = Bounds{x, y, x, y};
    extent->min_x = std::min(extent->min_x, x);
    extent->min_y = std::min(extent->min_y, y);
    extent->max_x = std::max(extent->max_x, x);
    extent->max_y = std::max(extent->max_y, y);
  }
};

bool is(double v, double g) { return std::fabs(v - g) < 1e-6; }

// GRBL's mc_arc(): the number of straight segments an arc of `radius` sweeping `sweep`
// radians is cut into for the arc tolerance $12 (default 0.002 mm).
int arc_segments(double radius, double sweep) {
  constexpr double kArcTolerance = 0.002;
  if (!(radius > kArcTolerance)) return 1;
  const double seg = std::floor(std::fabs(0.5 * sweep * radius) / std::sqrt(kArcTolerance * (2 * radius - kArcTolerance)));
  return std::max(1, static_cast<int>(std::min(seg, 100000.0)));
}

void add_move(Machine& m, const std::array<double, 3>& to, bool rapid, double feed) {
  laser::PlannedMove mv;
  mv.target = to;
  mv.rapid = rapid;
  mv.feed_mm_min = feed;
  mv.from_rest = m.sync_pending;
  m.sync_pending = false;
  m.moves.push_back(mv);
}

// Runs one line on the modal state: appends its moves to m.moves; returns its dwell seconds.
double run(Machine& m, const std::vector<Word>& ws) {
  std::optional<double> ax[3], off[2], r, p, s_word;
  bool non_modal_axes = false, dwell = false, sync = false;
  std::optional<int> motion, spindle;
  for (const Word& w : ws) {
    switch (w.letter) {
      case 'G':
        if (is(w.value, 0) || is(w.value, 1) || is(w.value, 2) || is(w.value, 3)) motion = static_cast<int>(w.value);
        else if (is(w.value, 80)) motion = -1;
        else if (is(w.value, 90)) m.absolute = true;
        else if (is(w.value, 91)) m.absolute = false;
        else if (is(w.value, 20)) m.unit = 25.4;
        else if (is(w.value, 21)) m.unit = 1;
        else if (is(w.value, 4)) dwell = true;
        // G10/G28/G30/G53/G92 use axis words for something other than a move in work
        // coordinates: left out of the estimate and the extent.
        else if (is(w.value, 10) || is(w.value, 28) || is(w.value, 30) || is(w.value, 53) || is(w.value, 92) ||
                 is(w.value, 28.1) || is(w.value, 30.1) || is(w.value, 92.1))
          non_modal_axes = true;
        break;
      case 'X': ax[0] = w.value; break;
      case 'Y': ax[1] = w.value; break;
      case 'Z': ax[2] = w.value; break;
      case 'I': off[0] = w.value; break;
      case 'J': off[1] = w.value; break;
      case 'R': r = w.value; break;
      case 'P': p = w.value; break;
      case 'F': m.feed = w.value; break;  // unit applied below: F follows G20/G21 of its line
      case 'S': s_word = w.value; break;
      case 'M':
        if (is(w.value, 3) || is(w.value, 4) || is(w.value, 5)) spindle = static_cast<int>(w.value);
        // Program stops and ends wait for the planner to empty.
        else if (is(w.value, 0) || is(w.value, 1) || is(w.value, 2) || is(w.value, 30)) sync = true;
        break;
      default: break;
    }
  }
  double seconds = 0;
  if (dwell && p) seconds += std::max(0.0, *p);
  if (motion) m.motion = *motion;
  const bool moves = !non_modal_axes && (ax[0] || ax[1] || ax[2]) && m.motion >= 0;
  // Buffer syncs (gcode.c): every spindle state change, in laser mode an S change on a line
  // without motion, dwells, program stops, G10 (an EEPROM write) and the other non-modal
  // position commands.
  if (spindle && *spindle != m.spindle) sync = true;
  if (s_word && *s_word != m.s_word && !moves && m.spindle != 5) sync = true;
  if (dwell || non_modal_axes) sync = true;
  if (spindle) m.spindle = *spindle;
  if (s_word) m.s_word = *s_word;
  if (sync) m.sync_pending = true;
  if (!moves) return seconds;

  const std::array<double, 3> from = m.pos;
  std::array<double, 3> to = from;
  for (int i = 0; i < 3; ++i)
    if (ax[i]) to[i] = m.absolute ? *ax[i] * m.unit : from[i] + *ax[i] * m.unit;
  const double feed = m.feed * m.unit;

  if (m.motion == 2 || m.motion == 3) {
    // The arc in the XY plane as GRBL's gcode.c constructs it (centre from I/J or R).
    const double x = to[0] - from[0], y = to[1] - from[1];
    double i = off[0].value_or(0) * m.unit, j = off[1].value_or(0) * m.unit;
    if (r) {
      double rr = *r * m.unit;
      double h = 4 * rr * rr - x * x - y * y;
      if (h < 0 || (x == 0 && y == 0)) h = 0;
      double h_div_d = -std::sqrt(h) / std::hypot(x, y);
      if (!std::isfinite(h_div_d)) h_div_d = 0;
      if (m.motion == 3) h_div_d = -h_div_d;
      if (rr < 0) h_div_d = -h_div_d;
      i = 0.5 * (x - y * h_div_d);
      j = 0.5 * (y + x * h_div_d);
    }
    const double cx = from[0] + i, cy = from[1] + j;
    const double r0x = -i, r0y = -j, r1x = to[0] - cx, r1y = to[1] - cy;
    const double radius = std::hypot(r0x, r0y);
    double sweep = std::atan2(r0x * r1y - r0y * r1x, r0x * r1x + r0y * r1y);
    if (m.motion == 2 && sweep >= -1e-9) sweep -= 2 * kPi;
    if (m.motion == 3 && sweep <= 1e-9) sweep += 2 * kPi;
    const double a0 = std::atan2(r0y, r0x);
    const int segments = arc_segments(radius, sweep);
    for (int k = 1; k < segments; ++k) {
      const double a = a0 + sweep * k / segments;
      add_move(m, {cx + radius * std::cos(a), cy + radius * std::sin(a), from[2] + (to[2] - from[2]) * k / segments},
               false, feed);
    }
    constexpr int kSamples = 72;
    for (int k = 1; k < kSamples; ++k) {
      const double a = a0 + sweep * k / kSamples;
      m.include(cx + radius * std::cos(a), cy + radius * std::sin(a));
    }
    // Exact extremes where the arc crosses an axis direction.
    for (int q = -8; q <= 8; ++q) {
      const double a = q * kPi / 2;
      const double t = (a - a0) / sweep;
      if (t > 0 && t < 1) m.include(cx + radius * std::cos(a), cy + radius * std::sin(a));
    }
  }
  m.include(to[0], to[1]);
  m.pos = to;
  add_move(m, to, m.motion == 0, feed);
  return seconds;
}

std::string mm(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  std::string s = buf;
  s.erase(s.find_last_not_of('0') + 1);
  if (s.back() == '.') s.pop_back();
  if (s == "-0") s = "0";
  return s;
}

std::string trim_spaces(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

}  // namespace

double Program::total_seconds() const { return std::accumulate(seconds.begin(), seconds.end(), 0.0); }

Program parse_program(std::string_view gcode, double rapid_mm_min) {
  laser::MotionSettings settings;
  if (rapid_mm_min > 0) settings.max_rate_mm_min = {rapid_mm_min, rapid_mm_min, rapid_mm_min};
  return parse_program(gcode, settings);
}

Program parse_program(std::string_view gcode, const laser::MotionSettings& settings) {
  Program p;
  Machine m;
  std::vector<size_t> moves_before;  // m.moves.size() before lines[i] ran
  int line_no = 0;
  bool header = true;  // before the first line that is sent
  std::string last_comment;  // for the note of a program pause (M0)
  size_t start = 0;
  while (start <= gcode.size()) {
    size_t end = gcode.find('\n', start);
    if (end == std::string_view::npos) end = gcode.size();
    std::string_view raw = gcode.substr(start, end - start);
    start = end + 1;
    ++line_no;
    if (!raw.empty() && raw.back() == '\r') raw.remove_suffix(1);
    if (raw.empty() && start > gcode.size()) break;  // the final newline ends the file

    Stripped s = strip(raw, line_no);
    if (!s.comment.empty()) last_comment = trim_spaces(s.comment);
    if (s.code.empty() || s.code == "%") {
      if (header && !s.comment.empty()) read_header(s.comment, line_no, p);
      continue;
    }
    header = false;
    if (s.code.size() > kMaxLineChars)
      fail(line_no, "longer than " + std::to_string(kMaxLineChars) + " characters once spaces and comments are removed (" +
                        std::to_string(s.code.size()) + "); GRBL's line buffer would overflow (error:11)");
    if (s.code.front() == '$')
      fail(line_no, "'" + s.code + "' is a GRBL system command; jobs may only contain G-code (send settings separately)");
    const std::vector<Word> ws = words(s.code);
    if (std::any_of(ws.begin(), ws.end(), [](const Word& w) { return w.letter == 'M' && is(w.value, 0); }))
      p.pauses[p.lines.size()] = last_comment;
    moves_before.push_back(m.moves.size());
    p.seconds.push_back(run(m, ws));
    p.lines.push_back(std::move(s.code));
    p.source_line.push_back(line_no);
    p.source_text.emplace_back(raw);
  }
  if (!p.bounds) p.bounds = m.extent;
  // Each line's moves timed by GRBL's planner; a line's time is its moves' plus its dwell.
  const std::vector<double> move_s = laser::move_seconds(m.moves, settings);
  for (size_t i = 0; i < p.seconds.size(); ++i) {
    const size_t end = i + 1 < moves_before.size() ? moves_before[i + 1] : move_s.size();
    for (size_t k = moves_before[i]; k < end; ++k) p.seconds[i] += move_s[k];
  }
  return p;
}

Program frame_program(const Bounds& b, double feed_mm_min, double rapid_mm_min) {
  if (!(feed_mm_min > 0)) throw std::invalid_argument("frame_program: feed must be positive");
  const std::string f = mm(feed_mm_min);
  std::string text = "; bounds=" + mm(b.min_x) + "," + mm(b.min_y) + "," + mm(b.max_x) + "," + mm(b.max_y) + "\n";
  text += "M5\nG90 G21\n";
  text += "G0 X" + mm(b.min_x) + " Y" + mm(b.min_y) + "\n";
  text += "G1 X" + mm(b.max_x) + " Y" + mm(b.min_y) + " F" + f + " S0\n";
  text += "G1 X" + mm(b.max_x) + " Y" + mm(b.max_y) + "\n";
  text += "G1 X" + mm(b.min_x) + " Y" + mm(b.max_y) + "\n";
  text += "G1 X" + mm(b.min_x) + " Y" + mm(b.min_y) + "\n";
  text += "G4 P0.01\n";
  return parse_program(text, rapid_mm_min > 0 ? rapid_mm_min : feed_mm_min);
}

}  // namespace atelier::grbl

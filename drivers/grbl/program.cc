#include "drivers/grbl/program.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "base/error.h"

namespace atelier::grbl {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kArcToleranceMm = 0.002;  // GRBL's $12 default (DEFAULT_ARC_TOLERANCE)

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
  double s = 0;      // spindle speed word (laser power)
  int spindle = 5;   // 3 (M3), 4 (M4) or 5 (M5)
  std::optional<Bounds> extent;
  // The moves GRBL's planner receives (arcs as mc_arc segments them), each tied to its line.
  std::vector<laser::PlannedMove> moves;
  std::vector<size_t> move_line;
  bool sync = false;  // GRBL emptied the planner since the last move

  void include(double x, double y) {
    if (!extent) extent = Bounds{x, y, x, y};
    extent->min_x = std::min(extent->min_x, x);
    extent->min_y = std::min(extent->min_y, y);
    extent->max_x = std::max(extent->max_x, x);
    extent->max_y = std::max(extent->max_y, y);
  }
  void move(const std::array<double, 3>& to, double feed_mm_min, bool rapid, size_t line) {
    moves.push_back({to, feed_mm_min, rapid, sync});
    move_line.push_back(line);
    sync = false;
  }
};

bool is(double v, double g) { return std::fabs(v - g) < 1e-6; }
bool feed_mode(int motion) { return motion >= 1 && motion <= 3; }

// Runs line `line` (index into Program::lines) on the modal state: its moves go to m.moves;
// returns its dwell seconds. Laser mode ($32=1) rules of GRBL 1.1h's gcode.c decide where
// the planner is synchronised (emptied, so the head stops): an M3/M4/M5 change, an S change
// on a line without motion while the laser is on, an M3 line without motion that leaves or
// enters G1/G2/G3, G4, M0/M1/M2/M30, and (mc_line) a zero-length move under M3.
double run(Machine& m, const std::vector<Word>& ws, size_t line, double arc_tolerance_mm) {
  std::optional<double> ax[3], off[2], r, p, s_word;
  bool non_modal_axes = false, dwell = false, flow = false;
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
      case 'M':
        if (is(w.value, 3) || is(w.value, 4) || is(w.value, 5)) spindle = static_cast<int>(w.value);
        else if (is(w.value, 0) || is(w.value, 1) || is(w.value, 2) || is(w.value, 30)) flow = true;
        break;
      case 'X': ax[0] = w.value; break;
      case 'Y': ax[1] = w.value; break;
      case 'Z': ax[2] = w.value; break;
      case 'I': off[0] = w.value; break;
      case 'J': off[1] = w.value; break;
      case 'R': r = w.value; break;
      case 'P': p = w.value; break;
      case 'S': s_word = w.value; break;
      case 'F': m.feed = w.value; break;  // unit applied below: F follows G20/G21 of its line
      default: break;
    }
  }
  const int new_motion = motion.value_or(m.motion);
  const bool axis_motion = (ax[0] || ax[1] || ax[2]) && !non_modal_axes && new_motion >= 0;
  // gcode.c [4.]: S changes (or M3's forced sync) while the laser is on sync unless the line moves.
  const bool force_sync = m.spindle == 3 && !axis_motion && feed_mode(m.motion) != feed_mode(new_motion);
  if ((s_word && *s_word != m.s) || force_sync) {
    if (m.spindle != 5 && !axis_motion) m.sync = true;
    if (s_word) m.s = *s_word;
  }
  // [7.] a spindle state change always syncs.
  if (spindle && *spindle != m.spindle) {
    m.sync = true;
    m.spindle = *spindle;
  }
  double seconds = 0;
  if (dwell) m.sync = true;  // mc_dwell: protocol_buffer_synchronize, then the delay
  if (dwell && p) seconds += std::max(0.0, *p);
  m.motion = new_motion;
  if (!axis_motion) {
    if (flow) m.sync = true;
    return seconds;
  }

  const std::array<double, 3> from = m.pos;
  std::array<double, 3> to = from;
  for (int i = 0; i < 3; ++i)
    if (ax[i]) to[i] = m.absolute ? *ax[i] * m.unit : from[i] + *ax[i] * m.unit;
  const double feed = m.feed * m.unit;
  const bool rapid = m.motion == 0;
  // A feed move without a feed is GRBL's error:22: nothing moves, nothing to time.
  const bool timed = rapid || feed > 0;

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
    // motion_control.c mc_arc: chords whose sagitta stays within the arc tolerance ($12).
    const double tol = arc_tolerance_mm;
    const double chord = std::sqrt(std::max(0.0, tol * (2 * radius - tol)));
    const int segments = chord > 0 ? static_cast<int>(std::floor(std::fabs(0.5 * sweep * radius) / chord)) : 0;
    for (int k = 1; timed && k < segments; ++k) {
      const double a = a0 + sweep * k / segments;
      m.move({cx + radius * std::cos(a), cy + radius * std::sin(a), from[2] + (to[2] - from[2]) * k / segments},
             feed, false, line);
    }
  }
  m.include(to[0], to[1]);
  m.pos = to;
  if (timed) {
    // mc_line: in laser mode a zero-length move under M3 syncs (it never enters the planner).
    const bool empty = to == from && m.motion <= 1;
    if (empty && m.spindle == 3) m.sync = true;
    else m.move(to, feed, rapid, line);
  }
  if (flow) m.sync = true;  // [21.] program flow after the line's motion
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

Program parse_program(std::string_view gcode, const laser::MotionSettings& motion) {
  Program p;
  Machine m;
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
    p.seconds.push_back(run(m, ws, p.lines.size(), kArcToleranceMm));
    p.lines.push_back(std::move(s.code));
    p.source_line.push_back(line_no);
    p.source_text.emplace_back(raw);
  }
  if (!p.bounds) p.bounds = m.extent;
  // GRBL's planner and stepper over the whole stream: each move's time goes to its line.
  const std::vector<double> t = laser::move_seconds(m.moves, motion);
  for (size_t k = 0; k < t.size(); ++k) p.seconds[m.move_line[k]] += t[k];
  return p;
}

Program parse_program(std::string_view gcode, double rapid_mm_min) {
  laser::MotionSettings motion;
  if (rapid_mm_min > 0) motion.max_rate_mm_min[0] = motion.max_rate_mm_min[1] = rapid_mm_min;
  return parse_program(gcode, motion);
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

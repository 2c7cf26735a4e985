#include "tools/laser_emu/gcode.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>

namespace atelier::laser_emu {
namespace {

// GRBL status codes used here (report.h / doc/csv/error_codes_en_US.csv).
enum : int {
  kOk = 0, kExpectedCommandLetter = 1, kBadNumberFormat = 2, kNegativeValue = 4,
  kUnsupportedCommand = 20, kModalGroupViolation = 21, kUndefinedFeedRate = 22,
  kCommandValueNotInteger = 23, kAxisCommandConflict = 24, kWordRepeated = 25,
  kNoAxisWords = 26, kInvalidLineNumber = 27, kValueWordMissing = 28,
  kG53InvalidMotionMode = 30, kAxisWordsExist = 31, kNoAxisWordsInPlane = 32,
  kInvalidTarget = 33, kArcRadiusError = 34, kNoOffsetsInPlane = 35, kUnusedWords = 36,
  kMaxValueExceeded = 38, kUnsupportedCoordSys = 29, kG43DynamicAxisError = 37,
  kInvalidJogCommand = 16,
};

constexpr double kMmPerInch = 25.4;
constexpr double kMaxLineNumber = 10000000.0;  // GRBL: N <= 9999999
constexpr double kArcAngularEpsilon = 5e-7;
constexpr double kMaxCommandNumber = 255;  // GRBL reads G/M numbers into a uint8
constexpr double kMaxArcSegments = 65535;  // GRBL counts arc chords in a uint16

// Modal groups (bit numbers as in gcode.h) and value words.
enum ModalGroup { G0 = 0, G1, G2, G3, G4, G5, G6, G7, G8, G12, G13, M4, M7, M8 };
enum Word { F = 0, I, J, K, L, N, P, R, S, T, X, Y, Z };

enum class AxisCommand { none, non_modal, motion, tool_length };
enum class NonModal { none, dwell, absolute_override, set_offset, reset_offset, set_coord_data, go_home, set_home };

}  // namespace

bool read_grbl_float(const std::string& line, size_t& pos, double& value) {
  constexpr int kMaxIntDigits = 8;  // GRBL's MAX_INT_DIGITS: digits kept in its uint32
  size_t p = pos;
  bool negative = false;
  if (p < line.size() && (line[p] == '-' || line[p] == '+')) negative = line[p++] == '-';
  uint32_t intval = 0;
  int exp = 0, ndigit = 0;
  bool decimal = false;
  for (; p < line.size(); ++p) {
    const char c = line[p];
    if (c >= '0' && c <= '9') {
      ++ndigit;
      if (ndigit <= kMaxIntDigits) {
        if (decimal) --exp;
        intval = intval * 10 + static_cast<uint32_t>(c - '0');
      } else if (!decimal) {
        ++exp;  // a dropped integer digit still counts
      }
    } else if (c == '.' && !decimal) {
      decimal = true;
    } else {
      break;
    }
  }
  if (ndigit == 0) return false;
  const double v = static_cast<double>(intval) * std::pow(10.0, exp);
  if (!(v <= std::numeric_limits<float>::max())) return false;
  value = negative ? -v : v;
  pos = p;
  return true;
}

std::string GcState::modes_report(bool report_inches) const {
  std::string out = "[GC:G" + std::to_string(motion);
  out += " G" + std::to_string(54 + coord_select);
  out += " G" + std::to_string(17 + plane);
  out += inches ? " G20" : " G21";
  out += incremental ? " G91" : " G90";
  out += inverse_time ? " G93" : " G94";
  out += spindle == Spindle::cw ? " M3" : spindle == Spindle::ccw ? " M4" : " M5";
  if (mist) out += " M7";
  if (flood) out += " M8";
  if (!mist && !flood) out += " M9";
  char buf[64];
  // F is printed in the report units (printFloat_RateValue), S with no decimals.
  std::snprintf(buf, sizeof buf, " T%d F%.*f S%.0f]", tool, report_inches ? 1 : 0,
                report_inches ? feed / kMmPerInch : feed, s);
  return out + buf;
}

LineResult execute_gcode_line(const std::string& line, GcState& state, const Settings& settings, bool jog) {
  auto fail = [](int code) { return LineResult{code, {}}; };
  GcState block = state;  // gc_block.modal starts as a copy of the current modes
  if (jog) {  // GC_PARSER_JOG_MOTION: G1 and G94 enforced for the checks
    block.motion = 1;
    block.inverse_time = false;
  }
  // Values of this block.
  double values[13] = {};
  unsigned value_words = 0, command_words = 0, axis_words = 0, ijk_words = 0;
  AxisCommand axis_command = AxisCommand::none;
  NonModal non_modal = NonModal::none;
  int program_flow = 0;  // 0 running, 1 M0 pause, 2 M2, 30 M30
  int home_index = 6;    // G28: 6, G30: 7 in coord_data
  int tool_length = -1;  // G49: 0, G43.1: 1
  Vec3 xyz{}, ijk{};

  // --- Step 1: read every word, catching modal-group and repeat violations (gc_execute_line).
  size_t pos = 0;
  while (pos < line.size()) {
    const char letter = line[pos];
    if (letter < 'A' || letter > 'Z') return fail(kExpectedCommandLetter);
    ++pos;
    double value = 0;
    if (!read_grbl_float(line, pos, value)) return fail(kBadNumberFormat);
    const double int_value = std::trunc(value);
    // value is finite and below 3.4e38 (read_grbl_float), so this difference is in [0, 1).
    int mantissa = static_cast<int>(std::lround(100 * (value - int_value)));
    int group = -1;
    // G and M numbers are cast to int below: out of GRBL's uint8 range is unsupported.
    if ((letter == 'G' || letter == 'M') && int_value > kMaxCommandNumber) return fail(kUnsupportedCommand);
    if (letter == 'G') {
      if (value < 0) return fail(kUnsupportedCommand);
      switch (static_cast<int>(int_value)) {
        case 4: case 53:
          group = G0;
          non_modal = int_value == 4 ? NonModal::dwell : NonModal::absolute_override;
          break;
        case 92:
          if (mantissa != 0 && mantissa != 10) return fail(kUnsupportedCommand);
          if (mantissa == 0) {
            if (axis_command != AxisCommand::none) return fail(kAxisCommandConflict);
            axis_command = AxisCommand::non_modal;
          }
          group = G0;
          non_modal = mantissa == 0 ? NonModal::set_offset : NonModal::reset_offset;
          mantissa = 0;
          break;
        case 10: case 28: case 30:
          if (int_value == 10 && mantissa != 0) return fail(kUnsupportedCommand);
          if (mantissa != 0 && mantissa != 10) return fail(kUnsupportedCommand);
          if (mantissa == 0) {  // G28.1/G30.1 take axis words as an implicit motion
            if (axis_command != AxisCommand::none) return fail(kAxisCommandConflict);
            axis_command = AxisCommand::non_modal;
          }
          group = G0;
          home_index = int_value == 28 ? 6 : 7;
          non_modal = int_value == 10 ? NonModal::set_coord_data : mantissa == 0 ? NonModal::go_home : NonModal::set_home;
          mantissa = 0;
          break;
        case 43: case 49:
          if (axis_command != AxisCommand::none) return fail(kAxisCommandConflict);
          axis_command = AxisCommand::tool_length;
          if (int_value == 49) tool_length = 0;
          else if (mantissa == 10) tool_length = 1;
          else return fail(kUnsupportedCommand);  // G43 (from a tool table) is not in GRBL
          mantissa = 0;
          group = G8;
          break;
        case 0: case 1: case 2: case 3:
          if (axis_command != AxisCommand::none) return fail(kAxisCommandConflict);
          axis_command = AxisCommand::motion;
          [[fallthrough]];
        case 80:
          group = G1;
          block.motion = static_cast<int>(int_value);
          break;
        case 17: case 18: case 19:
          group = G2;
          block.plane = static_cast<int>(int_value) - 17;
          break;
        case 90: case 91:
          if (mantissa == 0) {
            group = G3;
            block.incremental = int_value == 91;
          } else {
            group = G4;
            if (mantissa != 10 || int_value == 90) return fail(kUnsupportedCommand);  // G90.1
            mantissa = 0;  // G91.1: arc IJK incremental, the default
          }
          break;
        case 93: case 94:
          group = G5;
          block.inverse_time = int_value == 93;
          break;
        case 20: case 21:
          group = G6;
          block.inches = int_value == 20;
          break;
        case 40: group = G7; break;
        case 54: case 55: case 56: case 57: case 58: case 59:
          group = G12;
          block.coord_select = static_cast<int>(int_value) - 54;
          break;
        case 61:
          group = G13;
          if (mantissa != 0) return fail(kUnsupportedCommand);
          break;
        default: return fail(kUnsupportedCommand);  // incl. G10 G28 G30 G38 G43.1 G49 (not emulated)
      }
      if (mantissa > 0) return fail(kCommandValueNotInteger);
      if (command_words & (1u << group)) return fail(kModalGroupViolation);
      command_words |= 1u << group;
    } else if (letter == 'M') {
      if (mantissa > 0) return fail(kCommandValueNotInteger);
      if (value < 0) return fail(kUnsupportedCommand);
      switch (static_cast<int>(int_value)) {
        case 0: case 1: case 2: case 30:
          group = M4;
          if (int_value == 0) program_flow = 1;
          else if (int_value != 1) program_flow = static_cast<int>(int_value);  // M1: optional stop, ignored
          break;
        case 3: case 4: case 5:
          group = M7;
          block.spindle = static_cast<Spindle>(static_cast<int>(int_value));
          break;
        case 8: case 9:  // M7 (mist) only with ENABLE_M7, off in stock 1.1h: error:20
          group = M8;
          if (int_value == 8) block.flood = true;
          else block.mist = block.flood = false;
          break;
        default: return fail(kUnsupportedCommand);
      }
      if (command_words & (1u << group)) return fail(kModalGroupViolation);
      command_words |= 1u << group;
    } else {
      int word = -1;
      switch (letter) {
        case 'F': word = F; break;
        case 'I': word = I; ijk[0] = value; ijk_words |= 1; break;
        case 'J': word = J; ijk[1] = value; ijk_words |= 2; break;
        case 'K': word = K; ijk[2] = value; ijk_words |= 4; break;
        case 'L': word = L; break;
        case 'N': word = N; value = std::trunc(value); break;
        case 'P': word = P; break;
        case 'R': word = R; break;
        case 'S': word = S; break;
        case 'T':
          word = T;
          if (value > 255) return fail(kMaxValueExceeded);
          break;
        case 'X': word = X; xyz[0] = value; axis_words |= 1; break;
        case 'Y': word = Y; xyz[1] = value; axis_words |= 2; break;
        case 'Z': word = Z; xyz[2] = value; axis_words |= 4; break;
        default: return fail(kUnsupportedCommand);
      }
      if (value_words & (1u << word)) return fail(kWordRepeated);
      if ((word == F || word == N || word == P || word == T || word == S) && value < 0) return fail(kNegativeValue);
      value_words |= 1u << word;
      values[word] = value;
    }
  }

  // --- Step 2: error checks, in gcode.c's order.
  if (axis_words && axis_command == AxisCommand::none) axis_command = AxisCommand::motion;
  if ((value_words & (1u << N)) && values[N] >= kMaxLineNumber) return fail(kInvalidLineNumber);

  double feed = values[F];
  if (jog) {  // [2.] a jog needs its own F, in the block's units
    if (!(value_words & (1u << F))) return fail(kUndefinedFeedRate);
    if (block.inches) feed *= kMmPerInch;
  } else if (block.inverse_time) {
    if (axis_command == AxisCommand::motion && block.motion != 80 && block.motion != 0 &&
        !(value_words & (1u << F)))
      return fail(kUndefinedFeedRate);
  } else if (!state.inverse_time) {
    if (value_words & (1u << F)) {
      if (block.inches) feed *= kMmPerInch;
    } else {
      feed = state.feed;
    }
  }  // else: G93 -> G94 in this block: only this block's F counts
  const double s_value = (value_words & (1u << S)) ? values[S] : state.s;
  // [5.] gc_state.tool = gc_block.values.t for every executed line: 0 unless it has a T.
  block.tool = (value_words & (1u << T)) ? static_cast<int>(values[T]) : 0;

  if (non_modal == NonModal::dwell) {
    if (!(value_words & (1u << P))) return fail(kValueWordMissing);
    value_words &= ~(1u << P);
  }

  int axis_0 = 0, axis_1 = 1, axis_linear = 2;
  if (block.plane == 1) axis_0 = 2, axis_1 = 0, axis_linear = 1;
  else if (block.plane == 2) axis_0 = 1, axis_1 = 2, axis_linear = 0;

  if (block.inches)
    for (int i = 0; i < 3; ++i)
      if (axis_words & (1u << i)) xyz[i] *= kMmPerInch;

  // [14.] G43.1 takes exactly a Z word.
  if (axis_command == AxisCommand::tool_length && tool_length == 1 && axis_words != 4u)
    return fail(kG43DynamicAxisError);
  // [15.-19.] Work coordinates: WPos = MPos - G5x - G92 - TLO (Z).
  const Vec3 block_coord = state.coord_data[block.coord_select];
  Vec3 g92 = state.g92;
  Vec3 target = state.position;
  Vec3 home{};           // G28/G30: the stored position (only the axes named, when any)
  int coord_index = -1;  // G10: which coord_data entry it writes
  Vec3 coord_value{};
  if (non_modal == NonModal::set_coord_data) {
    if (!axis_words) return fail(kNoAxisWords);
    if (!(value_words & ((1u << P) | (1u << L)))) return fail(kValueWordMissing);
    const double p = std::trunc(values[P]);
    if (p > 6) return fail(kUnsupportedCoordSys);
    if (values[L] != 20) {
      if (values[L] != 2 || (value_words & (1u << R))) return fail(kUnsupportedCommand);
    }
    value_words &= ~((1u << L) | (1u << P));
    coord_index = p > 0 ? static_cast<int>(p) - 1 : block.coord_select;
    coord_value = state.coord_data[coord_index];
    for (int i = 0; i < 3; ++i) {
      if (!(axis_words & (1u << i))) continue;
      if (values[L] == 20) coord_value[i] = state.position[i] - state.g92[i] - xyz[i] - (i == 2 ? state.tlo : 0.0);
      else coord_value[i] = xyz[i];
    }
  } else if (non_modal == NonModal::set_offset) {
    if (!axis_words) return fail(kNoAxisWords);
    for (int i = 0; i < 3; ++i)
      if (axis_words & (1u << i)) g92[i] = state.position[i] - block_coord[i] - xyz[i] - (i == 2 ? state.tlo : 0.0);
  } else if (axis_words && axis_command != AxisCommand::tool_length) {
    for (int i = 0; i < 3; ++i) {
      if (!(axis_words & (1u << i))) continue;
      if (non_modal == NonModal::absolute_override) target[i] = xyz[i];
      else if (block.incremental) target[i] = state.position[i] + xyz[i];
      else target[i] = xyz[i] + block_coord[i] + state.g92[i] + (i == 2 ? state.tlo : 0.0);
    }
  }
  if (non_modal == NonModal::go_home) {
    home = state.coord_data[home_index];
    if (axis_words) {
      for (int i = 0; i < 3; ++i)
        if (!(axis_words & (1u << i))) home[i] = state.position[i];
    }
  }
  if (non_modal == NonModal::absolute_override && block.motion != 0 && block.motion != 1)
    return fail(kG53InvalidMotionMode);

  double arc_radius = 0;
  Vec3 arc_offset{};
  if (block.motion == 80) {
    if (axis_words) return fail(kAxisWordsExist);
  } else if (axis_command == AxisCommand::motion) {
    if (block.motion == 0) {
      if (!axis_words) axis_command = AxisCommand::none;
    } else {
      if (feed == 0.0) return fail(kUndefinedFeedRate);
      if (block.motion == 1) {
        if (!axis_words) axis_command = AxisCommand::none;
      } else {  // G2 / G3
        if (!axis_words) return fail(kNoAxisWords);
        if (!(axis_words & ((1u << axis_0) | (1u << axis_1)))) return fail(kNoAxisWordsInPlane);
        double x = target[axis_0] - state.position[axis_0];
        double y = target[axis_1] - state.position[axis_1];
        if (value_words & (1u << R)) {
          value_words &= ~(1u << R);
          if (target == state.position) return fail(kInvalidTarget);
          double r = values[R];
          if (block.inches) r *= kMmPerInch;
          double h_x2_div_d = 4.0 * r * r - x * x - y * y;
          if (h_x2_div_d < 0) return fail(kArcRadiusError);
          h_x2_div_d = -std::sqrt(h_x2_div_d) / std::hypot(x, y);
          if (block.motion == 3) h_x2_div_d = -h_x2_div_d;
          if (r < 0) {
            h_x2_div_d = -h_x2_div_d;
            r = -r;
          }
          arc_offset[axis_0] = 0.5 * (x - (y * h_x2_div_d));
          arc_offset[axis_1] = 0.5 * (y + (x * h_x2_div_d));
          arc_radius = r;
        } else {
          if (!(ijk_words & ((1u << axis_0) | (1u << axis_1)))) return fail(kNoOffsetsInPlane);
          value_words &= ~((1u << I) | (1u << J) | (1u << K));
          arc_offset = ijk;
          if (block.inches)
            for (auto& v : arc_offset) v *= kMmPerInch;
          x -= arc_offset[axis_0];
          y -= arc_offset[axis_1];
          const double target_r = std::hypot(x, y);
          arc_radius = std::hypot(arc_offset[axis_0], arc_offset[axis_1]);
          const double delta_r = std::fabs(target_r - arc_radius);
          if (delta_r > 0.005) {
            if (delta_r > 0.5) return fail(kInvalidTarget);
            if (delta_r > 0.001 * arc_radius) return fail(kInvalidTarget);
          }
        }
      }
    }
  }

  // [0.] Unused words; a jog uses only N, F and the axis words (S and T are unused there).
  value_words &= jog ? ~((1u << N) | (1u << F)) : ~((1u << N) | (1u << F) | (1u << S) | (1u << T));
  if (axis_command != AxisCommand::none) value_words &= ~((1u << X) | (1u << Y) | (1u << Z));
  if (value_words) return fail(kUnusedWords);

  if (jog) {
    // gc_execute_line()'s jog interception: only G20/G21, G90/G91 and G53 may come with it,
    // then jog_execute() plans one line with the parser's spindle and power (M3 stays on).
    if (command_words & ~((1u << G3) | (1u << G6) | (1u << G0))) return fail(kInvalidJogCommand);
    if (non_modal != NonModal::none && non_modal != NonModal::absolute_override) return fail(kInvalidJogCommand);
    LineResult jog_result;
    Action a{Action::Kind::line};
    // Without axis words gcode.c never fills the target: it stays zeroed and the jog goes to
    // machine 0,0,0 (the real 1.1h does that for "$J=F100").
    a.target = axis_words ? target : Vec3{};
    a.feed = feed;
    a.spindle = state.spindle;
    a.s = state.s;
    jog_result.actions.push_back(a);
    return jog_result;  // the parser's modes are not touched; the caller moves its position
  }

  // --- Step 3: execute: commit the state and list the actions (laser-mode rules of gcode.c).
  LineResult result;
  auto& acts = result.actions;
  const bool laser = settings.laser_mode();
  const bool motion_is_powered = block.motion == 1 || block.motion == 2 || block.motion == 3;
  bool laser_disable = false, laser_is_motion = false, force_sync = false;
  if (laser) {
    laser_disable = !motion_is_powered;
    if (axis_words && axis_command == AxisCommand::motion) {
      laser_is_motion = true;
    } else if (state.spindle == Spindle::cw) {
      const bool was_powered = state.motion == 1 || state.motion == 2 || state.motion == 3;
      if (was_powered ? laser_disable : !laser_disable) force_sync = true;
    }
  }

  GcState next = block;
  next.feed = feed;
  next.g92 = g92;
  next.spindle = state.spindle;
  next.s = state.s;
  if (state.s != s_value || force_sync) {
    if (state.spindle != Spindle::off && !laser_is_motion) {
      Action a{Action::Kind::spindle};
      a.spindle = state.spindle;
      a.s = laser_disable ? 0.0 : s_value;
      acts.push_back(a);
    }
    next.s = s_value;
  }
  const double block_s = laser_disable ? 0.0 : next.s;
  if (state.spindle != block.spindle) {
    Action a{Action::Kind::spindle};
    a.spindle = block.spindle;
    a.s = block_s;
    acts.push_back(a);
    next.spindle = block.spindle;
  }
  if (state.mist != block.mist || state.flood != block.flood) acts.push_back(Action{Action::Kind::sync});
  if (non_modal == NonModal::dwell) {
    Action a{Action::Kind::dwell};
    a.seconds = values[P];
    acts.push_back(a);
  }
  if (axis_command == AxisCommand::tool_length) next.tlo = tool_length == 1 ? xyz[2] : 0.0;
  bool wco_changed = state.coord_select != block.coord_select || non_modal == NonModal::set_offset ||
                     non_modal == NonModal::reset_offset || next.tlo != state.tlo;
  if (non_modal == NonModal::set_coord_data) {
    next.coord_data[coord_index] = coord_value;  // an EEPROM write: GRBL syncs the buffer first
    if (coord_index == next.coord_select) wco_changed = true;
    else acts.push_back(Action{Action::Kind::sync});
  }
  if (non_modal == NonModal::set_home) {
    next.coord_data[home_index] = state.position;
    acts.push_back(Action{Action::Kind::sync});
  }
  if (wco_changed) {
    if (non_modal == NonModal::reset_offset) next.g92 = Vec3{};
    acts.push_back(Action{Action::Kind::wco_change});
  }
  if (non_modal == NonModal::go_home) {
    // G28/G30: rapid to the intermediate point (when axis words are given), then home.
    for (const Vec3& to : axis_words ? std::vector<Vec3>{target, home} : std::vector<Vec3>{home}) {
      Action a{Action::Kind::line};
      a.target = to;
      a.rapid = true;
      a.spindle = next.spindle;
      a.s = 0;
      acts.push_back(a);
    }
    next.position = home;
  }

  if (next.motion != 80 && axis_command == AxisCommand::motion) {
    auto line_to = [&](const Vec3& to, double rate, bool inverse) {
      Action a{Action::Kind::line};
      a.target = to;
      a.feed = rate;
      a.rapid = next.motion == 0;
      a.inverse_time = inverse;
      a.spindle = next.spindle;
      a.s = block_s;
      acts.push_back(a);
    };
    if (next.motion == 0 || next.motion == 1) {
      line_to(target, feed, next.inverse_time && next.motion == 1);
    } else {
      // mc_arc(): chords within $12 of the true arc; the last chord ends exactly on target.
      const Vec3& p0 = state.position;
      const double c0 = p0[axis_0] + arc_offset[axis_0], c1 = p0[axis_1] + arc_offset[axis_1];
      const double r0 = -arc_offset[axis_0], r1 = -arc_offset[axis_1];
      const double rt0 = target[axis_0] - c0, rt1 = target[axis_1] - c1;
      double travel = std::atan2(r0 * rt1 - r1 * rt0, r0 * rt0 + r1 * rt1);
      if (next.motion == 2) {
        if (travel >= -kArcAngularEpsilon) travel -= 2 * M_PI;
      } else if (travel <= kArcAngularEpsilon) {
        travel += 2 * M_PI;
      }
      const double tol = settings.get(12);
      const double chords =
          std::floor(std::fabs(0.5 * travel * arc_radius) / std::sqrt(tol * (2 * arc_radius - tol)));
      if (!(chords <= kMaxArcSegments)) return fail(kInvalidTarget);  // also NaN
      const int segments = static_cast<int>(chords);
      // Inverse time is per line: each of n chords gets 1/n of the arc's time.
      const bool inverse = next.inverse_time;
      const double rate = segments > 0 && inverse ? feed * segments : feed;
      for (int i = 1; i < segments; ++i) {
        const double a = travel * i / segments;
        Vec3 p = p0;
        p[axis_0] = c0 + r0 * std::cos(a) - r1 * std::sin(a);
        p[axis_1] = c1 + r0 * std::sin(a) + r1 * std::cos(a);
        p[axis_linear] = p0[axis_linear] + (target[axis_linear] - p0[axis_linear]) * i / segments;
        line_to(p, rate, inverse);
      }
      line_to(target, rate, inverse);
    }
    next.position = target;
  }

  if (program_flow == 1) {
    acts.push_back(Action{Action::Kind::pause});
  } else if (program_flow == 2 || program_flow == 30) {
    next.motion = 1;
    next.plane = 0;
    next.incremental = false;
    next.inverse_time = false;
    next.coord_select = 0;
    next.spindle = Spindle::off;
    next.mist = next.flood = false;
    acts.push_back(Action{Action::Kind::program_end});
  }
  state = next;
  return result;
}

}  // namespace atelier::laser_emu

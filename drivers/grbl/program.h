// A G-code job made ready for GRBL: the lines as they go on the wire, each tied to the
// line of the source file it came from (for error messages), an estimated duration per line
// (for "time left": GRBL 1.1h's planner and stepper as modelled by laser/motion_planner.h,
// so acceleration, junction speeds and the 15-block look-ahead count), the power scale and
// the area the job covers. Also the frame job that
// traces that area with the beam off. Pure, thread-safe. Units: mm, mm/min, seconds.
#pragma once

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "algorithms/laser/motion_planner.h"

namespace atelier::grbl {

// GRBL 1.1's line buffer is 80 bytes with the terminator: 79 characters after GRBL itself has
// removed spaces and comments. Longer lines are refused with error:11.
constexpr size_t kMaxLineChars = 79;

struct Bounds {
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;  // mm, work coordinates
  double width() const { return max_x - min_x; }
  double height() const { return max_y - min_y; }
};

struct Program {
  // To send, in order: comments ("(...)" and "; ...") and whitespace removed, upper-cased,
  // blank lines and lone "%" dropped. Each fits GRBL's line buffer.
  std::vector<std::string> lines;
  std::vector<int> source_line;          // 1-based line in the source of lines[i]
  std::vector<std::string> source_text;  // that source line as written (without "\r\n")
  std::optional<double> s_max;           // from a "; s_max=N" header comment
  // From a "; bounds=min_x,min_y,max_x,max_y" header comment, else the extent of every
  // X/Y target and arc (G20 inches converted, G91 followed); empty if nothing moves.
  std::optional<Bounds> bounds;
  // Estimated duration of lines[i] on GRBL: its moves through the planner model (G0 at the
  // axes' rapid rates, G1 at F, G2/G3 as mc_arc's chords at the $12 default 0.002 mm), G4 P
  // dwells; M0 pauses count zero (the operator's wait is not known).
  std::vector<double> seconds;
  // Program pauses: index into `lines` of each line with M0 (GRBL finishes the motion before
  // it, holds, and answers that line only after a cycle start '~'), with the text of the last
  // comment before it in the source (trimmed; "" if none), which tells the operator what to
  // do (e.g. "sheet oak-1: place it face down at the origin, then resume").
  std::map<size_t, std::string> pauses;
  double total_seconds() const;
};

// Parses `gcode`; `motion` is the machine's planner settings ($11, $100-$122) for the
// estimate. Laser mode ($32=1) is assumed for where GRBL empties its planner (M3/M4/M5 changes,
// S on a line without motion, G4, M0...: the head stops there). Throws std::runtime_error "line N: ..." for lines GRBL cannot take: longer than 79
// characters, bytes GRBL reads as real-time commands ('?', '!', '~', 0x80-0xFF), '$' system
// commands (they are not job content and settings must not be streamed), and bad header values.
Program parse_program(std::string_view gcode, const laser::MotionSettings& motion);
// The same with default MotionSettings whose X/Y rapid rates are `rapid_mm_min` (if > 0).
// Kept until every caller passes the machine's settings.
Program parse_program(std::string_view gcode, double rapid_mm_min);

// The bounding-box trace with the beam off: M5, G90 G21, G0 to the first corner, G1 at
// `feed_mm_min` with S0 round the other corners and back, G4 P0.01 (its ok comes once the
// head has stopped). `rapid_mm_min` only feeds the estimate (0: use feed_mm_min).
Program frame_program(const Bounds& b, double feed_mm_min, double rapid_mm_min = 0);

}  // namespace atelier::grbl

// From a two-colour stitch pattern to the carriage passes an AYAB machine knits: needle
// placement on the bed, knitting mode, row order. Pure, thread-safe.
//
// Mapping (documented for users in README "Knitting on the machine"):
// - pattern.png column 0 -> the leftmost needle of the working range (start_needle), column c
//   -> start_needle + c; `mirror` reverses this (the knitter faces the purl side).
// - pattern.png's bottom row is the first row knitted (`[knit] first_row = "bottom"`, the
//   default, as AYAB desktop does): the cast-on edge is the bottom of the picture, so the
//   fabric, cast-on edge down, is pattern.png upright. `first_row = "top"` knits row 0 first
//   (the fabric comes off the machine upside down: for top-down pieces).
// - A contrast stitch (1, black in pattern.png) selects its needle in single-bed Fair Isle.
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/error.h"
#include "drivers/ayab/messages.h"

namespace atelier::ayab {

// The pattern cannot be knitted on this machine (e.g. wider than the bed); what() says why,
// with both widths.
class PlanError : public BadInput {
 public:
  using BadInput::BadInput;
};

enum class KnitMode {
  single_bed,      // 2 colours, 1 pass per row: selected needles knit the contrast yarn
  classic_ribber,  // 2 colours, 2 passes per row in the order A B, B A, A B, ...
  circular,        // 2 colours, 4 passes per row: A, blank, B, blank (tubular on the ribber)
};
std::optional<KnitMode> knit_mode_from_name(const std::string& name);  // "single-bed", ...
std::string knit_mode_name(KnitMode mode);

struct PlanParams {
  MachineType machine = MachineType::kh930;
  KnitMode mode = KnitMode::single_bed;
  std::optional<int> start_needle;  // leftmost needle (0-based); centred when empty
  bool first_row_top = false;  // false: pattern row rows-1 (the bottom) is knitted first
  bool mirror = false;
};

struct KnitPlan {
  MachineType machine = MachineType::kh930;
  int start_needle = 0;  // working range [start_needle, stop_needle], 0-based
  int stop_needle = 0;
  std::vector<Bytes> passes;           // needle data of each carriage pass, in knitting order
  std::vector<int> pattern_row;        // pattern.png row that each pass belongs to
  std::vector<uint8_t> colour;         // colour index sent with each pass (0 or 1)
  int passes_per_row = 1;              // 0: varies per row (lace); pattern_row says which
  // Lace plans (lace_plan.h) only; empty for plan_knitting(), where every pass is the knit
  // carriage's. Per pass: the carriage the operator must use, and what the pass does
  // ("chart row 2 (RS row 3): lace carriage left to right, transfers").
  std::vector<Carriage> carriage;
  std::vector<std::string> note;
};

// `pattern`: CV_8UC1, 1 = contrast, 0 = background (pattern.png inverted: black -> 1).
// Throws PlanError when the pattern does not fit the machine.
KnitPlan plan_knitting(const cv::Mat& pattern, const PlanParams& params);

}  // namespace atelier::ayab

// Placement and pass generation for the two-colour knitting modes.
//
// Modes of the protocol file not offered here: "middle-colours-twice" and "heart-of-pluto"
// only differ from classic ribber when a row has more than two colours (2n - 2 passes for n
// colours); atelier's knit patterns are strictly two-colour (contrast / background), where
// both would reduce to classic ribber, so they would add names without adding behaviour.
// Classic ribber with more than two colours (every other pass blank) is out for the same reason.
#include "drivers/ayab/knit_plan.h"

namespace atelier::ayab {

std::optional<KnitMode> knit_mode_from_name(const std::string& name) {
  if (name == "single-bed") return KnitMode::single_bed;
  if (name == "classic-ribber") return KnitMode::classic_ribber;
  if (name == "circular") return KnitMode::circular;
  return std::nullopt;
}

std::string knit_mode_name(KnitMode mode) {
  switch (mode) {
    case KnitMode::single_bed: return "single-bed";
    case KnitMode::classic_ribber: return "classic-ribber";
    case KnitMode::circular: return "circular";
  }
  return "unknown";
}

KnitPlan plan_knitting(const cv::Mat& pattern, const PlanParams& params) {
  if (pattern.empty() || pattern.type() != CV_8UC1)
    throw PlanError("the knit pattern must be a non-empty one-channel 8-bit image");
  const int needles = needle_count(params.machine);
  const int width = pattern.cols;
  const std::string machine = machine_display_name(params.machine);
  if (width > needles)
    throw PlanError("pattern is " + std::to_string(width) + " stitches wide but the " + machine + " has " +
                    std::to_string(needles) + " needles");
  // The firmware needs start < stop.
  if (width < 2) throw PlanError("pattern is 1 stitch wide; the knitting machine needs at least 2 needles");
  const int start = params.start_needle.value_or((needles - width) / 2);
  if (start < 0 || start + width > needles)
    throw PlanError("pattern is " + std::to_string(width) + " stitches wide and starts at needle " +
                    std::to_string(start) + ", but the " + machine + " has needles 0.." +
                    std::to_string(needles - 1) + " (" + std::to_string(needles) + " needles)");

  KnitPlan plan;
  plan.machine = params.machine;
  plan.start_needle = start;
  plan.stop_needle = start + width - 1;
  plan.passes_per_row = params.mode == KnitMode::single_bed ? 1 : params.mode == KnitMode::classic_ribber ? 2 : 4;

  const size_t bytes = static_cast<size_t>(line_bytes(params.machine));
  // Needles selected for stitches of colour `colour` (1 = contrast) in pattern row `row`.
  auto select = [&](int row, uint8_t colour) {
    Bytes data(bytes, 0);
    const uint8_t* px = pattern.ptr<uint8_t>(row);
    for (int c = 0; c < width; ++c) {
      const uint8_t stitch = px[c] != 0 ? 1 : 0;
      const int needle = start + (params.mirror ? width - 1 - c : c);
      if (stitch == colour) select_needle(data, needle, true);
    }
    return data;
  };
  auto add = [&](int row, uint8_t colour, Bytes data) {
    plan.passes.push_back(std::move(data));
    plan.pattern_row.push_back(row);
    plan.colour.push_back(colour);
  };

  const int rows = pattern.rows;
  plan.passes.reserve(static_cast<size_t>(rows * plan.passes_per_row));
  for (int i = 0; i < rows; ++i) {
    const int row = params.first_row_top ? i : rows - 1 - i;
    switch (params.mode) {
      case KnitMode::single_bed:
        add(row, 0, select(row, 1));
        break;
      case KnitMode::classic_ribber: {
        // A B on even knitted rows, B A on odd ones: the carriage keeps the last yarn.
        const uint8_t first = (i % 2 == 0) ? 0 : 1;
        add(row, first, select(row, first));
        add(row, static_cast<uint8_t>(1 - first), select(row, static_cast<uint8_t>(1 - first)));
        break;
      }
      case KnitMode::circular:
        add(row, 0, select(row, 0));
        add(row, 0, Bytes(bytes, 0));
        add(row, 1, select(row, 1));
        add(row, 1, Bytes(bytes, 0));
        break;
    }
  }
  return plan;
}

}  // namespace atelier::ayab

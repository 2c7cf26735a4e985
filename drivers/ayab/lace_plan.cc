#include "drivers/ayab/lace_plan.h"

namespace atelier::ayab {

LacePlanResult plan_lace(const lace::Chart& chart, int cast_on, int repeats_wide, int repeats_high,
                         const PlanParams& params, const lace::CarriageLimits& limits) {
  LacePlanResult out;
  if (repeats_wide < 1 || repeats_high < 1) {
    out.problems.push_back("the swatch needs at least one repeat each way (got " + std::to_string(repeats_wide) +
                           " wide, " + std::to_string(repeats_high) + " high)");
    return out;
  }
  if (const lace::Knittability k = lace::knittable(chart, cast_on); !k) {
    out.problems.push_back(k.why.empty() ? "the chart cannot be knitted" : k.why);
    return out;
  }
  const int needles = needle_count(params.machine);
  const int width = cast_on * repeats_wide;
  const std::string machine = machine_display_name(params.machine);
  if (width > needles) {
    out.problems.push_back("the lace is " + std::to_string(width) + " stitches wide (" + std::to_string(repeats_wide) +
                           " repeats of " + std::to_string(cast_on) + ") but the " + machine + " has " +
                           std::to_string(needles) + " needles");
  } else if (width < 2) {
    out.problems.push_back("the lace is 1 stitch wide; the knitting machine needs at least 2 needles");
  }
  const int start = params.start_needle.value_or((needles - width) / 2);
  if (width <= needles && (start < 0 || start + width > needles))
    out.problems.push_back("the lace is " + std::to_string(width) + " stitches wide and starts at needle " +
                           std::to_string(start) + ", but the " + machine + " has needles 0.." +
                           std::to_string(needles - 1));

  std::vector<lace::LaceRowSchedule> rows;
  rows.reserve(chart.rows.size());
  for (size_t r = 0; r < chart.rows.size(); ++r) {
    rows.push_back(lace::schedule_lace_row(chart.rows[r], repeats_wide, static_cast<int>(r), limits));
    for (const auto& p : rows.back().problems) out.problems.push_back(p);
  }
  if (!out.problems.empty()) return out;

  KnitPlan plan;
  plan.machine = params.machine;
  plan.start_needle = start;
  plan.stop_needle = start + width - 1;
  plan.passes_per_row = 0;
  const size_t bytes = static_cast<size_t>(line_bytes(params.machine));
  auto add = [&](int row, Carriage carriage, Bytes data, std::string note) {
    plan.passes.push_back(std::move(data));
    plan.pattern_row.push_back(row);
    plan.colour.push_back(0);
    plan.carriage.push_back(carriage);
    plan.note.push_back(std::move(note));
  };
  const int chart_rows = static_cast<int>(chart.rows.size());
  for (int i = 0; i < chart_rows * repeats_high; ++i) {
    // Chart rows as resume --from-row counts them (repeats included), with the knitted rows.
    const std::string chart_row = "chart row " + std::to_string(i + 1);
    const std::string rs = chart_row + " (RS row " + std::to_string(2 * i + 1) + ")";
    for (const lace::LacePass& pass : rows[static_cast<size_t>(i % chart_rows)].passes) {
      Bytes data(bytes, 0);
      for (int j : pass.needles) select_needle(data, start + j, true);
      const bool ltr = pass.direction == lace::LaceDirection::left_to_right;
      add(i, Carriage::lace, std::move(data),
          rs + ": lace carriage " + (ltr ? "left to right" : "right to left") +
              (pass.needles.empty() ? ", blank pass (no transfer)" : ", transfers"));
      ++out.lace_passes;
    }
    add(i, Carriage::knit, Bytes(bytes, 0), rs + ": knit carriage, the right-side row");
    add(i, Carriage::knit, Bytes(bytes, 0),
        chart_row + " (WS row " + std::to_string(2 * i + 2) + "): knit carriage, the plain wrong-side row");
    out.knit_passes += 2;
  }
  out.plan = std::move(plan);
  return out;
}

}  // namespace atelier::ayab

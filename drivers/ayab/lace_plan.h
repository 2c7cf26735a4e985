// From a lace chart to the carriage passes an AYAB machine knits with the lace carriage, or
// the reasons it cannot (algorithms/lace/transfers.h states the carriage model).
//
// Mapping: the chart is tiled repeats_wide times side by side (transfers may cross repeat
// boundaries) over cast_on * repeats_wide needles, and its rows are repeated repeats_high times.
// Knitting-order stitch j (right-side right first) is needle start_needle + j counted from the
// operator's left (the purl side faces the operator). Per chart row: the lace-carriage passes
// (an even number, the first left to right; 1 = a needle whose loops move one needle in the
// pass direction), then two knit-carriage passes with no needle selected (the RS row and the
// plain WS row). PlanParams::mode, first_row_top and mirror do not apply to lace:
// chart row 0 (row 1, drawn at the bottom of chart.pdf) is always knitted first.
//
// Pure, thread-safe.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/transfers.h"
#include "drivers/ayab/knit_plan.h"

namespace atelier::ayab {

struct LacePlanResult {
  std::optional<KnitPlan> plan;       // set <=> problems is empty
  std::vector<std::string> problems;  // what the lace carriage cannot do, one per chart row and stitch
  int lace_passes = 0;                // lace-carriage passes in the plan (blank ones included)
  int knit_passes = 0;                // knit-carriage passes in the plan
};

// The KnitPlan has passes_per_row = 0 (it varies), pattern_row = the chart row of each pass
// (0-based, counting repeats_high: 0 .. rows * repeats_high - 1, non-decreasing), colour 0,
// and per-pass carriage and note. A chart that is not knittable from cast_on, repeats < 1, or
// a swatch wider than the machine (both widths named) are problems too.
LacePlanResult plan_lace(const lace::Chart& chart, int cast_on, int repeats_wide, int repeats_high,
                         const PlanParams& params, const lace::CarriageLimits& limits = {});

}  // namespace atelier::ayab

#include "convert/lace/lace_report.h"

#include "convert/common/display_text.h"

#include <algorithm>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/fitness.h"
#include "algorithms/lace/hole_lines.h"
#include "algorithms/lace/transfers.h"
#include "drivers/ayab/lace_plan.h"

namespace atelier {
namespace {

// Over all rows, each taken as repeated side by side (as the fabric has it).
int max_adjacent_yarn_overs(const lace::Chart& chart) {
  int most = 0;
  for (const lace::Row& row : chart.rows) most = std::max(most, lace::max_adjacent_yarn_overs(row, true));
  return most;
}

nlohmann::json stitch_counts(const lace::Chart& chart) {
  nlohmann::json counts = nlohmann::json::object();
  for (lace::Symbol s : lace::kAllSymbols) counts[std::string(lace::name(s))] = 0;
  for (const lace::Row& row : chart.rows)
    for (lace::Symbol s : row) counts[std::string(lace::name(s))] = counts[std::string(lace::name(s))].get<int>() + 1;
  return counts;
}

nlohmann::json params_json(const LaceParams& p) {
  nlohmann::json j = {{"width", p.width},
                      {"rows", p.rows},
                      {"population", p.population},
                      {"generations", p.generations},
                      {"holes", p.holes},
                      {"knit_length", p.knit_length},
                      {"depth", p.depth},
                      {"symmetry", p.symmetry},
                      {"hole_lines", p.hole_lines},
                      {"yo_band", p.yo_band},
                      {"width_change", p.width_change},
                      {"yo_share_min", p.yo_share_min},
                      {"yo_share_max", p.yo_share_max},
                      {"target_score", p.target_score ? *p.target_score : 0.0},
                      {"stagnation", p.stagnation},
                      {"width_tolerance", p.width_tolerance},
                      {"seed", p.seed},
                      {"lace_carriage", p.lace_carriage},
                      {"repeats_wide", p.repeats_wide},
                      {"repeats_high", p.repeats_high}};
  if (p.start_chart_file) j["start_chart"] = safe_text(p.start_chart_file->string());
  else if (!p.start_rows.empty()) j["start_chart"] = p.start_rows;
  return j;
}

// What the lace carriage of a Brother machine (through AYAB) can do with the swatch. The
// device plans again with its own machine type and needles; this uses a KH-930 bed, centred.
nlohmann::json machine_json(const lace::Chart& chart, int cast_on, const LaceParams& p) {
  ayab::PlanParams plan_params;
  const ayab::LacePlanResult plan =
      ayab::plan_lace(chart, cast_on, p.repeats_wide, p.repeats_high, plan_params);
  // The first problems say what to change; a 200 x 200 chart can have thousands.
  constexpr std::size_t kListed = 100;
  const std::vector<std::string> listed(plan.problems.begin(),
                                        plan.problems.begin() + static_cast<std::ptrdiff_t>(
                                                                    std::min(kListed, plan.problems.size())));
  return {{"lace_carriage", plan.problems.empty()},
          {"machine", "kh930"},
          {"repeats_wide", p.repeats_wide},
          {"repeats_high", p.repeats_high},
          {"lace_passes", plan.lace_passes},
          {"knit_passes", plan.knit_passes},
          {"problems", listed},
          {"problems_total", plan.problems.size()},
          {"how", "per chart row: the lace carriage (parked left) transfers, then the knit "
                  "carriage knits the right-side row and the purl row"}};
}

// Does the chart read as a design (issue 22): how much of it is holes, whether the holes form
// lines, how mirror-symmetric the repeat is, how long the plain runs are.
nlohmann::json design_json(const lace::Chart& chart, int cast_on, const LaceParams& p) {
  const lace::HoleLines h = lace::hole_lines(chart, cast_on);
  const lace::Objectives o = lace::evaluate(chart, cast_on, lace::Weights{}, p.width_tolerance).objectives;
  return {{"yo_share", h.yo_share},
          {"yo_share_band", {p.yo_share_min, p.yo_share_max}},
          {"yo_share_in_band", h.yo_share >= p.yo_share_min && h.yo_share <= p.yo_share_max},
          {"hole_lines", h.hole_lines},
          {"connectedness", h.connectedness},
          {"holes", h.yarn_overs},
          {"holes_in_lines", h.in_lines},
          {"symmetry", o.symmetry},
          {"knit_length", o.knit_length}};
}

// What the user must hear before carrying the job to a machine: chart rows the
// Brother lace carriage cannot make (transfers.h), said whatever lace_carriage is.
std::vector<std::string> lace_warnings(const lace::Chart& chart, const LaceParams& p) {
  int rows = 0;
  for (const lace::Row& row : chart.rows)
    if (!lace::schedule_lace_row(row, 1, 0).ok()) ++rows;
  if (rows == 0) return {};
  const std::string n = std::to_string(rows) + " of " + std::to_string(chart.rows.size()) + " chart rows";
  if (!p.lace_carriage)
    return {"this chart needs a V-bed / hand transfers: " + n +
            " the lace carriage cannot make; use lace_carriage = true for the Brother lace carriage"};
  return {"the lace carriage cannot make " + n + " of this chart (machine.problems in report.json)"};
}

}  // namespace

nlohmann::json lace_report_json(const ConvertRequest& req, const std::string& title, const LaceParams& params,
                                const std::optional<LaceChartFile>& start, const lace::EvolveResult& result,
                                const lace::PreviewOptions& preview, double evolve_s, double outputs_s) {
  const lace::Chart& chart = result.chart;
  const int cast_on = result.cast_on;
  std::vector<int> row_widths;
  for (const lace::Row& row : chart.rows) row_widths.push_back(lace::produced(row));
  const lace::Evaluation& ev = result.evaluation;
  const lace::Knittability knit = lace::knittable(chart, cast_on);
  return {
      {"kind", "lace"},
      {"input", req.input == "-" ? std::string("-") : safe_text(req.input.filename().string())},
      {"title", title},
      {"cast_on", cast_on},
      {"rows", chart.rows.size()},
      {"row_widths", row_widths},
      {"start_chart", start ? nlohmann::json(params_json(params)["start_chart"]) : nlohmann::json(nullptr)},
      {"constraints",
       {{"knittable", knit.ok},
        {"yarn_over_balance", lace::yarn_over_balance(chart)},
        {"max_adjacent_yarn_overs", max_adjacent_yarn_overs(chart)},
        {"adjacent_yarn_overs_ok", lace::adjacent_yarn_overs_ok(chart, true)},
        {"width_tolerance", params.width_tolerance},
        {"width_ok", lace::width_ok(chart, params.width_tolerance)},
        {"all_satisfied", ev.constraints.ok()}}},
      {"fitness",
       {{"score", ev.score},
        {"holes", ev.objectives.holes},
        {"knit_length", ev.objectives.knit_length},
        {"depth", ev.objectives.depth},
        {"symmetry", ev.objectives.symmetry},
        {"hole_lines", ev.objectives.hole_lines},
        {"yo_band_distance", ev.objectives.yo_band_distance},
        {"width_change", ev.objectives.width_change},
        {"weights",
         {{"holes", params.holes},
          {"knit_length", params.knit_length},
          {"depth", params.depth},
          {"symmetry", params.symmetry},
          {"hole_lines", params.hole_lines},
          {"yo_band", params.yo_band},
          {"width_change", params.width_change}}}}},
      {"design", design_json(chart, cast_on, params)},
      {"stitches", stitch_counts(chart)},
      {"generations", result.generations_run},
      {"stopped_by", result.stopped_by},
      {"population", params.population},
      {"best_score", result.best_score},
      {"feasible_in_final_population", result.feasible_in_final_population},
      {"machine", machine_json(chart, cast_on, params)},
      {"preview", {{"repeats_wide", preview.repeats_x}, {"repeats_high", preview.repeats_y},
                   {"stitch_px", preview.stitch_px}}},
      {"params", params_json(params)},
      {"timings_s", {{"evolve", evolve_s}, {"outputs", outputs_s}}},
      {"warnings", lace_warnings(chart, params)},  // shown by atelierctl show
  };
}

}  // namespace atelier

#include "daemon/convert/lace_job.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include "algorithms/lace/evolve.h"
#include "algorithms/lace/fitness.h"
#include "algorithms/lace/instructions.h"
#include "algorithms/lace/preview.h"
#include "daemon/convert/lace_chart.h"
#include "daemon/convert/lace_chart_json.h"
#include "daemon/convert/lace_knitout.h"
#include "daemon/convert/lace_params.h"
#include "daemon/convert/output_files.h"
#include "daemon/convert/param_table.h"
#include "drivers/ayab/lace_plan.h"

namespace atelier {
namespace {

using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ParamError(file.string() + ": start_chart: cannot open the file");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The start chart named by the parameters: a chart.json, an instructions.txt, or inline rows.
std::optional<LaceChartFile> load_start_chart(const LaceParams& p) {
  try {
    if (p.start_chart_file) {
      const fs::path& file = *p.start_chart_file;
      const std::string text = read_text(file);
      if (file.extension() == ".json") {
        nlohmann::json j;
        try {
          j = nlohmann::json::parse(text);
        } catch (const nlohmann::json::exception& e) {
          throw std::invalid_argument(std::string("not JSON: ") + e.what());
        }
        return lace_chart_from_json(j, file.string());
      }
      const lace::ParsedInstructions parsed = lace::parse_instructions(text);
      return LaceChartFile{parsed.chart, parsed.cast_on};
    }
    if (!p.start_rows.empty()) {
      std::string text;
      for (size_t r = 0; r < p.start_rows.size(); ++r) {
        std::string row = p.start_rows[r];
        while (!row.empty() && (row.back() == ' ' || row.back() == '\t')) row.pop_back();
        if (!row.empty() && row.back() != '.') row += '.';
        text += "Row " + std::to_string(2 * r + 1) + " (RS): " + row + "\n";
      }
      const lace::ParsedInstructions parsed = lace::parse_instructions(text);
      const lace::Knittability k = lace::knittable(parsed.chart, parsed.cast_on);
      if (!k) throw std::invalid_argument(k.why);
      return LaceChartFile{parsed.chart, parsed.cast_on};
    }
  } catch (const std::invalid_argument& e) {
    const std::string where = p.start_chart_file ? p.start_chart_file->string() : std::string("inline rows");
    const std::string what = e.what();
    // lace_chart_from_json already names the file.
    throw ParamError("start_chart: " + (what.rfind(where, 0) == 0 ? what : where + ": " + what));
  }
  return std::nullopt;
}

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
                      {"width_tolerance", p.width_tolerance},
                      {"seed", p.seed},
                      {"lace_carriage", p.lace_carriage},
                      {"repeats_wide", p.repeats_wide},
                      {"repeats_high", p.repeats_high}};
  if (p.start_chart_file) j["start_chart"] = p.start_chart_file->string();
  else if (!p.start_rows.empty()) j["start_chart"] = p.start_rows;
  return j;
}

// What the lace carriage of a Brother machine (through AYAB) can do with the swatch. The
// device plans again with its own machine type and needles; this uses a KH-930 bed, centred.
nlohmann::json machine_json(const lace::Chart& chart, int cast_on, const LaceParams& p) {
  ayab::PlanParams plan_params;
  const ayab::LacePlanResult plan =
      ayab::plan_lace(chart, cast_on, p.repeats_wide, p.repeats_high, plan_params);
  return {{"lace_carriage", plan.problems.empty()},
          {"machine", "kh930"},
          {"repeats_wide", p.repeats_wide},
          {"repeats_high", p.repeats_high},
          {"lace_passes", plan.lace_passes},
          {"knit_passes", plan.knit_passes},
          {"problems", plan.problems},
          {"how", "per chart row: the lace carriage (parked left) transfers, then the knit "
                  "carriage knits the right-side row and the purl row"}};
}

}  // namespace

ConvertResult convert_lace(const ConvertRequest& req) {
  const auto t0 = Clock::now();
  const LaceParams params = read_lace_params(req.params, req.params_source);
  const std::string title =
      req.input.empty() || req.input == "-" ? std::string("lace") : req.input.stem().string();
  const std::optional<LaceChartFile> start = load_start_chart(params);
  report_progress(req, 0.0);

  lace::EvolveParams ep;
  ep.width = params.width;
  ep.rows = params.rows;
  ep.population = params.population;
  ep.generations = params.generations;
  ep.weights = {params.holes, params.knit_length, params.depth, params.symmetry};
  ep.width_tolerance = params.width_tolerance;
  ep.seed = params.seed;
  if (start) {
    ep.start = start->chart;
    ep.start_cast_on = start->cast_on;
  }
  ep.threads = static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 2u));
  if (params.lace_carriage) {
    const int repeats_wide = params.repeats_wide;
    ep.extra_violations = [repeats_wide](const lace::Chart& chart, int cast_on) {
      return static_cast<int>(
          ayab::plan_lace(chart, cast_on, repeats_wide, 1, ayab::PlanParams{}).problems.size());
    };
  }
  ep.progress = [&req](int generation, int generations) {
    report_progress(req, 0.85 * generation / std::max(1, generations));
  };
  lace::EvolveResult result;
  try {
    result = lace::evolve(ep);
  } catch (const std::invalid_argument& e) {
    throw ParamError(req.params_source + ": " + e.what());
  } catch (const std::runtime_error& e) {  // no chart met every constraint
    throw ConvertError(title + ": " + e.what());
  }
  const double evolve_s = seconds_since(t0);
  const auto t1 = Clock::now();

  const lace::Chart& chart = result.chart;
  const int cast_on = result.cast_on;
  const fs::path& out = req.output_dir;
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw ConvertError(out.string() + ": cannot create the output folder: " + ec.message());
  LaceChartFile file{chart, cast_on, params.repeats_wide, params.repeats_high};
  write_output(out / "chart.json", lace_chart_to_json(file).dump(1) + "\n");
  try {
    write_lace_chart_svg(chart, cast_on, {title}, out / "chart.svg");
  } catch (const std::runtime_error& e) {
    throw ConvertError((out / "chart.svg").string() + ": " + e.what());
  }
  try {
    write_lace_chart_pdf(chart, cast_on, {title}, out / "chart.pdf");
  } catch (const std::runtime_error& e) {
    throw ConvertError((out / "chart.pdf").string() + ": " + e.what());
  }
  write_output(out / "instructions.txt", lace::write_instructions(chart, cast_on, {title}));
  write_output(out / "lace.k",
               make_lace_knitout(chart, cast_on, {title, params.repeats_wide, params.repeats_high}));
  lace::PreviewOptions preview_options;
  preview_options.repeats_x = params.repeats_wide;
  preview_options.repeats_y = params.repeats_high;
  write_output_png(out / "preview.png", lace::render_preview(chart, cast_on, preview_options));
  report_progress(req, 0.95);

  std::vector<int> row_widths;
  for (const lace::Row& row : chart.rows) row_widths.push_back(lace::produced(row));
  const lace::Evaluation& ev = result.evaluation;
  const lace::Knittability knit = lace::knittable(chart, cast_on);
  nlohmann::json report = {
      {"kind", "lace"},
      {"input", req.input == "-" ? std::string("-") : req.input.filename().string()},
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
        {"weights",
         {{"holes", params.holes},
          {"knit_length", params.knit_length},
          {"depth", params.depth},
          {"symmetry", params.symmetry}}}}},
      {"stitches", stitch_counts(chart)},
      {"generations", result.generations_run},
      {"population", params.population},
      {"best_score", result.best_score},
      {"feasible_in_final_population", result.feasible_in_final_population},
      {"machine", machine_json(chart, cast_on, params)},
      {"params", params_json(params)},
      {"timings_s", {{"evolve", evolve_s}, {"outputs", seconds_since(t1)}}},
  };
  write_output(out / "report.json", report.dump(2) + "\n");
  report_progress(req, 1.0);
  return {report,
          {"chart.json", "chart.svg", "chart.pdf", "instructions.txt", "lace.k", "preview.png",
           "report.json"}};
}

}  // namespace atelier

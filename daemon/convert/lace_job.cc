#include "daemon/convert/lace_job.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <thread>
#include <unordered_map>

#include "algorithms/lace/evolve.h"
#include "algorithms/lace/fitness.h"
#include "algorithms/lace/instructions.h"
#include "algorithms/lace/preview.h"
#include "algorithms/lace/transfers.h"
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

// A start chart file is a chart.json or an instructions.txt: a few kilobytes. Anything far
// larger is not one (and would only be read into memory to be refused).
constexpr std::uintmax_t kMaxStartChartBytes = 4 << 20;

// Throws std::invalid_argument (the caller adds the file and key).
std::string read_text(const fs::path& file) {
  std::error_code ec;
  const fs::file_status st = fs::status(file, ec);
  if (ec || !fs::exists(st)) throw std::invalid_argument("no such file");
  if (fs::is_directory(st)) throw std::invalid_argument("a folder, not a chart file (chart.json or instructions.txt)");
  if (!fs::is_regular_file(st)) throw std::invalid_argument("not a regular file");
  if (fs::file_size(file, ec) > kMaxStartChartBytes)
    throw std::invalid_argument("larger than " + std::to_string(kMaxStartChartBytes >> 20) +
                                " MB: not a chart.json or instructions.txt");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::invalid_argument("cannot open the file");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The start chart named by the parameters: a chart.json, an instructions.txt, or inline rows,
// within what evolve() takes (EvolveParams::start). Every problem is a ParamError
// "FILE:LINE: key 'start_chart': <chart file or 'inline rows'>: <problem>".
std::optional<LaceChartFile> load_start_chart(const LaceParams& p) {
  if (!p.start_chart_file && p.start_rows.empty()) return std::nullopt;
  const std::string where = p.start_chart_file ? p.start_chart_file->string() : std::string("inline rows");
  try {
    LaceChartFile chart;
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
        chart = lace_chart_from_json(j, "");
      } else {
        const lace::ParsedInstructions parsed = lace::parse_instructions(text);
        chart = LaceChartFile{parsed.chart, parsed.cast_on};
      }
    } else {
      std::string text;
      for (size_t r = 0; r < p.start_rows.size(); ++r) {
        std::string row = p.start_rows[r];
        // One row per string: a line break would smuggle in rows or a cast-on line.
        if (row.find_first_of("\n\r") != std::string::npos)
          throw std::invalid_argument("row " + std::to_string(r + 1) + " holds a line break; give one row per string");
        while (!row.empty() && (row.back() == ' ' || row.back() == '\t')) row.pop_back();
        if (!row.empty() && row.back() != '.') row += '.';
        text += "Row " + std::to_string(2 * r + 1) + " (RS): " + row + "\n";
      }
      const lace::ParsedInstructions parsed = lace::parse_instructions(text);
      chart = LaceChartFile{parsed.chart, parsed.cast_on};
    }
    // What evolve() takes as a start (it would refuse the rest without naming the key).
    if (chart.cast_on < 2 || chart.cast_on > 200)
      throw std::invalid_argument("the chart is worked over " + std::to_string(chart.cast_on) +
                                  " stitches; a start chart needs 2 to 200");
    if (chart.chart.rows.size() > 200)
      throw std::invalid_argument("the chart has " + std::to_string(chart.chart.rows.size()) +
                                  " right-side rows; a start chart may have at most 200");
    const int last = lace::produced(chart.chart.rows.back());
    if (last != chart.cast_on)
      throw std::invalid_argument("the chart ends " + std::to_string(last) + " stitches wide but starts from " +
                                  std::to_string(chart.cast_on) + " (eq. 1: it must end as wide as it starts)");
    return chart;
  } catch (const std::invalid_argument& e) {
    std::string what = e.what();
    if (what.rfind(": ", 0) == 0) what.erase(0, 2);  // lace_chart_from_json's empty source
    throw ParamError(p.start_chart_where + where + ": " + what);
  }
}

// The job file's own table: its nodes know their file and line, which the merged parameters'
// copies do not (toml++ copies no source). Empty for "-", a non-TOML input or one that does
// not parse (atelier-convert has parsed it already).
toml::table job_table(const ConvertRequest& req) {
  if (req.input.empty() || req.input == "-" || req.input.extension() != ".toml") return {};
  try {
    return toml::parse_file(req.input.string());
  } catch (const toml::parse_error&) {
    return {};
  }
}

// "FILE:LINE: key 'KEY': ", the job file's line when the key is in it.
std::string key_where(const toml::table& job, const ConvertRequest& req, const std::string& key) {
  if (job.contains(key)) return lace_key_where(job, key, req.input.string());
  return lace_key_where(req.params, key, req.params_source);
}

// What one job may ask for, so that a job file cannot take the machine's memory or run for
// days (measured on 2 cores: 500 x 200 generations of 200 x 200 charts take ~1.1 GB and ~5
// min; 20000 individuals take ~4 s a generation for their niche counts alone).
constexpr double kMaxPopulationCells = 2e7;   // population x width x rows: the forests in memory
constexpr double kMaxEvolveCells = 4e9;       // x generations: evaluation and breeding
constexpr double kMaxEvolvePairs = 2e10;      // population^2 x generations: fitness sharing
constexpr double kMaxSwatchStitches = 5e5;    // (width x repeats_wide) x (rows x repeats_high)

// Throws ParamError naming the key that takes the job over a limit. width and rows are the
// chart's (the start chart's when there is one).
void check_budget(const LaceParams& p, int width, int rows, const toml::table& job,
                  const ConvertRequest& req) {
  const toml::table& params = req.params;
  const double cells = static_cast<double>(width) * rows, pop = p.population, gens = p.generations;
  auto fail = [&](const std::string& key, const std::string& what) {
    throw ParamError(key_where(job, req, key) + what);
  };
  auto num = [](double v) { return std::to_string(static_cast<long long>(v)); };
  const std::string chart = std::to_string(width) + " x " + std::to_string(rows) + " chart";
  if (pop * cells > kMaxPopulationCells)
    fail("population", "population " + num(pop) + " of a " + chart + " needs more than " +
                           num(kMaxPopulationCells) + " chart cells in memory; use a smaller population");
  if (gens * pop * cells > kMaxEvolveCells)
    fail("generations", num(gens) + " generations x population " + num(pop) + " of a " + chart +
                            " is more than " + num(kMaxEvolveCells) +
                            " cells to evolve (minutes of work); use fewer generations or a smaller population");
  if (gens * pop * pop > kMaxEvolvePairs)
    fail("population", "population " + num(pop) + " for " + num(gens) + " generations compares more than " +
                           num(kMaxEvolvePairs) + " pairs of charts (fitness sharing); use a smaller population");
  const double swatch = static_cast<double>(width) * p.repeats_wide * rows * p.repeats_high;
  if (swatch > kMaxSwatchStitches)
    fail(params.contains("repeats_high") || !params.contains("repeats_wide") ? "repeats_high" : "repeats_wide",
         "the swatch (" + std::to_string(p.repeats_wide) + " x " + std::to_string(p.repeats_high) +
             " repeats of a " + chart + ") has more than " + num(kMaxSwatchStitches) +
             " stitches for lace.k, the preview and the machine; use fewer repeats");
}

// The preview's bounds: at most kMaxPreviewStitches stitches drawn (~50 us a stitch: a 200 x
// 200 chart 3 x 3 took 37 s; one repeat is drawn whatever its size) and at most
// kMaxPreviewSide pixels a side (a 50 x 50 swatch at 14 px took 355 MB of PNG). Fewer
// repeats first for the stitches, then smaller stitches (14 px down to 4), then fewer repeats
// again for the pixels.
constexpr int kMaxPreviewStitches = 50000;
constexpr int kMaxPreviewSide = 4096;

lace::PreviewOptions preview_options(const lace::Chart& chart, int cast_on, const LaceParams& p) {
  lace::PreviewOptions o;
  o.repeats_x = p.repeats_wide;
  o.repeats_y = p.repeats_high;
  const bool stacks = lace::produced(chart.rows.back()) == cast_on;  // else drawn once high
  const int rows = static_cast<int>(chart.rows.size());
  auto wide = [&] { return cast_on * o.repeats_x; };                  // stitches across
  auto courses = [&] { return 2 * rows * (stacks ? o.repeats_y : 1); };  // RS and WS rows
  while (wide() * courses() > kMaxPreviewStitches && (o.repeats_x > 1 || o.repeats_y > 1)) {
    int& more = o.repeats_x >= o.repeats_y ? o.repeats_x : o.repeats_y;
    --more;
  }
  auto fits = [&] {
    const int row_px = std::max(3, static_cast<int>(std::lround(0.8 * o.stitch_px)));
    return wide() * o.stitch_px <= kMaxPreviewSide && courses() * row_px <= kMaxPreviewSide;
  };
  for (o.stitch_px = 14; o.stitch_px > 4 && !fits(); --o.stitch_px) {
  }
  while (!fits() && o.repeats_x > 1 && wide() * o.stitch_px > kMaxPreviewSide) --o.repeats_x;
  while (!fits() && o.repeats_y > 1) --o.repeats_y;
  return o;
}

// With generations = 0 the result is the start chart itself: one that breaks a constraint is
// the job file's mistake, named here (evolve() would only say no chart was feasible).
void check_start_feasible(const LaceChartFile& start, const lace::EvolveParams& ep, const LaceParams& p) {
  const lace::Evaluation e = lace::evaluate(start.chart, start.cast_on, ep.weights, ep.width_tolerance);
  std::vector<std::string> broken;
  if (e.constraints.adjacent_yo_excess > 0) broken.push_back("more than two yarn-overs side by side");
  if (e.constraints.width_excess > 0)
    broken.push_back("a row wider or narrower than width_tolerance = " + std::to_string(ep.width_tolerance) +
                     " allows");
  // The evolution's own verdict (rows the carriage cannot do; the swatch's width is only
  // reported), with the first problem for the message.
  if (ep.extra_violations && ep.extra_violations(start.chart, start.cast_on) > 0) {
    std::string first;
    for (std::size_t r = 0; r < start.chart.rows.size() && first.empty(); ++r) {
      const lace::LaceRowSchedule row = lace::schedule_lace_row(start.chart.rows[r], 1, static_cast<int>(r));
      if (!row.problems.empty()) first = " (" + row.problems.front() + ")";
    }
    broken.push_back("the lace carriage cannot knit it" + first);
  }
  if (broken.empty()) return;
  std::string list;
  for (const std::string& b : broken) list += (list.empty() ? "" : "; ") + b;
  throw ParamError(p.start_chart_where +
                   (p.start_chart_file ? p.start_chart_file->string() : std::string("inline rows")) +
                   ": with generations = 0 the result is this chart, but it breaks the constraints: " + list);
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

// How many stitches of the row the lace carriage cannot do (transfers.h), for the evolution's
// extra constraint. Children share most rows with their parents, so each evaluation thread
// remembers its answers (the result is a pure function of the row; bounded memory).
int carriage_problems(const lace::Row& row) {
  thread_local std::unordered_map<std::string, int> known;
  std::string key(row.size(), '\0');
  for (size_t i = 0; i < row.size(); ++i) key[i] = static_cast<char>(row[i]);
  if (auto it = known.find(key); it != known.end()) return it->second;
  if (known.size() > 200000) known.clear();
  const int n = static_cast<int>(lace::schedule_lace_row(row, 1, 0).problems.size());
  known.emplace(std::move(key), n);
  return n;
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

// The evolution the parameters ask for (progress reported through the request).
lace::EvolveParams evolve_params(const LaceParams& params, const std::optional<LaceChartFile>& start,
                                 const ConvertRequest& req) {
  lace::EvolveParams ep;
  ep.width = params.width;
  ep.rows = params.rows;
  ep.population = params.population;
  ep.generations = params.generations;
  ep.weights = {params.holes, params.knit_length, params.depth, params.symmetry};
  ep.width_tolerance = params.width_tolerance;
  ep.seed = params.seed;
  // The defaults (tournament 4, 2 elites) need at least 5 individuals; population may be 2.
  ep.tournament = std::min(ep.tournament, params.population);
  ep.elites = std::min(ep.elites, params.population - 1);
  if (start) {
    ep.start = start->chart;
    ep.start_cast_on = start->cast_on;
  }
  ep.threads = static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 2u));
  if (params.lace_carriage) {
    ep.carriage_pairings = true;
    // Rows the lace carriage cannot do. Each repeat's transfers stay inside it (every row is
    // balanced), so one repeat decides; the swatch's width is checked by the plan below.
    ep.extra_violations = [](const lace::Chart& chart, int) {
      int problems = 0;
      for (const lace::Row& row : chart.rows) problems += carriage_problems(row);
      return problems;
    };
  }
  ep.progress = [&req](int generation, int generations) {
    report_progress(req, 0.85 * generation / std::max(1, generations));
  };
  return ep;
}

// report.json: the chart's constraint check and fitness terms, the evolution, what the lace
// carriage can do, what the preview shows, the parameters and timings.
nlohmann::json report_json(const ConvertRequest& req, const std::string& title, const LaceParams& params,
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
      {"preview", {{"repeats_wide", preview.repeats_x}, {"repeats_high", preview.repeats_y},
                   {"stitch_px", preview.stitch_px}}},
      {"params", params_json(params)},
      {"timings_s", {{"evolve", evolve_s}, {"outputs", outputs_s}}},
  };
}

}  // namespace

ConvertResult convert_lace(const ConvertRequest& req) {
  const auto t0 = Clock::now();
  LaceParams params = read_lace_params(req.params, req.params_source);
  const toml::table job = job_table(req);
  if (job.contains("start_chart")) {
    params.start_chart_where = key_where(job, req, "start_chart");
    // A relative path in the job file is relative to the job file, also when the merged copy
    // has forgotten where it came from (it would be taken from the working directory).
    const toml::node* merged = req.params.get("start_chart");
    if (params.start_chart_file && params.start_chart_file->is_relative() && merged && !merged->source().path &&
        job.get("start_chart")->value<std::string>() == merged->value<std::string>())
      params.start_chart_file = req.input.parent_path() / *params.start_chart_file;
  }
  const std::string title =
      req.input.empty() || req.input == "-" ? std::string("lace") : req.input.stem().string();
  const std::optional<LaceChartFile> start = load_start_chart(params);
  check_budget(params, start ? start->cast_on : params.width,
               start ? static_cast<int>(start->chart.rows.size()) : params.rows, job, req);
  report_progress(req, 0.0);

  const lace::EvolveParams ep = evolve_params(params, start, req);
  if (start && params.generations == 0) check_start_feasible(*start, ep, params);
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
  const lace::PreviewOptions preview = preview_options(chart, cast_on, params);
  write_output_png(out / "preview.png", lace::render_preview(chart, cast_on, preview));
  report_progress(req, 0.95);

  const nlohmann::json report =
      report_json(req, title, params, start, result, preview, evolve_s, seconds_since(t1));
  write_output(out / "report.json", report.dump(2) + "\n");
  report_progress(req, 1.0);
  return {report,
          {"chart.json", "chart.svg", "chart.pdf", "instructions.txt", "lace.k", "preview.png",
           "report.json"}};
}

}  // namespace atelier

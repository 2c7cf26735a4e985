#include "convert/lace/lace_job.h"

#include "convert/common/display_text.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>
#include <unordered_map>

#include "algorithms/lace/evolve.h"
#include "algorithms/lace/instructions.h"
#include "algorithms/lace/preview.h"
#include "algorithms/lace/transfers.h"
#include "convert/lace/lace_chart.h"
#include "convert/lace/lace_chart_json.h"
#include "convert/lace/lace_job_checks.h"
#include "convert/lace/lace_knitout.h"
#include "convert/lace/lace_params.h"
#include "convert/lace/lace_report.h"
#include "convert/common/output_files.h"
#include "convert/common/param_table.h"

namespace atelier {
namespace {

using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
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

// The evolution the parameters ask for (progress reported through the request).
lace::EvolveParams evolve_params(const LaceParams& params, const std::optional<LaceChartFile>& start,
                                 const ConvertRequest& req) {
  lace::EvolveParams ep;
  ep.width = params.width;
  ep.rows = params.rows;
  ep.population = params.population;
  ep.generations = params.generations;
  ep.weights = {params.holes,      params.knit_length, params.depth,        params.symmetry,
                params.hole_lines, params.yo_band,     params.width_change, params.yo_share_min,
                params.yo_share_max};
  ep.target_score = params.target_score;
  ep.stagnation = params.stagnation;
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

}  // namespace

ConvertResult convert_lace(const ConvertRequest& req) {
  const auto t0 = Clock::now();
  LaceParams params = read_lace_params(req.params, req.params_source);
  const toml::table job = lace_job_table(req);
  if (job.contains("start_chart")) {
    params.start_chart_where = lace_job_key_where(job, req, "start_chart");
    // A relative path in the job file is relative to the job file, also when the merged copy
    // has forgotten where it came from (it would be taken from the working directory).
    const toml::node* merged = req.params.get("start_chart");
    if (params.start_chart_file && params.start_chart_file->is_relative() && merged && !merged->source().path &&
        job.get("start_chart")->value<std::string>() == merged->value<std::string>())
      params.start_chart_file = req.input.parent_path() / *params.start_chart_file;
  }
  const std::string title =
      req.input.empty() || req.input == "-" ? std::string("lace") : safe_text(req.input.stem().string());
  const std::optional<LaceChartFile> start = load_start_chart(params, req.paths.access("start_chart", req.input.parent_path()));
  check_lace_budget(params, start ? start->cast_on : params.width,
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
  write_output(out / kLaceChartFile, lace_chart_to_json(file).dump(1) + "\n");
  write_lace_chart_svg(chart, cast_on, {title}, out / "chart.svg");
  write_lace_chart_pdf(chart, cast_on, {title}, out / "chart.pdf");
  write_output(out / "instructions.txt", lace::write_instructions(chart, cast_on, {title}));
  write_output(out / "lace.k",
               make_lace_knitout(chart, cast_on, {title, params.repeats_wide, params.repeats_high}));
  const lace::PreviewOptions preview = preview_options(chart, cast_on, params);
  write_output_png(out / "preview.png", lace::render_preview(chart, cast_on, preview));
  report_progress(req, 0.95);

  const nlohmann::json report =
      lace_report_json(req, title, params, start, result, preview, evolve_s, seconds_since(t1));
  write_output(out / "report.json", report.dump(2) + "\n");
  report_progress(req, 1.0);
  return {report,
          {kLaceChartFile, "chart.svg", "chart.pdf", "instructions.txt", "lace.k", "preview.png",
           "report.json"}};
}

}  // namespace atelier

#include "convert/knit/knit_job.h"

#include "convert/common/display_text.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/knit/auto_choice.h"
#include "algorithms/knit/dither.h"
#include "algorithms/knit/floats.h"
#include "algorithms/knit/preview.h"
#include "algorithms/knit/similarity.h"
#include "algorithms/knit/solvers.h"
#include "algorithms/knit/stitch_grid.h"
#include "convert/knit/knit_chart.h"
#include "convert/knit/knit_knitout.h"
#include "convert/knit/knit_params.h"
#include "convert/knit/knit_preview_png.h"
#include "convert/common/output_files.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;

// preview.png's size limit: 40 Mpx (120 MB of pixels), a 4000 x 10000 render.
constexpr double kPreviewMaxPixels = 40e6;
using Clock = std::chrono::steady_clock;

// Wall time of each stage in milliseconds, in the order the stages ran.
class StageTimer {
 public:
  void done(const std::string& stage) {
    auto now = Clock::now();
    times_[stage] = std::chrono::duration<double, std::milli>(now - last_).count();
    last_ = now;
  }
  const nlohmann::ordered_json& json() const { return times_; }

 private:
  Clock::time_point last_ = Clock::now();
  nlohmann::ordered_json times_ = nlohmann::ordered_json::object();
};

cv::Vec3b bgr(const Rgb& c) { return cv::Vec3b(c.b, c.g, c.r); }

// The relax mask in stitch-grid coordinates: resampled exactly as the picture (same size,
// same orientation and gauge), dark mask pixels (< 128) become relaxed stitches.
cv::Mat load_relax(const PathAccess& access, const fs::path& mask_file, const cv::Size& picture,
                   const KnitParams& p, const ImageLimits& limits) {
  cv::Mat mask = to_8bit(load_image(access, mask_file, limits));
  cv::Mat resized;
  cv::resize(mask, resized, picture, 0, 0, cv::INTER_NEAREST);
  cv::Mat grey = knit::to_stitch_grid(resized, p.gauge());
  return grey < 128;
}

double pct(long part, long whole) { return whole > 0 ? 100.0 * part / whole : 100.0; }


}  // namespace

ConvertResult convert_knit(const ConvertRequest& req) {
  StageTimer timer;
  const KnitParams p = read_knit_params(req.params, req.params_source);
  const std::string input_name = safe_text(req.input.filename().string());  // names are data
  report_progress(req, 0.0);

  ImageHeader header = probe_image(req.input);
  // The row limit from the header, before decoding (a tall picture is refused at once).
  const long rows = knit::stitch_rows(static_cast<long>(header.width), static_cast<long>(header.height), p.gauge());
  if (rows > knit::kMaxRows) {
    char metres[32];
    std::snprintf(metres, sizeof metres, "%.1f", knit::kMaxRows / p.rows_per_10cm / 10);
    throw ConvertError(input_name + ": the pattern would have " + std::to_string(rows) + " rows of " +
                       std::to_string(p.width) + " stitches, more than the limit of " +
                       std::to_string(knit::kMaxRows) + " rows (" + metres + " m of fabric at " +
                       std::to_string(static_cast<int>(std::lround(p.rows_per_10cm))) +
                       " rows per 10 cm); lower the width or use a shorter picture");
  }
  cv::Mat image = to_8bit(load_image(req.input, req.limits));
  timer.done("load");
  report_progress(req, 0.05);

  cv::Mat gray = knit::to_stitch_grid(image, p.gauge());
  if (p.invert) gray = 255 - gray;
  knit::FloatRules rules;
  rules.max_float = p.max_float;
  rules.anchoring = p.anchoring;
  fs::path relax_file = resolve_relax_mask(p, req.input);
  if (!relax_file.empty()) {
    // The parameter is opened as its origin allows (confined when a job set it); the
    // NAME.EXT.relax.png beside the input is job content too.
    const PathAccess access = p.relax_mask.empty() ? req.paths.companion(input_name)
                                                   : req.paths.access("relax_mask", req.input.parent_path());
    rules.relax = load_relax(access, relax_file, image.size(), p, req.limits);
  }
  timer.done("stitch_grid");
  report_progress(req, 0.1);

  const knit::Dither requested = p.dither_method();
  knit::SolverParams sp;
  sp.solver = p.solver_kind();
  sp.seed = p.seed;
  sp.rw_n = p.rw_n;
  sp.rw_q = p.rw_q;
  sp.rw_m = p.rw_m;
  const bool search = requested == knit::Dither::automatic || p.solver_auto();
  knit::Dither method = requested;
  knit::AutoResult chosen;
  cv::Mat start, grid;
  knit::SolveStats stats;
  if (search) {
    // Measured, not guessed: each candidate pair is solved and scored (auto_choice.h).
    const std::vector<knit::Dither> dithers =
        requested == knit::Dither::automatic ? knit::auto_dither_candidates() : std::vector<knit::Dither>{requested};
    const std::vector<knit::Solver> solvers =
        p.solver_auto() ? knit::auto_solver_candidates() : std::vector<knit::Solver>{sp.solver};
    chosen = knit::choose_by_measurement(gray, rules, dithers, solvers, p.threshold, sp, 2);
    method = chosen.candidates[chosen.chosen].dither;
    sp.solver = chosen.candidates[chosen.chosen].solver;
    start = chosen.start;
    grid = chosen.grid;
    stats = chosen.stats;
    timer.done("auto_search");  // every candidate's dither, solve and SSIM
  } else {
    start = knit::dither(gray, method, p.threshold);
    timer.done("dither");
    report_progress(req, 0.15);
    grid = start.clone();
    sp.progress = [&req](double f) { report_progress(req, 0.15 + 0.65 * f); };
    stats = knit::solve(grid, rules, sp);
  }
  const std::string solver_used = knit::solver_name(sp.solver);
  timer.done("solve");
  report_progress(req, 0.8);

  const long total = static_cast<long>(grid.total());
  const long consistent_before = knit::consistent_stitches(start, rules);
  const long consistent_after = knit::consistent_stitches(grid, rules);
  const int longest = knit::longest_float(grid, rules);
  const knit::BlurredSsim ssim(gray, 2.0);
  const double similarity = ssim(grid);
  const double similarity_start = ssim(start);
  const long relaxed = rules.relax.empty() ? 0 : cv::countNonZero(rules.relax);
  timer.done("metrics");

  std::error_code ec;
  fs::create_directories(req.output_dir, ec);
  if (ec) {
    throw ConvertError(req.output_dir.string() + ": cannot create output folder: " + ec.message());
  }
  const fs::path& out = req.output_dir;

  cv::Mat pattern = 255 - grid * 255;  // 1 (contrast) -> black, 0 -> white
  write_output_png(out / kKnitPatternFile, pattern);
  timer.done("pattern_png");

  knit::PreviewStyle style;
  style.background = bgr(p.rgb[0]);
  style.contrast = bgr(p.rgb[1]);
  style.stitch_px = std::clamp(4000 / grid.cols, 1, 12);  // keeps the render near 4000 px wide
  style.stitch_aspect = p.stitches_per_10cm / p.rows_per_10cm;
  // ... and within kPreviewMaxPixels, smaller stitches for long patterns.
  auto preview_pixels = [&](int w) {
    const double h = std::max(1.0, std::round(w * style.stitch_aspect));
    return static_cast<double>(grid.cols) * w * grid.rows * h;
  };
  while (style.stitch_px > 1 && preview_pixels(style.stitch_px) > kPreviewMaxPixels) --style.stitch_px;
  // Encoded from the grid's structure (knit_preview_png.h), the same pixels as the render.
  const std::string preview = encode_preview_png(grid, style);
  if (!preview.empty()) write_output(out / "preview.png", preview);
  else write_output_png(out / "preview.png", knit::render_preview(grid, style));
  timer.done("preview_png");
  report_progress(req, 0.85);

  ChartInfo chart;
  chart.title = input_name;
  chart.max_float = p.max_float;
  chart.solver = solver_used;
  chart.colors = p.rgb;
  chart.color_names = p.colors;
  chart.first_row_top = p.first_row == "top";
  chart.progress = [&req](double f) { report_progress(req, 0.85 + 0.1 * f); };
  const int pages = write_chart_pdf(grid, chart, out / "chart.pdf");
  timer.done("chart_pdf");
  report_progress(req, 0.95);

  // What pattern.k holds (knitout_longest_float: each yarn from stitch to stitch, turning at
  // its last stitch of a row); an incomplete solution is said to be not knittable as is, in the
  // file, report.json's warnings and to the knitting device.
  const int knitout_float = knitout_longest_float(grid, p.first_row == "top");
  const bool knittable = stats.violations_after == 0;
  std::vector<std::string> warnings;
  std::string not_knittable;  // what pattern.k's header says after "NOT KNITTABLE AS IS: "
  if (!knittable) {
    not_knittable = "floats up to " + std::to_string(knitout_float) + " needles, limit " +
                    std::to_string(p.max_float) + " (solver \"" + p.solver + "\" left " +
                    std::to_string(stats.violations_after) + " violations); use solver = \"hybrid\" or \"gsat\"";
    warnings.push_back("not knittable as is: " + not_knittable);
  } else if (knitout_float > p.max_float) {
    warnings.push_back("pattern.k holds floats up to " + std::to_string(knitout_float) +
                       " needles, limit " + std::to_string(p.max_float) +
                       ": where a yarn turns between rows around a free edge run (anchoring = false) or in "
                       "the relaxed area (relax_mask), as chosen for hand knitting");
  }

  KnitoutOptions ko;
  ko.not_knittable = not_knittable;
  if (knittable) ko.notes = warnings;
  ko.stitches_per_10cm = p.stitches_per_10cm;
  ko.title = "atelier knit pattern from " + input_name;
  ko.first_row_top = p.first_row == "top";
  write_output(out / "pattern.k", make_knitout(grid, ko));
  timer.done("knitout");

  ConvertResult result;
  result.outputs = {kKnitPatternFile, "preview.png", "chart.pdf", "pattern.k", "report.json"};

  nlohmann::ordered_json params = {
      {"width", p.width},
      {"stitches_per_10cm", p.stitches_per_10cm},
      {"rows_per_10cm", p.rows_per_10cm},
      {"orientation", p.orientation},
      {"dither", p.dither},
      {"dither_used", knit::dither_name(method)},
      {"threshold", p.threshold},
      {"max_float", p.max_float},
      {"anchoring", p.anchoring},
      {"relax_mask", safe_text(relax_file.string())},
      {"solver", p.solver},
      {"seed", p.seed},
      {"rw_n", p.rw_n},
      {"rw_q", p.rw_q},
      {"rw_m", p.rw_m},
      {"invert", p.invert},
      {"colors", {p.colors[0], p.colors[1]}},
      {"first_row", p.first_row},
  };
  nlohmann::ordered_json r;
  r["kind"] = "knit";
  r["input"] = {{"file", input_name},
                {"format", header.format},
                {"width", image.cols},
                {"height", image.rows},
                {"channels", image.channels()}};
  r["parameters"] = params;
  if (requested == knit::Dither::automatic) {
    r["dither_auto_choice"] = knit::dither_name(method);
    r["dither_auto_reason"] = chosen.reason;
  }
  if (p.solver_auto()) {
    r["solver_auto_choice"] = solver_used;
    r["solver_auto_reason"] = chosen.reason;
  }
  if (search) {
    nlohmann::ordered_json tried = nlohmann::ordered_json::array();
    for (const knit::AutoCandidate& c : chosen.candidates)
      tried.push_back({{"dither", knit::dither_name(c.dither)},
                       {"solver", knit::solver_name(c.solver)},
                       {"similarity", c.similarity},
                       {"violations", c.violations},
                       {"flips", c.flips}});
    r["auto_search"] = {{"candidates", tried},
                        {"chosen", chosen.chosen},
                        {"reason", chosen.reason}};
  }
  r["grid"] = {{"stitches", grid.cols}, {"rows", grid.rows}};
  // The picture row knitted first; the knitting machine's device reads it (knit_order.h).
  r["first_row"] = p.first_row;
  r["conflicts_before"] = stats.violations_before;
  r["conflicts_after"] = stats.violations_after;
  r["consistent_before_pct"] = pct(consistent_before, total);
  r["consistent_after_pct"] = pct(consistent_after, total);
  r["flips"] = stats.flips;
  r["random_walk_flips"] = stats.random_walk_flips;
  r["search_flips"] = stats.search_flips;
  r["longest_float"] = knitout_float;  // the float pattern.k holds
  r["longest_constrained_float"] = longest;  // the solver's measure (free edge runs, relax excluded)
  r["max_float"] = p.max_float;
  r["solver"] = solver_used;  // what ran ("auto" resolved); parameters.solver as configured
  r["complete"] = stats.violations_after == 0;
  r["knittable"] = knittable;   // false: the knitting device refuses the job
  r["warnings"] = warnings;     // shown by atelierctl show
  r["relaxed_stitches"] = relaxed;
  r["similarity"] = similarity;
  r["similarity_start"] = similarity_start;
  r["similarity_note"] = "blurred SSIM (sigma 2 stitches) against the grey stitch grid" +
                         std::string(p.invert ? " (inverted, as dithered)" : "");
  r["chart_pages"] = pages;
  timer.done("report");
  r["timings_ms"] = timer.json();
  r["outputs"] = result.outputs;
  return finish_report(req, out, r, std::move(result));
}

}  // namespace atelier

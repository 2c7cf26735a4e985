#include "convert/lace/lace_job_checks.h"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "algorithms/lace/fitness.h"
#include "algorithms/lace/instructions.h"
#include "algorithms/lace/transfers.h"
#include "convert/common/display_text.h"
#include "convert/common/param_table.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;

// A start chart file is a chart.json or an instructions.txt: a few kilobytes. Anything far
// larger is not one (and would only be read into memory to be refused).
constexpr std::uintmax_t kMaxStartChartBytes = 4 << 20;

// Read through `access` (confined to the spool when a job named the file). Throws
// std::invalid_argument "PATH: problem" (the caller adds the file and key).
std::string read_text(const PathAccess& access, const fs::path& file) {
  const PathAccess quiet = access.relabeled("", "");
  if (quiet.is_dir(file))
    throw std::invalid_argument(display_path(file) + ": a folder, not a chart file (chart.json or instructions.txt)");
  try {
    return quiet.read_text(file, kMaxStartChartBytes);
  } catch (const ConvertError& e) {
    throw std::invalid_argument(e.what());
  }
}

// What one job may ask for, so that a job file cannot take the machine's memory or run for
// days (measured on 2 cores: 500 x 200 generations of 200 x 200 charts take ~1.1 GB and ~5
// min; 20000 individuals take ~4 s a generation for their niche counts alone).
constexpr double kMaxPopulationCells = 2e7;   // population x width x rows: the forests in memory
constexpr double kMaxEvolveCells = 4e9;       // x generations: evaluation and breeding
constexpr double kMaxEvolvePairs = 2e10;      // population^2 x generations: fitness sharing
constexpr double kMaxSwatchStitches = 5e5;    // (width x repeats_wide) x (rows x repeats_high)

}  // namespace

// The start chart named by the parameters: a chart.json, an instructions.txt, or inline rows,
// within what evolve() takes (EvolveParams::start). Every problem is a ParamError
// "FILE:LINE: key 'start_chart': <chart file or 'inline rows'>: <problem>".
std::optional<LaceChartFile> load_start_chart(const LaceParams& p, const PathAccess& access) {
  if (!p.start_chart_file && p.start_rows.empty()) return std::nullopt;
  // A file's own messages start with its path (read_text, the parsers below add it).
  const std::string where = p.start_chart_file ? display_path(*p.start_chart_file) : std::string("inline rows");
  try {
    LaceChartFile chart;
    if (p.start_chart_file) {
      const fs::path& file = *p.start_chart_file;
      std::string text;
      try {
        text = read_text(access, file);
      } catch (const std::invalid_argument& e) {
        throw ParamError(p.start_chart_where + e.what());
      }
      try {
        if (file.extension() == ".json") {
          chart = lace_chart_from_json_text(text, "");
        } else {
          const lace::ParsedInstructions parsed = lace::parse_instructions(text);
          chart = LaceChartFile{parsed.chart, parsed.cast_on};
        }
      } catch (const std::invalid_argument& e) {
        // The parsers quote what they could not read: never echo a file's bytes.
        throw std::invalid_argument(redact_quoted(e.what(), text));
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
toml::table lace_job_table(const ConvertRequest& req) {
  if (req.input.empty() || req.input == "-" || req.input.extension() != ".toml") return {};
  try {
    return toml::parse_file(req.input.string());
  } catch (const toml::parse_error&) {
    return {};
  }
}

// "FILE:LINE: key 'KEY': ", the job file's line when the key is in it.
std::string lace_job_key_where(const toml::table& job, const ConvertRequest& req, const std::string& key) {
  if (job.contains(key)) return lace_key_where(job, key, req.input.string());
  return lace_key_where(req.params, key, req.params_source);
}

// Throws ParamError naming the key that takes the job over a limit. width and rows are the
// chart's (the start chart's when there is one).
void check_lace_budget(const LaceParams& p, int width, int rows, const toml::table& job,
                       const ConvertRequest& req) {
  const toml::table& params = req.params;
  const double cells = static_cast<double>(width) * rows, pop = p.population, gens = p.generations;
  auto fail = [&](const std::string& key, const std::string& what) {
    throw ParamError(lace_job_key_where(job, req, key) + what);
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
                   (p.start_chart_file ? display_path(*p.start_chart_file) : std::string("inline rows")) +
                   ": with generations = 0 the result is this chart, but it breaks the constraints: " + list);
}

}  // namespace atelier

// A lace job file (incoming/NAME.toml with kind = "lace"), checked as convert_lace checks it
// before evolving anything: its parameters over the [lace] defaults (read_lace_params), an
// inline start chart in written instructions (load_start_chart), the memory/time/swatch budget
// and, for generations = 0, the start chart's feasibility. A start_chart naming a file is not
// followed (the target reads no files the input names).
#include <string>
#include <string_view>
#include <toml++/toml.h>

#include "algorithms/lace/evolve.h"
#include "base/error.h"
#include "convert/common/param_table.h"
#include "convert/convert.h"
#include "convert/lace/lace_job_checks.h"
#include "convert/lace/lace_params.h"
#include "tests/fuzz/fuzz_targets.h"

int fuzz_lace_job(const uint8_t* data, size_t size) {
  if (size > atelier::fuzz::kMaxFuzzInput) return 0;
  const std::string text(reinterpret_cast<const char*>(data), size);
  toml::table job;
  try {
    job = toml::parse(text, std::string_view{"job.toml"});
  } catch (const toml::parse_error&) {
    return 0;
  }
  atelier::ConvertRequest req;
  req.input = "job.toml";
  req.params = job;
  req.params_source = "job.toml";
  try {
    atelier::LaceParams p = atelier::read_lace_params(req.params, req.params_source);
    if (job.contains("start_chart"))
      p.start_chart_where = atelier::lace_job_key_where(job, req, "start_chart");
    p.start_chart_file.reset();
    const auto start = atelier::load_start_chart(p, atelier::PathAccess{});
    atelier::check_lace_budget(p, start ? start->cast_on : p.width,
                               start ? static_cast<int>(start->chart.rows.size()) : p.rows, job, req);
    if (start && p.generations == 0) {
      atelier::lace::EvolveParams ep;
      ep.width = p.width;
      ep.rows = p.rows;
      ep.weights = {p.holes, p.knit_length, p.depth, p.symmetry};
      ep.width_tolerance = p.width_tolerance;
      ep.start = start->chart;
      ep.start_cast_on = start->cast_on;
      atelier::check_start_feasible(*start, ep, p);
    }
  } catch (const atelier::BadInput&) {
  }
  return 0;
}

// What a lace job may ask for, checked before any work: the start chart it names (read and
// validated), and limits on memory and time beyond each parameter's own range. Every problem
// is a ParamError "FILE:LINE: key 'KEY': ..." naming the job file's line when the key is in it
// (the merged parameters' toml++ copies have lost their source).
// Reads the job file and the start chart file; no other I/O. Thread-safe per request.
#pragma once

#include <optional>
#include <string>
#include <toml++/toml.h>

#include "algorithms/lace/evolve.h"
#include "convert/convert.h"
#include "convert/lace/lace_chart_json.h"
#include "convert/lace/lace_params.h"

namespace atelier {

// The job file's own table (its nodes know their file and line). Empty for "-", a non-TOML
// input or one that does not parse (atelier-convert has parsed it already).
toml::table lace_job_table(const ConvertRequest& req);

// "FILE:LINE: key 'KEY': ", the job file's line when the key is in it.
std::string lace_job_key_where(const toml::table& job, const ConvertRequest& req, const std::string& key);

// The start chart named by the parameters: a chart.json, an instructions.txt, or inline rows,
// within what evolve() takes (EvolveParams::start); nullopt when none is named.
std::optional<LaceChartFile> load_start_chart(const LaceParams& p, const PathAccess& access);

// Throws when the job would take too much memory or time: population x width x rows <= 2e7,
// x generations <= 4e9, population^2 x generations <= 2e10, a swatch of at most 500000
// stitches. width and rows are the chart's (the start chart's when there is one).
void check_lace_budget(const LaceParams& p, int width, int rows, const toml::table& job,
                       const ConvertRequest& req);

// With generations = 0 the result is the start chart itself: one that breaks a constraint
// (including the evolution's extra ones) is the job file's mistake, named here.
void check_start_feasible(const LaceChartFile& start, const lace::EvolveParams& ep, const LaceParams& p);

}  // namespace atelier

// One job's conversion, as shared by atelierd (which runs it in an `atelier-convert`
// child process) and the atelier-convert tool: input file + parameters -> output folder.
//
// Not thread-safe per request; separate requests may run concurrently.
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <toml++/toml.h>
#include <vector>

#include "convert/common/convert_error.h"
#include "convert/common/image_input.h"
#include "convert/common/job_paths.h"

namespace atelier {

// Another target converted together with the primary one (parquetry only, paper 4.2: the
// targets' patches share one priority queue on the same wood). Outputs go to output_dir;
// Its pieces are labelled in the stock with output_dir's name (the job id in the daemon).
struct ExtraTarget {
  std::filesystem::path input, output_dir;
};

struct ConvertRequest {
  std::string kind;
  std::filesystem::path input;        // the image (or job file); read only. For a job-file
                                      // kind, its parameters are already merged into params
                                      // (atelier-convert does it), and "-" means no file
  toml::table params;                 // merged: config section, sidecar, --set
  std::string params_source = "parameters";  // for error messages
  std::filesystem::path output_dir;   // created if missing; outputs are written here
  ImageLimits limits;
  // The conversion's memory budget in MB ([limits] job_memory_mb, atelier-convert --memory-mb);
  // 0 = none. Kinds that can estimate their peak memory refuse a job above it before starting.
  uint64_t memory_mb = 0;
  // What the conversion may read for path-valued parameters that a job set (sidecar, job file,
  // --set): confined to the spool and [spool] allow_paths when atelier-convert was given
  // --confine, unconfined otherwise (job_paths.h).
  JobPaths paths;
  // Further targets planned with this one (kind parquetry only; ConvertError otherwise).
  // Each gets its own outputs; the result describes the primary target.
  std::vector<ExtraTarget> together;
  // Fraction done in [0, 1]; may be empty. Called from the converting thread.
  std::function<void(double)> progress;
};

struct ConvertResult {
  nlohmann::json report;              // as written to report.json
  std::vector<std::string> outputs;   // file names written into output_dir
};

// Tells the request's progress callback (if any) the fraction done, clamped to [0, 1].
void report_progress(const ConvertRequest& req, double fraction);

// The last step of a single-target kind: writes `report` into `out` as report.json
// (report_file_name(), indented, one trailing newline), reports progress 1 and returns
// `result` with the report kept in it (the daemon logs and stores that copy).
ConvertResult finish_report(const ConvertRequest& req, const std::filesystem::path& out,
                            const nlohmann::ordered_json& report, ConvertResult result);

// Runs the conversion and writes every output of the kind plus report.json.
// Throws ConvertError (bad input), ParamError (bad parameters).
ConvertResult convert(const ConvertRequest& request);

}  // namespace atelier

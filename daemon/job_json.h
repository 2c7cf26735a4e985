// JSON views of jobs for the control protocol (docs/control-protocol.md). Pure; any thread.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "daemon/store.h"

namespace atelier {

// "2026-11-22T11:31:50.123Z" from milliseconds since the epoch.
std::string iso8601_utc(int64_t ms);

// What a job's progress counts: "percent" while it converts (and for a job no device ran),
// then the machine's steps: "rows" knitted or "lines" of G-code acknowledged.
std::string progress_unit(const Job& job);

// id, kind, name, state, reason, device, created, updated, output_dir,
// progress {done, total, unit}.
nlohmann::json job_to_json(const Job& job);

// The converter's time estimate in seconds from a job's report.json: its "estimated_time_s",
// at the top (cut) or in one of its sections ("laser" for parquetry, "engrave" for sketch);
// nullopt when the report has none (a job no laser runs).
std::optional<double> estimated_seconds(const nlohmann::json& report);

// The warnings a converter put in a job's report.json ("warnings": strings it
// wants the user to read before the job goes to a machine, e.g. "not knittable as is: ...");
// empty when the report has none or is not an object.
std::vector<std::string> report_warnings(const nlohmann::json& report);

// The job's reason when its conversion finished: `base` ("converted; waiting for knitter"),
// then the first warning and how many more `atelierctl show` lists.
std::string converted_reason(const std::string& base, const std::vector<std::string>& warnings);

nlohmann::json events_to_json(const std::vector<JobEvent>& events);

}  // namespace atelier

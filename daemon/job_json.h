// JSON views of jobs for the control protocol (docs/control-protocol.md). Pure.
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "daemon/store.h"

namespace atelier {

// "2026-11-22T11:31:50.123Z" from milliseconds since the epoch.
std::string iso8601_utc(int64_t ms);

// id, kind, name, state, reason, device, created, updated, output_dir, progress.
nlohmann::json job_to_json(const Job& job);

nlohmann::json events_to_json(const std::vector<JobEvent>& events);

}  // namespace atelier

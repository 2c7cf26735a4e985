#include "daemon/job_json.h"

#include <ctime>

namespace atelier {

std::string iso8601_utc(int64_t ms) {
  std::time_t secs = static_cast<std::time_t>(ms / 1000);
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char buf[40];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  char out[48];
  std::snprintf(out, sizeof out, "%s.%03dZ", buf, static_cast<int>(ms % 1000));
  return out;
}

nlohmann::json job_to_json(const Job& job) {
  return {{"id", job.id},
          {"kind", job.kind},
          {"name", job.name},
          {"state", state_name(job.state)},
          {"reason", job.reason},
          {"device", job.device},
          {"created", iso8601_utc(job.created_ms)},
          {"updated", iso8601_utc(job.updated_ms)},
          {"output_dir", job.output_dir},
          {"progress", {{"done", job.progress_done}, {"total", job.progress_total}}}};
}

nlohmann::json events_to_json(const std::vector<JobEvent>& events) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& e : events)
    out.push_back({{"at", iso8601_utc(e.at_ms)}, {"from", e.from}, {"to", e.to}, {"reason", e.reason}});
  return out;
}

}  // namespace atelier

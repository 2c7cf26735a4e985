#include "daemon/job_json.h"

#include <ctime>

#include "convert/kinds.h"

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

std::string progress_unit(const Job& job) {
  // A conversion counts percent; from then on the machine's own steps (a job that no device
  // ran only ever counted its conversion).
  if (job.device.empty() || job.state == JobState::queued || job.state == JobState::converting)
    return "percent";
  const KindInfo* kind = find_kind(job.kind);
  switch (kind ? kind->machine_input : MachineInput::none) {
    case MachineInput::knit_pattern:
    case MachineInput::lace_chart:
      return "rows";
    case MachineInput::gcode:
      return "lines";
    case MachineInput::stitch_files:
    case MachineInput::none:
      break;
  }
  return "percent";
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
          {"progress",
           {{"done", job.progress_done}, {"total", job.progress_total}, {"unit", progress_unit(job)}}}};
}

std::optional<double> estimated_seconds(const nlohmann::json& report) {
  if (!report.is_object()) return std::nullopt;
  auto read = [](const nlohmann::json& o) -> std::optional<double> {
    auto it = o.find("estimated_time_s");
    if (it == o.end() || !it->is_number()) return std::nullopt;
    return it->get<double>();
  };
  if (auto s = read(report)) return s;
  for (const auto& [key, value] : report.items())
    if (value.is_object())
      if (auto s = read(value)) return s;
  return std::nullopt;
}

std::vector<std::string> report_warnings(const nlohmann::json& report) {
  std::vector<std::string> out;
  if (!report.is_object()) return out;
  const auto it = report.find("warnings");
  if (it == report.end() || !it->is_array()) return out;
  for (const auto& w : *it)
    if (w.is_string()) out.push_back(w.get<std::string>());
  return out;
}

std::string converted_reason(const std::string& base, const std::vector<std::string>& warnings) {
  if (warnings.empty()) return base;
  std::string out = base + "; warning: " + warnings.front();
  if (warnings.size() > 1) out += " (and " + std::to_string(warnings.size() - 1) + " more: atelierctl show)";
  return out;
}

nlohmann::json events_to_json(const std::vector<JobEvent>& events) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& e : events)
    out.push_back({{"at", iso8601_utc(e.at_ms)}, {"from", e.from}, {"to", e.to}, {"reason", e.reason}});
  return out;
}

}  // namespace atelier

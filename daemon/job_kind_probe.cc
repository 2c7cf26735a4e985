#include "daemon/job_kind_probe.h"

#include <memory>
#include <mutex>
#include <optional>

#include "daemon/child_process.h"
#include "daemon/conversion_runner.h"

namespace fs = std::filesystem;

namespace atelier {

JobFileKind probe_job_kind(const fs::path& exe, const fs::path& file, const std::string& shown_name,
                           const JobKindProbeLimits& limits) {
  const ChildResult child = run_child({exe.string(), "--job-kind", file.string()},
                                      {limits.timeout, limits.cpu_seconds, limits.memory_bytes});
  if (child.end == ChildResult::End::timed_out)
    return {"", shown_name + ": reading the job file took longer than " +
                    std::to_string(limits.timeout.count() / 1000.0).substr(0, 4) +
                    " s; is it a TOML job file?"};
  if (child.out_of_cpu())
    return {"", shown_name + ": reading the job file used more than " + std::to_string(limits.cpu_seconds) +
                    " s of CPU; is it a TOML job file?"};
  if (child.end == ChildResult::End::signaled)
    return {"", shown_name + ": the TOML reader stopped with signal " + std::to_string(child.code) +
                    " while reading the job file (out of memory, or input that crashes it); fix the file"};
  if (child.ok()) {
    const std::string kind = first_line(child.out);
    if (!kind.empty()) return {kind, ""};
    return {"", shown_name + ": the job file's kind could not be read"};
  }
  std::string message = first_line(child.err);
  if (message.rfind("error: ", 0) == 0) message.erase(0, 7);
  // The child names the file by its own name; anything else it says is dropped rather than
  // passed on, so an unexpected message can never carry the file's content.
  if (message.rfind(shown_name + ":", 0) != 0)
    message = shown_name + ": the job file could not be read (atelier-convert exit code " +
              std::to_string(child.code) + ")";
  return {"", message};
}

JobKindProbe subprocess_job_kind_probe(const JobKindProbeLimits& limits) {
  auto exe = std::make_shared<std::optional<fs::path>>();
  auto mu = std::make_shared<std::mutex>();
  return [exe, mu, limits](const fs::path& file, const std::string& shown_name) {
    fs::path path;
    {
      std::lock_guard lock(*mu);
      if (!*exe) *exe = find_convert_executable();
      path = **exe;
    }
    return probe_job_kind(path, file, shown_name, limits);
  };
}

}  // namespace atelier

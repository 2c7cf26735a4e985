// Runs one job's conversion in an `atelier-convert` child process, so that a decoder crash,
// a runaway allocation or a hung conversion costs one job, never the daemon. The child gets
// the config's defaults for the kind on stdin (`--params /dev/stdin`), the job's own
// overrides as `--set`, and reports progress on fd 3. Its sidecar (NAME.EXT.toml beside the
// input) is applied by atelier-convert itself, between the two.
//
// Time: SubprocessRunner measures the task's timeout on the Clock given (real_clock() in the
// daemon; a test moves a FakeClock past it). The child is a real process, so its pipes are
// polled in real time, 100 ms at a time, which is also how soon a cancel is seen.
// Threading: run() blocks the calling worker thread; several run() calls may proceed at once.
#pragma once

#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "base/clock.h"
#include "convert/common/image_input.h"

namespace atelier {

struct ConversionTask {
  int64_t job_id = 0;
  std::string kind;
  std::filesystem::path input;        // in work/<id>/
  std::filesystem::path output_dir;   // work/<id>/
  std::string defaults_toml;          // the config's [kind] table as TOML text
  std::vector<std::string> sets;      // "key=value" overrides of the job
  // Further targets planned in the same conversion (parquetry, paper 4.2): input and output
  // folder of each, passed as `--with INPUT OUTPUT_DIR`. Their sidecars are not read: the
  // scheduler only batches jobs whose own overrides equal the first job's.
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> together;
  ImageLimits limits;
  std::chrono::seconds timeout{600};
  // Only parse and check the parameters (`atelier-convert --check`): no input is read, no
  // output written. The daemon checks a submit's --set values this way.
  bool check_only = false;
};

struct ConversionOutcome {
  enum class Status { ok, failed, canceled, timed_out } status = Status::failed;
  std::string message;  // for failed: the converter's error (names the file and the problem)
};

class ConversionRunner {
 public:
  virtual ~ConversionRunner() = default;
  // `progress` gets fractions in [0, 1]; `cancel` is polled at least every 100 ms.
  virtual ConversionOutcome run(const ConversionTask& task,
                                const std::function<void(double)>& progress,
                                const std::atomic<bool>& cancel) = 0;
};

class SubprocessRunner : public ConversionRunner {
 public:
  // `convert_exe`: path of atelier-convert. `memory_limit_bytes`: the child's memory budget
  // ([limits] job_memory_mb): its RLIMIT_AS, also passed as `--memory-mb` so that the
  // converter reports running out as "NAME: needs more than N MB (limits.job_memory_mb)";
  // a child killed by SIGKILL that the runner did not send (the kernel's OOM killer) fails
  // with that reason too. `clock` (borrowed; must outlive the runner): what task.timeout is
  // measured on.
  explicit SubprocessRunner(std::filesystem::path convert_exe,
                            uint64_t memory_limit_bytes = 2048ull << 20, Clock& clock = real_clock());
  ConversionOutcome run(const ConversionTask& task, const std::function<void(double)>& progress,
                        const std::atomic<bool>& cancel) override;

 private:
  std::filesystem::path exe_;
  uint64_t memory_limit_;
  Clock& clock_;
};

// atelier-convert beside the running program, or in ../bin; $ATELIER_CONVERT wins.
// Throws std::runtime_error when none is found.
std::filesystem::path find_convert_executable();

}  // namespace atelier

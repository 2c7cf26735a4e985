// A machine the daemon drives: one worker thread per [[device]], taking the `ready` jobs of
// its kinds one at a time. Implementations (on DeviceWorker): KnitDevice (AYAB knitting
// machines), LaserDevice (GRBL laser cutters).
//
// Threading: all public methods are thread-safe; the worker owns the machine link.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>

#include "base/error.h"
#include "daemon/config.h"

namespace atelier {

struct Job;

// What `atelierctl start ID --from-row N --start-needle K` asks of a knitting machine, or
// `--start-from bed|origin|here` of a laser; they override the job's sidecar keys
// (convert/common/job_start.h). Empty for a plain start.
struct StartOptions {
  std::optional<int> from_row;              // 1-based row in knitting order
  std::optional<std::string> start_needle;  // as typed: "L20", "R5" or "20" (job_start.h)
  std::optional<std::string> start_from;    // laser placement as typed: "bed", "origin", "here"
  bool empty() const { return !from_row && !start_needle && !start_from; }
};

// An operator's command to a laser's controller outside any job (`atelierctl laser ...`).
struct MachineCommand {
  enum class Op { unlock, home, jog, origin, send } op = Op::send;
  double dx_mm = 0, dy_mm = 0;  // jog: relative move, mm
  double feed_mm_min = 0;       // jog: mm/min; 0 = the device's frame feed
  std::string line;             // send: one line for the controller, without newline
  int64_t uid = -1;             // the client who asked (console log)
};

class Device {
 public:
  virtual ~Device() = default;
  virtual const DeviceConfig& config() const = 0;
  // {"name", "driver", "port", "state" (offline|online|busy), "job" (id or null), "detail"}
  virtual nlohmann::json describe() const = 0;
  // A job may have become ready (or armed): look at the store again.
  virtual void wake() = 0;
  // Arms a ready job on a device without autostart, with `options` for the job (knitting
  // machines only). Throws std::runtime_error (BadInput naming the job and the values) if not
  // possible; then nothing is armed.
  virtual void start(int64_t job_id, const StartOptions& options = {}) = 0;
  // Whether a ready `job` of this device's kinds starts without `atelierctl start`: the
  // device's autostart, or (knitting machines) the job's own `autostart = true`.
  virtual bool autostarts(const Job& job) const {
    (void)job;
    return config().autostart;
  }
  // Cancels a ready job of this device's kinds (at once) or the job it is running (it stops
  // after the current row). Returns false if the job is neither.
  virtual bool cancel(int64_t job_id) = 0;
  // Knitting: continues an interrupted job from pattern row `from_row` (1-based). Laser:
  // `from_row` 0 releases a feed hold. Throws std::runtime_error naming the problem.
  virtual void resume(int64_t job_id, int from_row) = 0;
  // Laser: feed hold on the running job (motion stops, the beam is off, position is kept).
  virtual void hold(int64_t job_id) {
    throw BadInput("job " + std::to_string(job_id) + ": " + config().name +
                             " cannot hold a job; only lasers can");
  }
  // Laser: traces a ready job's bounding box with the beam off, soon (asynchronously).
  virtual void frame(int64_t job_id) {
    throw BadInput("job " + std::to_string(job_id) + ": " + config().name +
                             " is not a laser; framing traces a laser job's outline");
  }
  // Laser: runs `cmd` on the controller (on the worker thread, which owns the port) and waits
  // for it: {"device", "lines": [{"sent", "reply": [..]}], "effect"}. Every line sent is logged
  // in the store's console log. Throws std::runtime_error (BadInput) naming the problem: not a
  // laser, offline, a job running or held, a line with real-time bytes or several lines, a jog
  // leaving the work area, or the controller's own error.
  virtual nlohmann::json machine_command(const MachineCommand& cmd) {
    (void)cmd;
    throw BadInput(config().name + " is not a laser; only a laser's controller takes operator commands");
  }
  // Stops the worker (a running job is left interrupted, never restarted on its own).
  virtual void stop() = 0;
  bool takes(const std::string& kind) const {
    for (const auto& k : config().kinds)
      if (k == kind) return true;
    return false;
  }
};

}  // namespace atelier

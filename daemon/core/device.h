// A machine the daemon drives: one worker thread per [[device]], taking the `ready` jobs of
// its kinds one at a time. Implementations: KnitDevice (AYAB knitting machines).
//
// Threading: all public methods are thread-safe; the worker owns the machine link.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "daemon/core/config.h"

namespace atelier {

class Device {
 public:
  virtual ~Device() = default;
  virtual const DeviceConfig& config() const = 0;
  // {"name", "driver", "port", "state" (offline|online|busy), "job" (id or null), "detail"}
  virtual nlohmann::json describe() const = 0;
  // A job may have become ready (or armed): look at the store again.
  virtual void wake() = 0;
  // Arms a ready job on a device without autostart. Throws std::runtime_error if not possible.
  virtual void start(int64_t job_id) = 0;
  // Cancels a ready job of this device's kinds (at once) or the job it is running (it stops
  // after the current row). Returns false if the job is neither.
  virtual bool cancel(int64_t job_id) = 0;
  // Continues an interrupted job from pattern row `from_row` (1-based). Throws
  // std::runtime_error naming the problem (bad row, device offline).
  virtual void resume(int64_t job_id, int from_row) = 0;
  // Stops the worker (a running job is left interrupted, never restarted on its own).
  virtual void stop() = 0;
  bool takes(const std::string& kind) const {
    for (const auto& k : config().kinds)
      if (k == kind) return true;
    return false;
  }
};

}  // namespace atelier

// A Brother knitting machine behind AYAB (drivers/ayab/): knits `ready` knit jobs row by row.
//
// Life of a job here: ready -> running (pattern.png planned onto the needle bed, session
// opened, rows sent as the carriage asks) -> completed | canceled (stopped after the current
// row with the blank last line, so the machine ends clean) | interrupted (link lost or machine
// silent: "device disconnected after row N"; `resume --from-row` continues) | failed (the
// pattern does not fit, the firmware is too old, ...).
// Online/offline: the port is watched while idle (its device node exists, or the USB device
// maps to a tty); it is only opened for a job, since opening resets an Arduino.
//
// Threading: one worker thread (started by start_worker()); public methods are thread-safe.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "daemon/core/device.h"
#include "daemon/core/job_service.h"
#include "drivers/ayab/host_session.h"
#include "drivers/transport.h"

namespace atelier {

class KnitDevice : public Device {
 public:
  // Opens a transport to a port path (SerialTransport::open in the daemon, fakes in tests).
  using Opener = std::function<std::unique_ptr<Transport>(const std::string& port)>;
  // The port to use now, or nullopt when the machine is not plugged in.
  using PortResolver = std::function<std::optional<std::string>()>;

  KnitDevice(DeviceConfig config, JobService& jobs, Opener open, PortResolver resolve,
             ayab::SessionTimeouts timeouts = {});
  ~KnitDevice() override;

  void start_worker();
  const DeviceConfig& config() const override { return config_; }
  nlohmann::json describe() const override;
  void wake() override;
  void start(int64_t job_id) override;
  bool cancel(int64_t job_id) override;
  void resume(int64_t job_id, int from_row) override;
  void stop() override;

 private:
  struct Work {
    int64_t id;
    int from_row;  // 1-based pattern row to start at
  };
  void worker();
  // Picks the next job and marks it running (ready/interrupted -> running) under the claim
  // lock, so a concurrent cancel sees either the ready job or the running one.
  std::optional<Work> next_work();
  void knit(const Work& work);
  // The job stopped on purpose (cancel, or the daemon stopping): canceled, or interrupted
  // when the daemon stops (so it is never resumed without an operator).
  void end_early(int64_t id, int rows_done, bool knitting_started);
  void set_state(const std::string& state, const std::string& detail);
  nlohmann::json current_job_json(int64_t id) const;  // {"id", "name", "progress"}
  ayab::PlanParams plan_params() const;

  DeviceConfig config_;
  JobService& jobs_;
  Opener open_;
  PortResolver resolve_;
  ayab::SessionTimeouts timeouts_;

  mutable std::mutex mu_;
  std::condition_variable cv_;
  bool stopping_ = false;
  bool woken_ = false;
  std::string state_ = "offline";
  std::string detail_;
  std::string port_;
  std::optional<int64_t> current_;
  std::shared_ptr<std::atomic<bool>> cancel_flag_;
  // The open link while a job waits for the machine to become ready (a person has to move
  // the carriage, which may never happen): stop() and cancel() close it to end the wait.
  // Null while rows are being knitted: then cancel ends cleanly after the current row.
  Transport* waiting_link_ = nullptr;
  std::set<int64_t> armed_;
  std::map<int64_t, int> resumes_;  // job -> from_row
  std::thread thread_;
};

}  // namespace atelier

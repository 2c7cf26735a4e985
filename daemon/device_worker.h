// What every machine worker shares (KnitDevice, LaserDevice): one worker thread that watches
// whether the machine is plugged in (online/offline), takes the `ready` jobs of its kinds one
// at a time (at once with autostart, else when `atelierctl start` armed them), and describes
// itself for `atelierctl devices`. Subclasses say how a job runs on their machine.
//
// Time: the worker's idle looks (every 300 ms) and what subclasses time (sessions, progress
// throttling) are on the Clock given (real_clock() in the daemon, a FakeClock in tests).
// Threading: one worker thread (start_worker()); public methods are thread-safe. Subclasses
// guard their own state with mu_ as well. Devices of different kinds compete for ready jobs
// only under claim_mutex(), so a job is never taken twice nor canceled while being taken.
#pragma once

#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>

#include "base/clock.h"
#include "daemon/device.h"
#include "daemon/job_service.h"

namespace atelier {

class DeviceWorker : public Device {
 public:
  // The port to use now, or nullopt when the machine is not plugged in. May throw (e.g. two
  // boards match a USB id); the message becomes the offline reason.
  using PortResolver = std::function<std::optional<std::string>()>;

  // Borrows `jobs` and `clock`, which must outlive the device.
  DeviceWorker(DeviceConfig config, JobService& jobs, PortResolver resolve, Clock& clock = real_clock());
  ~DeviceWorker() override;

  void start_worker();
  const DeviceConfig& config() const override { return config_; }
  nlohmann::json describe() const override;
  void wake() override;
  // Arms a ready job of this device's kinds; `options` go to accept_start() first.
  void start(int64_t job_id, const StartOptions& options = {}) override;
  // Cancels a ready job at once; a running job is handed to cancel_running().
  bool cancel(int64_t job_id) override;
  // Stops the worker: stopping_ is set and abort_running() ends the current job (which a
  // subclass leaves interrupted, never to be restarted on its own). Subclass destructors must
  // call stop() themselves, while their own members still exist.
  void stop() override;

 protected:
  static std::mutex& claim_mutex();
  static std::string job_tag(int64_t id) { return "job " + std::to_string(id); }

  // The worker found the machine online and idle. Returns true if it ran something (a job or
  // another request), so the worker looks again at once.
  virtual bool run_next() = 0;
  // A cancel request for `job_id` (any job): forgets what the subclass holds for it and, if it
  // is the job on the machine, asks it to stop and returns true. Called with mu_ held; must
  // not block.
  virtual bool cancel_running(int64_t job_id) = 0;
  // The daemon is stopping: end the job on the machine (if any) soon. Called with mu_ held.
  virtual void abort_running() = 0;
  // The machine went offline: drop requests that must not run on their own when it comes
  // back (a frame asked for hours ago). Called with mu_ held. Armed jobs are dropped by the
  // base.
  virtual void forget_requests() {}
  // `atelierctl start` with `options` for the ready `job`: checks them and keeps what the job
  // will run with; throws BadInput naming the job and the values, and then the job is not
  // armed. The base refuses any option (only knitting machines take them).
  virtual void accept_start(const Job& job, const StartOptions& options);
  // Throws std::runtime_error if the machine is offline (start and frame need it present).
  void require_online() const;
  // Extra fields for describe() (e.g. the knitting machine model). Called with mu_ held.
  virtual void describe_more(nlohmann::json& out) const { (void)out; }

  // For its life, marks `id` as the job on the machine and a fresh stop handle (e.g. a cancel
  // flag) as its handle in `slot`, which cancel_running()/abort_running() use under mu_.
  template <class Handle>
  class OnMachine {
   public:
    OnMachine(DeviceWorker& device, int64_t id, std::shared_ptr<Handle>& slot)
        : device_(device), slot_(slot), handle_(std::make_shared<Handle>()) {
      std::lock_guard lock(device_.mu_);
      device_.current_ = id;
      slot_ = handle_;
    }
    ~OnMachine() {
      std::lock_guard lock(device_.mu_);
      device_.current_.reset();
      slot_.reset();
    }
    OnMachine(const OnMachine&) = delete;
    OnMachine& operator=(const OnMachine&) = delete;
    Handle& handle() { return *handle_; }

   private:
    DeviceWorker& device_;
    std::shared_ptr<Handle>& slot_;
    std::shared_ptr<Handle> handle_;
  };

  // The oldest ready job this device may take now (autostart, or armed), marked running with
  // `reason` under the claim lock; nullopt if none.
  std::optional<int64_t> claim_ready(const std::string& reason);
  // The same, with the reason made for the job taken (e.g. naming its start row).
  std::optional<int64_t> claim_ready(const std::function<std::string(const Job&)>& reason);
  void set_state(const std::string& state, const std::string& detail);
  void set_detail(const std::string& detail);
  // What the device did last that an operator should see after it is idle again (e.g. a
  // framing that failed); shown as "last" by describe().
  void set_last(const std::string& what);
  bool stopping() const;

  DeviceConfig config_;
  JobService& jobs_;
  PortResolver resolve_;
  Clock& clock_;

  mutable std::mutex mu_;
  std::condition_variable_any cv_;  // _any: waited on through clock_
  bool stopping_ = false;
  std::optional<int64_t> current_;  // the job on the machine, if any
  std::string port_;                // the port found by the last resolve

 private:
  void worker();

  bool woken_ = false;
  std::string state_ = "offline";
  std::string detail_;
  std::string last_;
  std::set<int64_t> armed_;
  std::thread thread_;
};

}  // namespace atelier

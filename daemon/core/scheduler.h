// Conversion scheduling: `workers` threads take queued jobs in order, run each through the
// ConversionRunner with the per-job timeout, and record the outcome through JobService.
//
// Threading: enqueue/cancel/stop may be called from any thread. Worker threads are owned
// here and joined by stop() (or the destructor).
#pragma once

#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "daemon/core/config.h"
#include "daemon/core/conversion_runner.h"
#include "daemon/core/job_service.h"

namespace atelier {

class Scheduler {
 public:
  // `config` returns the current configuration (it changes on SIGHUP); read once per job.
  Scheduler(JobService& jobs, ConversionRunner& runner,
            std::function<std::shared_ptr<const Config>()> config);
  ~Scheduler();

  // Jobs of a kind that a device takes end `ready` for it instead of `completed`.
  // `waiting_for` says what a converted job waits for ("knitter", "laser and `atelierctl start
  // 7`"), or "" when no device takes its kind; `on_ready` wakes the devices.
  void set_device_hooks(std::function<std::string(const Job& job)> waiting_for,
                        std::function<void()> on_ready);

  void start(int workers);
  void enqueue(int64_t id);
  // Cancels a queued or converting job: it ends `canceled`, its input kept in failed/<id>.
  // Returns false when the job is neither queued nor converting here.
  bool cancel(int64_t id);
  // No new work; converting jobs are stopped and re-queued (converted again at next start).
  void stop();

  size_t queue_length() const;
  size_t converting() const;

 private:
  void worker();
  void convert_one(int64_t id);

  JobService& jobs_;
  ConversionRunner& runner_;
  std::function<std::shared_ptr<const Config>()> config_;
  std::function<std::string(const Job&)> waiting_for_;
  std::function<void()> on_ready_;
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::deque<int64_t> queue_;
  std::map<int64_t, std::shared_ptr<std::atomic<bool>>> running_;  // job -> cancel flag
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace atelier

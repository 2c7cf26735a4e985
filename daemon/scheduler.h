// Conversion scheduling: `workers` threads take queued jobs in order, run each through the
// ConversionRunner with the per-job timeout, and record the outcome through JobService.
//
// Parquetry batches (paper 4.2, targets planned together on the same wood): when a worker
// takes a parquetry job, every other parquetry job queued at that moment whose own overrides
// (--set values and sidecar text) equal its own joins it, up to kMaxBatch jobs in all, in one
// conversion (`--with` per extra job). They move converting -> ready/completed together, or
// fail with the same reason; the timeout is job_timeout_s per job of the batch. Canceling one
// cancels the conversion: that job ends canceled and the others are queued again (first in
// line). A batch cut off by a stop or a crash is re-queued whole (every job is `converting`,
// and recovery re-queues converting jobs).
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
#include <set>
#include <thread>
#include <vector>

#include "daemon/config.h"
#include "daemon/conversion_runner.h"
#include "daemon/job_service.h"

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
  std::vector<int64_t> converting_ids() const;  // jobs being converted now

 private:
  static constexpr size_t kMaxBatch = 8;

  void worker();
  void convert_one(int64_t id);
  // Queued parquetry jobs that may join `first` (see above); removed from the queue and
  // registered as running with `flag`. Called with mu_ held.
  std::vector<Job> take_batch_partners(const Job& first, const std::shared_ptr<std::atomic<bool>>& flag);

  JobService& jobs_;
  ConversionRunner& runner_;
  std::function<std::shared_ptr<const Config>()> config_;
  std::function<std::string(const Job&)> waiting_for_;
  std::function<void()> on_ready_;
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::deque<int64_t> queue_;
  std::map<int64_t, std::shared_ptr<std::atomic<bool>>> running_;  // job -> cancel flag (shared by a batch)
  std::set<int64_t> cancel_requested_;  // running jobs the user canceled (not the rest of their batch)
  std::set<int64_t> alone_;  // queued jobs of a failed batch: converted alone, so one bad input fails only its job
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace atelier

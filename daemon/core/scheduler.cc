#include "daemon/core/scheduler.h"

#include <sstream>

#include "daemon/core/log.h"

namespace atelier {

Scheduler::Scheduler(JobService& jobs, ConversionRunner& runner,
                     std::function<std::shared_ptr<const Config>()> config)
    : jobs_(jobs), runner_(runner), config_(std::move(config)) {}

Scheduler::~Scheduler() { stop(); }

void Scheduler::set_device_hooks(std::function<std::string(const Job&)> waiting_for,
                                 std::function<void()> on_ready) {
  waiting_for_ = std::move(waiting_for);
  on_ready_ = std::move(on_ready);
}

void Scheduler::start(int workers) {
  std::lock_guard lock(mu_);
  stopping_ = false;
  for (int i = 0; i < workers; ++i) threads_.emplace_back([this] { worker(); });
}

void Scheduler::enqueue(int64_t id) {
  {
    std::lock_guard lock(mu_);
    queue_.push_back(id);
  }
  cv_.notify_one();
}

bool Scheduler::cancel(int64_t id) {
  std::unique_lock lock(mu_);
  if (auto it = running_.find(id); it != running_.end()) {
    it->second->store(true);  // the worker sees it within 100 ms and records `canceled`
    return true;
  }
  for (auto it = queue_.begin(); it != queue_.end(); ++it) {
    if (*it == id) {
      queue_.erase(it);
      lock.unlock();
      jobs_.fail(id, "canceled by user before conversion", JobState::canceled);
      return true;
    }
  }
  return false;
}

void Scheduler::stop() {
  {
    std::lock_guard lock(mu_);
    stopping_ = true;
    for (auto& [id, flag] : running_) flag->store(true);
  }
  cv_.notify_all();
  for (auto& t : threads_)
    if (t.joinable()) t.join();
  threads_.clear();
}

size_t Scheduler::queue_length() const {
  std::lock_guard lock(mu_);
  return queue_.size();
}

size_t Scheduler::converting() const {
  std::lock_guard lock(mu_);
  return running_.size();
}

void Scheduler::worker() {
  for (;;) {
    int64_t id;
    {
      std::unique_lock lock(mu_);
      cv_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      id = queue_.front();
      queue_.pop_front();
    }
    try {
      convert_one(id);
    } catch (const std::exception& e) {
      // Store or file-system trouble (e.g. a full disk): the job fails, the daemon goes on.
      log::error("job " + std::to_string(id) + ": " + e.what());
      try {
        jobs_.fail(id, std::string("atelierd could not process the job: ") + e.what());
      } catch (const std::exception& e2) {
        log::error("job " + std::to_string(id) + ": cannot record the failure: " + e2.what());
      }
    }
  }
}

void Scheduler::convert_one(int64_t id) {
  auto job = jobs_.store().get(id);
  if (!job || job->state != JobState::queued) return;  // canceled or handled meanwhile
  auto flag = std::make_shared<std::atomic<bool>>(false);
  {
    std::lock_guard lock(mu_);
    running_[id] = flag;
    if (stopping_) flag->store(true);  // stop() swept the flags just before we registered
  }
  struct Release {
    Scheduler* s;
    int64_t id;
    ~Release() {
      std::lock_guard lock(s->mu_);
      s->running_.erase(id);
    }
  } release{this, id};

  jobs_.transition(id, JobState::converting, "converting");
  auto config = config_();
  ConversionTask task;
  task.job_id = id;
  task.kind = job->kind;
  task.input = jobs_.input_of(*job);
  task.output_dir = job->work_dir;
  {
    std::ostringstream defaults;
    auto it = config->kind_defaults.find(job->kind);
    if (it != config->kind_defaults.end()) defaults << it->second;
    task.defaults_toml = defaults.str();
  }
  if (!job->params.empty()) {
    toml::table overrides = toml::parse(job->params);
    for (const auto& [k, v] : overrides) {
      std::ostringstream value;
      v.visit([&value](const auto& node) { value << node; });
      task.sets.push_back(std::string(k.str()) + "=" + value.str());
    }
  }
  task.limits = config->limits;
  task.timeout = std::chrono::seconds(config->job_timeout_s);

  int last_percent = -1;
  auto progress = [&](double fraction) {
    int percent = static_cast<int>(fraction * 100.0);
    if (percent == last_percent) return;
    last_percent = percent;
    jobs_.store().set_progress(id, percent, 100);
  };
  log::info("job " + std::to_string(id) + ": converting " + job->name + " (" + job->kind + ")");
  ConversionOutcome outcome = runner_.run(task, progress, *flag);
  switch (outcome.status) {
    case ConversionOutcome::Status::ok:
    {
      const std::string device = waiting_for_ ? waiting_for_(*job) : "";
      if (device.empty()) {
        jobs_.store().set_progress(id, 100, 100);
        jobs_.finish_converted(id, JobState::completed, "converted; no device for kind " + job->kind);
        log::info("job " + std::to_string(id) + ": completed");
      } else {
        jobs_.store().set_progress(id, 0, 0);  // from here progress counts the device's rows
        jobs_.finish_converted(id, JobState::ready, "converted; waiting for " + device);
        if (on_ready_) on_ready_();
      }
      break;
    }
    case ConversionOutcome::Status::canceled: {
      bool stopping;
      {
        std::lock_guard lock(mu_);
        stopping = stopping_;
      }
      if (stopping) {
        jobs_.requeue(id, "atelierd is stopping; the job will be converted again at the next start");
      } else {
        jobs_.fail(id, "canceled by user during conversion", JobState::canceled);
      }
      break;
    }
    case ConversionOutcome::Status::timed_out:
    case ConversionOutcome::Status::failed:
      log::warning("job " + std::to_string(id) + ": failed: " + outcome.message);
      jobs_.fail(id, outcome.message);
      break;
  }
}

}  // namespace atelier

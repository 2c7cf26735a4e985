#include "daemon/scheduler.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "convert/kinds.h"
#include "convert/report_file.h"
#include "daemon/job_json.h"
#include "daemon/job_log.h"
#include "daemon/job_sets.h"
#include "daemon/log.h"

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
    cancel_requested_.insert(id);
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

std::vector<int64_t> Scheduler::converting_ids() const {
  std::lock_guard lock(mu_);
  std::vector<int64_t> out;
  for (const auto& [id, flag] : running_) out.push_back(id);
  return out;
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
      log::error(e.what(), job_fields(jobs_.store(), id));
      try {
        jobs_.fail(id, std::string("atelierd could not process the job: ") + e.what());
      } catch (const std::exception& e2) {
        log::error(std::string("cannot record the failure: ") + e2.what(), job_fields(jobs_.store(), id));
      }
    }
  }
}

namespace {

// A job's own overrides: its --set values and its sidecar's text. Jobs are planned together
// only when these are equal, since one conversion applies one set of parameters.
std::string own_overrides(const Job& job) {
  std::string text = job.params;
  std::ifstream sidecar(std::filesystem::path(job.work_dir) / (job.name + ".toml"));
  if (sidecar) {
    std::stringstream buf;
    buf << sidecar.rdbuf();
    text += "\n--sidecar--\n" + buf.str();
  }
  return text;
}

std::string id_list(const std::vector<Job>& jobs) {
  std::string s;
  for (const auto& j : jobs) s += (s.empty() ? "" : ", ") + std::to_string(j.id);
  return s;
}

}  // namespace

std::vector<Job> Scheduler::take_batch_partners(const Job& first,
                                                const std::shared_ptr<std::atomic<bool>>& flag) {
  std::vector<Job> partners;
  const KindInfo* kind = find_kind(first.kind);
  if (!kind || !kind->batches || alone_.erase(first.id)) return partners;
  const std::string overrides = own_overrides(first);
  for (auto it = queue_.begin(); it != queue_.end() && partners.size() + 1 < kMaxBatch;) {
    auto job = *it == first.id ? std::nullopt : jobs_.store().get(*it);
    if (job && job->state == JobState::queued && job->kind == first.kind && !running_.count(job->id) &&
        !alone_.count(job->id) && own_overrides(*job) == overrides) {
      running_[job->id] = flag;
      partners.push_back(*job);
      it = queue_.erase(it);
    } else {
      ++it;
    }
  }
  return partners;
}

void Scheduler::convert_one(int64_t id) {
  auto first = jobs_.store().get(id);
  if (!first || first->state != JobState::queued) return;  // canceled or handled meanwhile
  auto flag = std::make_shared<std::atomic<bool>>(false);
  std::vector<Job> batch = {*first};
  {
    std::lock_guard lock(mu_);
    if (running_.count(id)) return;  // queued twice and already taken by another worker
    running_[id] = flag;
    for (Job& j : take_batch_partners(*first, flag)) batch.push_back(std::move(j));
    if (stopping_) flag->store(true);  // stop() swept the flags just before we registered
  }
  struct Release {
    Scheduler* s;
    const std::vector<Job>& batch;
    ~Release() {
      std::lock_guard lock(s->mu_);
      for (const Job& j : batch) {
        s->running_.erase(j.id);
        s->cancel_requested_.erase(j.id);
      }
    }
  } release{this, batch};

  const Job& job = batch.front();
  for (const Job& j : batch) {
    jobs_.transition(j.id, JobState::converting,
                     batch.size() == 1 ? "converting"
                     : j.id == id      ? "converting together with jobs " + id_list({batch.begin() + 1, batch.end()})
                                       : "converting together with job " + std::to_string(id));
  }
  auto config = config_();
  ConversionTask task;
  task.job_id = id;
  task.kind = job.kind;
  task.input = jobs_.input_of(job);
  task.output_dir = job.work_dir;
  for (size_t i = 1; i < batch.size(); ++i)
    task.together.emplace_back(jobs_.input_of(batch[i]), batch[i].work_dir);
  {
    std::ostringstream defaults;
    auto it = config->kind_defaults.find(job.kind);
    if (it != config->kind_defaults.end()) defaults << it->second;
    task.defaults_toml = defaults.str();
  }
  // The job's --set strings go to the converter as given: the daemon parses no TOML of a job.
  task.sets = params_to_sets(job.params);
  task.limits = config->limits;
  task.confine = config->confine_dirs();
  task.timeout = std::chrono::seconds(config->job_timeout_s) * static_cast<int64_t>(batch.size());

  int last_percent = -1;
  auto progress = [&](double fraction) {
    int percent = static_cast<int>(fraction * 100.0);
    if (percent == last_percent) return;
    last_percent = percent;
    for (const Job& j : batch) jobs_.store().set_progress(j.id, percent, 100);
  };
  ConversionOutcome outcome = runner_.run(task, progress, *flag);
  switch (outcome.status) {
    case ConversionOutcome::Status::ok:
      for (const Job& j : batch) {
        const std::string device = waiting_for_ ? waiting_for_(j) : "";
        // The report's warnings go in the job's reason, before it goes to a machine.
        const std::vector<std::string> warnings = report_warnings(read_report(j.work_dir));
        if (device.empty()) {
          jobs_.store().set_progress(j.id, 100, 100);
          jobs_.finish_converted(j.id, JobState::completed,
                                 converted_reason("converted; no device for kind " + j.kind, warnings));
        } else {
          jobs_.store().set_progress(j.id, 0, 0);  // from here progress counts the device's rows
          jobs_.finish_converted(j.id, JobState::ready, converted_reason("converted; waiting for " + device, warnings));
        }
      }
      if (on_ready_) on_ready_();
      break;
    case ConversionOutcome::Status::canceled: {
      bool stopping;
      std::set<int64_t> canceled;
      {
        std::lock_guard lock(mu_);
        stopping = stopping_;
        canceled = cancel_requested_;
      }
      std::vector<int64_t> again;
      for (const Job& j : batch) {
        if (stopping) {
          jobs_.requeue(j.id, "atelierd is stopping; the job will be converted again at the next start");
        } else if (canceled.count(j.id)) {
          jobs_.fail(j.id, "canceled by user during conversion", JobState::canceled);
        } else {
          jobs_.requeue(j.id, "the conversion it shared was canceled; converting again");
          again.push_back(j.id);
        }
      }
      if (!again.empty()) {
        {
          // Released here, with the insert, not later by Release: a worker popping one of
          // them meanwhile would find it still running and drop it.
          std::lock_guard lock(mu_);
          for (int64_t a : again) {
            running_.erase(a);
            cancel_requested_.erase(a);
          }
          queue_.insert(queue_.begin(), again.begin(), again.end());
        }
        cv_.notify_all();
      }
      break;
    }
    case ConversionOutcome::Status::timed_out:
    case ConversionOutcome::Status::failed:
      if (batch.size() > 1) {
        // Which input failed is not known: every job is converted again on its own, so only
        // the bad one fails.
        {
          std::lock_guard lock(mu_);
          for (const Job& j : batch) {
            jobs_.requeue(j.id, "the conversion it shared failed (" + outcome.message +
                                    "); converting it alone");
            running_.erase(j.id);
            cancel_requested_.erase(j.id);
            alone_.insert(j.id);
          }
          std::vector<int64_t> ids;
          for (const Job& j : batch) ids.push_back(j.id);
          queue_.insert(queue_.begin(), ids.begin(), ids.end());
        }
        cv_.notify_all();
        break;
      }
      for (const Job& j : batch) jobs_.fail(j.id, outcome.message);  // logged by JobLog
      break;
  }
}

}  // namespace atelier

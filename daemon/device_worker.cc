#include "daemon/device_worker.h"

#include "base/error.h"
#include "daemon/job_json.h"
#include "daemon/job_log.h"
#include "daemon/log.h"

namespace atelier {

std::mutex& DeviceWorker::claim_mutex() {
  static std::mutex mu;
  return mu;
}

DeviceWorker::DeviceWorker(DeviceConfig config, JobService& jobs, PortResolver resolve, Clock& clock)
    : config_(std::move(config)), jobs_(jobs), resolve_(std::move(resolve)), clock_(clock) {}

DeviceWorker::~DeviceWorker() {
  // Subclasses stop first (their members die before ours); this only catches the case where
  // the worker never started.
  if (thread_.joinable()) thread_.join();
}

void DeviceWorker::start_worker() { thread_ = std::thread([this] { worker(); }); }

void DeviceWorker::stop() {
  {
    std::lock_guard lock(mu_);
    stopping_ = true;
    abort_running();
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

bool DeviceWorker::stopping() const {
  std::lock_guard lock(mu_);
  return stopping_;
}

nlohmann::json DeviceWorker::describe() const {
  std::lock_guard lock(mu_);
  nlohmann::json job = nullptr;
  if (current_) {
    job = {{"id", *current_}};
    if (auto j = jobs_.store().get(*current_)) {
      job["name"] = j->name;
      job["progress"] = job_to_json(*j)["progress"];  // with its unit: rows, lines
    }
  }
  nlohmann::json out = {
      {"name", config_.name},
      {"driver", config_.driver},
      {"port", !port_.empty() ? port_ : (config_.port.empty() ? "usb " + config_.usb : config_.port)},
      {"kinds", config_.kinds},
      {"autostart", config_.autostart},
      {"state", state_},
      {"detail", detail_},
      {"last", last_},
      {"job", job}};
  describe_more(out);
  return out;
}

void DeviceWorker::set_state(const std::string& state, const std::string& detail) {
  std::lock_guard lock(mu_);
  if (state_ != state)
    log::info(state + (detail.empty() ? "" : " (" + detail + ")"), log::device_fields(config_.name));
  state_ = state;
  detail_ = detail;
}

void DeviceWorker::set_detail(const std::string& detail) {
  std::lock_guard lock(mu_);
  detail_ = detail;
}

void DeviceWorker::set_last(const std::string& what) {
  std::lock_guard lock(mu_);
  last_ = what;
}

void DeviceWorker::wake() {
  {
    std::lock_guard lock(mu_);
    woken_ = true;
  }
  cv_.notify_all();
}

void DeviceWorker::require_online() const {
  std::lock_guard lock(mu_);
  if (state_ == "offline")
    throw BadInput(config_.name + " is offline (" + detail_ + "); connect it, then ask again");
}

void DeviceWorker::accept_start(const Job& job, const StartOptions& options) {
  if (options.empty()) return;
  throw BadInput(job_tag(job.id) + ": " + config_.name + " is not a knitting machine; --from-row and " +
                 "--start-needle are for knit and lace jobs (start it with: atelierctl start " +
                 std::to_string(job.id) + ")");
}

void DeviceWorker::start(int64_t job_id, const StartOptions& options) {
  auto job = jobs_.store().get(job_id);
  if (!job || job->state != JobState::ready || !takes(job->kind))
    throw BadInput(job_tag(job_id) + " is not a ready job for " + config_.name);
  // An arming must not wait for a machine plugged in hours later, with nobody there.
  require_online();
  accept_start(*job, options);
  {
    std::lock_guard lock(mu_);
    armed_.insert(job_id);
  }
  log::info("armed by atelierctl start", job_fields(jobs_.store(), job_id, config_.name));
  wake();
}

bool DeviceWorker::cancel(int64_t job_id) {
  // Under the claim lock a ready job cannot turn running behind our back (claim_ready()).
  std::lock_guard claim(claim_mutex());
  {
    std::lock_guard lock(mu_);
    armed_.erase(job_id);
    if (cancel_running(job_id)) return true;
  }
  auto job = jobs_.store().get(job_id);
  if (job && job->state == JobState::ready && takes(job->kind)) {
    jobs_.transition(job_id, JobState::canceled, "canceled by user before the machine started");
    return true;
  }
  return false;
}

std::optional<int64_t> DeviceWorker::claim_ready(const std::string& reason) {
  return claim_ready([&reason](const Job&) { return reason; });
}

std::optional<int64_t> DeviceWorker::claim_ready(const std::function<std::string(const Job&)>& reason) {
  std::lock_guard claim(claim_mutex());
  JobFilter filter;
  filter.state = JobState::ready;
  filter.limit = -1;
  auto ready = jobs_.store().list(filter);
  for (auto it = ready.rbegin(); it != ready.rend(); ++it) {  // oldest first
    if (!takes(it->kind)) continue;
    const bool own_start = autostarts(*it);  // may read the job's sidecar: not under mu_
    {
      std::lock_guard lock(mu_);
      if (!own_start && !armed_.count(it->id)) continue;
      armed_.erase(it->id);
    }
    jobs_.transition(it->id, JobState::running, reason(*it), config_.name);
    return it->id;
  }
  return std::nullopt;
}

void DeviceWorker::worker() {
  for (;;) {
    if (stopping()) return;
    std::optional<std::string> port;
    std::string why = "not connected";
    try {
      port = resolve_();
    } catch (const std::exception& e) {  // e.g. two boards match the USB id
      why = e.what();
    }
    {
      std::lock_guard lock(mu_);
      port_ = port.value_or("");
    }
    if (!port) {
      set_state("offline", why);
      std::lock_guard lock(mu_);
      armed_.clear();
      forget_requests();
    } else {
      set_state("online", "");
      try {
        if (run_next()) continue;
      } catch (const std::exception& e) {
        // The store failed under us (e.g. a full disk): say so and try again later.
        log::error(e.what(), log::device_fields(config_.name));
      }
    }
    std::unique_lock lock(mu_);
    clock_.wait_for(cv_, lock, std::chrono::milliseconds(300), [this] { return stopping_ || woken_; });
    woken_ = false;
  }
}

}  // namespace atelier

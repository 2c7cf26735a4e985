#include "daemon/purge.h"

#include <fcntl.h>

#include <cerrno>
#include <cstring>

#include "base/unique_fd.h"
#include "daemon/log.h"
#include "daemon/remove_tree.h"

namespace fs = std::filesystem;

namespace atelier {
namespace {

struct Removal {
  std::string problem;  // "" when removed (or already gone)
  bool retry = false;   // worth trying again at the next pass
};

// Removes `folder` if it is <spool>/done/<id> or <spool>/failed/<id>.
Removal remove_job_folder(const SpoolLayout& layout, int64_t id, const std::string& folder) {
  const fs::path recorded = fs::path(folder).lexically_normal();
  std::string parent;  // "done" or "failed", as the layout names them
  if (recorded == layout.done(id).lexically_normal()) parent = layout.done().filename().string();
  else if (recorded == layout.failed(id).lexically_normal()) parent = layout.failed().filename().string();
  if (parent.empty())
    return {folder + ": not job " + std::to_string(id) + "'s folder in the spool (" + layout.done(id).string() +
            " or " + layout.failed(id).string() + "); left in place"};
  // The spool itself is the workshop's (it may be a symlink); below it nothing is followed.
  UniqueFd root(::open(layout.root.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (!root.valid()) return {layout.root.string() + ": cannot open the spool: " + std::strerror(errno), true};
  UniqueFd sub(::openat(root.get(), parent.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
  if (!sub.valid()) {
    if (errno == ENOENT) return {};  // nothing there to remove
    return {(layout.root / parent).string() + ": cannot open (a symlink is never followed): " + std::strerror(errno),
            true};
  }
  std::string failed;
  if (std::error_code ec = remove_tree_at(sub.get(), std::to_string(id), failed))
    return {(layout.root / parent / failed).string() + ": cannot remove: " + ec.message(), true};
  return {};
}

}  // namespace

PurgeReport purge_finished_jobs(Store& store, const SpoolLayout& layout, const RetentionPolicy& policy,
                                int64_t now_ms) {
  PurgeReport report;
  const std::vector<int64_t> chosen = jobs_to_purge(store.finished_jobs(), policy, now_ms);
  if (!chosen.empty()) report.jobs = store.purge(chosen);
  // The folders of this pass and any a cut-off pass recorded.
  for (const PurgedFolder& f : store.purged_folders()) {
    const Removal r = remove_job_folder(layout, f.job_id, f.path);
    if (r.problem.empty()) ++report.folders_removed;
    else report.problems.push_back(r.problem);
    if (!r.retry) store.forget_purged_folder(f.job_id);
  }
  return report;
}

std::string purge_summary(const PurgeReport& report, const RetentionPolicy& policy) {
  if (report.jobs.empty() && report.folders_removed == 0) return "";
  std::string ids;
  for (size_t i = 0; i < report.jobs.size() && i < 10; ++i) ids += (i ? ", " : "") + std::to_string(report.jobs[i]);
  if (report.jobs.size() > 10) ids += ", ...";
  std::string s = "retention: purged " + std::to_string(report.jobs.size()) + " finished job" +
                  (report.jobs.size() == 1 ? "" : "s") + (ids.empty() ? "" : " (" + ids + ")") + " and " +
                  std::to_string(report.folders_removed) + " output folder" +
                  (report.folders_removed == 1 ? "" : "s") + "; [store] keep_days = " +
                  std::to_string(policy.keep_days) + ", keep_jobs = " + std::to_string(policy.keep_jobs);
  return s;
}

PurgeWorker::PurgeWorker(Store& store, SpoolLayout layout, std::function<RetentionPolicy()> policy, Clock& clock,
                         Clock::duration period, std::function<void(const PurgeReport&)> on_pass)
    : store_(store),
      layout_(std::move(layout)),
      policy_(std::move(policy)),
      clock_(clock),
      period_(period),
      on_pass_(std::move(on_pass)) {}

PurgeWorker::~PurgeWorker() { stop(); }

void PurgeWorker::start() {
  if (thread_.joinable()) return;
  stopping_ = false;
  thread_ = std::thread([this] { run(); });
}

void PurgeWorker::wake() {
  {
    std::lock_guard lock(mu_);
    woken_ = true;
  }
  wake_.notify_all();
}

void PurgeWorker::stop() {
  {
    std::lock_guard lock(mu_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void PurgeWorker::run() {
  for (;;) {
    const RetentionPolicy policy = policy_();
    PurgeReport report;
    try {
      report = purge_finished_jobs(store_, layout_, policy, now_ms());
    } catch (const std::exception& e) {
      report.problems.push_back(std::string("the store: ") + e.what());
    }
    if (const std::string summary = purge_summary(report, policy); !summary.empty()) log::info(summary);
    for (const std::string& p : report.problems) log::warning("retention: " + p);
    if (on_pass_) on_pass_(report);
    std::unique_lock lock(mu_);
    clock_.wait_for(wake_, lock, period_, [this] { return stopping_ || woken_; });
    if (stopping_) return;
    woken_ = false;
  }
}

}  // namespace atelier

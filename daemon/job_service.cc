#include "daemon/job_service.h"

#include <fcntl.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <system_error>

#include "base/error.h"
#include "convert/convert.h"
#include "convert/kinds.h"
#include "daemon/client_file.h"
#include "daemon/log.h"

namespace fs = std::filesystem;

namespace atelier {
namespace {

constexpr const char* kClaimFile = "claim.json";
constexpr const char* kReasonFile = "reason.txt";
// Written into a job folder just before it moves to done/ or failed/: the state the job is
// going to, so that recover() finishes a move that a crash cut off with the right state.
constexpr const char* kFinishFile = "finish.json";

// Lenient JSON text: file names from other systems need not be valid UTF-8.
std::string json_text(const nlohmann::json& j) {
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// Writes a small file and fsyncs it, so it exists before the next step of a claim.
// Throws std::system_error (the errno, naming the file) so that a claim can tell a full
// disk or a lack of descriptors (retried) from a lasting failure.
void write_durable(const fs::path& file, const std::string& text) {
  int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::system_error(errno, std::generic_category(), file.string() + ": cannot write");
  ssize_t n = ::write(fd, text.data(), text.size());
  const int err = n < 0 ? errno : ENOSPC;
  ::fsync(fd);
  ::close(fd);
  if (n != static_cast<ssize_t>(text.size()))
    throw std::system_error(err, std::generic_category(), file.string() + ": cannot write");
}

// Replaces `file` atomically (a temporary beside it, fsynced, renamed over it).
void replace_durable(const fs::path& file, const std::string& text) {
  const fs::path tmp = file.parent_path() / ("." + file.filename().string() + ".new");
  write_durable(tmp, text);
  if (::rename(tmp.c_str(), file.c_str()) != 0)
    throw std::system_error(errno, std::generic_category(), file.string() + ": cannot replace");
}

void fsync_dir(const fs::path& dir) {
  int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream buf;
  buf << in.rdbuf();
  return buf.str();
}

// "incoming/" or "incoming/<folder>/", for messages.
std::string place_of(const std::string& folder) {
  return "incoming/" + (folder.empty() ? "" : folder + "/");
}

// Why a claimed entry is not a regular file the daemon can read ("" when it is). The entry is
// opened without following a symlink and without blocking (a FIFO), and the opened
// descriptor is examined, so what is checked is what is there. `shown` names it in messages.
// Throws std::system_error for a transient failure (no descriptors, no memory).
std::string file_type_problem(const fs::path& claimed, const std::string& shown, const std::string& folder) {
  const int fd = ::open(claimed.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    const int err = errno;
    if (err == ELOOP) return shown + ": symbolic links are not accepted in the hot folder; copy the file instead";
    if (err == ENXIO) return shown + ": not a regular file";  // a socket
    if (is_transient_errno(err))
      throw std::system_error(err, std::generic_category(), claimed.string() + ": cannot open");
    return shown + ": cannot read: " + strerror(err);
  }
  struct stat st;
  const int rc = ::fstat(fd, &st);
  const int err = errno;
  ::close(fd);
  if (rc != 0) throw std::system_error(err, std::generic_category(), claimed.string() + ": cannot stat");
  if (S_ISDIR(st.st_mode))
    return shown + ": folders are not accepted in " + place_of(folder) + "; drop the files themselves";
  if (S_ISFIFO(st.st_mode))
    return shown + ": a FIFO (named pipe) is not a regular file; drop the file itself";
  if (!S_ISREG(st.st_mode)) return shown + ": not a regular file";
  return "";
}

}  // namespace

bool is_transient_errno(int err) {
  switch (err) {
    case EMFILE: case ENFILE: case ENOMEM: case ENOSPC: case EDQUOT: case EAGAIN: case EINTR:
    case EBUSY: case ENOBUFS: case ETXTBSY:
      return true;
    default:
      return false;
  }
}

JobService::JobService(Store& store, SpoolLayout layout, ChangeListener on_change, JobKindProbe probe)
    : store_(store),
      layout_(std::move(layout)),
      on_change_(std::move(on_change)),
      probe_(probe ? std::move(probe) : subprocess_job_kind_probe()) {}

JobService::Examined JobService::examine(const fs::path& work, const std::string& name,
                                         const std::string& folder) const {
  const fs::path claimed = work / name;
  if (std::string problem = file_type_problem(claimed, name, folder); !problem.empty()) return {"", problem};
  if (folder.empty()) {
    if (claimed.extension() != ".toml")
      return {"", name + ": files must be dropped into incoming/<kind>/ (kinds: " + known_kinds_text() +
                      "); job files NAME.toml name their kind inside"};
    // Untrusted TOML: read in a child (daemon/job_kind_probe.h), never in the daemon.
    JobFileKind found = probe_(claimed, name);
    if (!found.problem.empty()) return {"", found.problem};
    if (!is_known_kind(found.kind) || !converts_job_file(found.kind))
      return {"", name + ": the job file's kind could not be read"};
    return {found.kind, ""};
  }
  if (!is_known_kind(folder))
    return {folder, name + ": unknown kind '" + folder + "' (folder incoming/" + folder +
                        "/); this build converts: " + known_kinds_text()};
  return {folder, ""};
}

std::string JobService::examine_companions(const fs::path& work, const std::string& name) const {
  std::error_code ec;
  for (const std::string& suffix : companion_suffixes()) {
    const fs::path companion = work / (name + suffix);
    if (!fs::exists(fs::symlink_status(companion, ec))) continue;
    const std::string shown = name + suffix + (suffix == ".toml" ? " (the sidecar of " : " (a companion of ") + name + ")";
    const std::string problem = file_type_problem(companion, shown, "");
    if (!problem.empty()) return problem + "; both files are kept in failed/";
  }
  return "";
}

void JobService::ensure_layout() const {
  for (const auto& kind : known_kinds()) fs::create_directories(layout_.incoming(kind));
  fs::create_directories(layout_.work());
  fs::create_directories(layout_.done());
  fs::create_directories(layout_.failed());
}

void JobService::insert(const Job& job) {
  store_.insert_job(job);
  if (on_change_) on_change_({*store_.get(job.id), "", state_name(job.state), job.reason});
}

std::optional<int64_t> JobService::claim(const fs::path& entry) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(entry, ec))) return std::nullopt;
  const std::string name = entry.filename().string();
  const fs::path parent = entry.parent_path();
  // Only the place it was dropped is known before the claim; what it is, is examined after.
  const std::string folder = parent == layout_.incoming() ? "" : parent.filename().string();

  fs::path work;
  std::vector<std::pair<fs::path, fs::path>> moved;  // (where it was in incoming/, where it is now)
  // Undoes a claim cut off before its row: every moved entry back into incoming/ (never over
  // a file dropped since), then the folder. Whatever cannot go back stays with claim.json in
  // work/<id>, adopted at the next start.
  auto roll_back = [&] {
    std::error_code e;
    for (auto it = moved.rbegin(); it != moved.rend(); ++it) {
      if (::renameat2(AT_FDCWD, it->second.c_str(), AT_FDCWD, it->first.c_str(), RENAME_NOREPLACE) != 0) {
        log::error(it->second.string() + ": cannot move back to " + it->first.string() + ": " +
                   strerror(errno) + "; adopted at the next start");
        return;
      }
    }
    if (!work.empty()) fs::remove_all(work, e);
  };
  Job job;
  try {
    const int64_t id = store_.reserve_id();
    work = layout_.work(id);
    fs::create_directories(work);
    write_durable(work / kClaimFile,
                  json_text({{"kind", folder}, {"name", name}, {"folder", folder}, {"examined", false}}));
    step("intent");
    if (::rename(entry.c_str(), (work / name).c_str()) != 0) {
      const int err = errno;
      if (err == ENOENT) {
        fs::remove_all(work, ec);
        return std::nullopt;  // vanished before we got it: not ours to log
      }
      throw std::system_error(err, std::generic_category(), "cannot claim");
    }
    moved.emplace_back(entry, work / name);
    step("claimed");
    Examined found = examine(work, name, folder);
    if (found.problem.empty()) {
      for (const std::string& suffix : companion_suffixes()) {
        const fs::path companion = parent / (name + suffix);
        if (!fs::exists(fs::symlink_status(companion, ec))) continue;
        if (::rename(companion.c_str(), (work / (name + suffix)).c_str()) != 0) {
          if (errno == ENOENT) continue;
          throw std::system_error(errno, std::generic_category(), companion.string() + ": cannot claim");
        }
        moved.emplace_back(companion, work / (name + suffix));
      }
      found.problem = examine_companions(work, name);
    }
    replace_durable(work / kClaimFile, json_text({{"kind", found.kind},
                                                  {"name", name},
                                                  {"folder", folder},
                                                  {"problem", found.problem},
                                                  {"examined", true}}));
    fsync_dir(work);
    step("examined");
    job.id = id;
    job.kind = found.kind;
    job.name = name;
    job.state = JobState::queued;
    job.reason = found.problem.empty() ? "dropped into the hot folder" : "rejected at pick-up";
    job.work_dir = work.string();
    store_.insert_job(job);
    job.reason = found.problem;  // the problem, for below
  } catch (const std::system_error& e) {
    roll_back();
    throw PickupError(entry.string() + ": cannot pick up: " + e.what(), is_transient_errno(e.code().value()));
  } catch (const std::exception& e) {
    // The store (SQLite busy, disk full, no descriptors): worth another try.
    roll_back();
    throw PickupError(entry.string() + ": cannot pick up: " + e.what(), true);
  }
  const std::string problem = job.reason;
  if (on_change_) on_change_({*store_.get(job.id), "", state_name(JobState::queued), job.reason});
  if (!problem.empty()) fail(job.id, problem);
  return job.id;
}

int64_t JobService::submit(int fd, const std::string& name, const std::string& kind,
                           const std::string& params, uint64_t max_bytes, const std::string& reason) {
  if (!is_known_kind(kind))
    throw BadInput("unknown kind '" + kind + "'; this build converts: " +
                             known_kinds_text());
  if (name.empty() || name.find('/') != std::string::npos || name == "." || name == "..")
    throw BadInput("'" + name + "' is not a file name");
  const int64_t id = store_.reserve_id();
  const fs::path work = layout_.work(id);
  fs::create_directories(work);
  // The copy is complete before claim.json exists: recover() drops a folder without one, so a
  // crash mid-copy leaves no half file behind as a job.
  std::error_code ec;
  try {
    copy_client_file(fd, name, work / (".copy-" + name), max_bytes);
  } catch (const std::exception&) {
    fs::remove_all(work, ec);
    throw;
  }
  fs::rename(work / (".copy-" + name), work / name, ec);
  if (ec) {
    fs::remove_all(work);
    throw InternalError(name + ": cannot copy: " + ec.message());
  }
  write_durable(work / kClaimFile,
                json_text({{"kind", kind}, {"name", name}, {"problem", ""}, {"params", params}}));
  fsync_dir(work);
  Job job;
  job.id = id;
  job.kind = kind;
  job.name = name;
  job.reason = reason;
  job.work_dir = work.string();
  job.params = params;
  insert(job);
  return id;
}

fs::path JobService::input_of(const Job& job) const { return fs::path(job.work_dir) / job.name; }

void JobService::transition(int64_t id, JobState to, const std::string& reason,
                            const std::optional<std::string>& device) {
  auto before = store_.get(id);
  store_.transition(id, to, reason, std::nullopt, device);
  if (on_change_ && before)
    on_change_({*store_.get(id), state_name(before->state), state_name(to), reason});
}

void JobService::note(int64_t id, const std::string& reason) {
  store_.note(id, reason);
  if (!on_change_) return;
  auto job = store_.get(id);
  if (job) on_change_({*job, state_name(job->state), state_name(job->state), reason});
}

void JobService::progress(int64_t id, int64_t done, int64_t total, const std::string& what) {
  store_.set_progress(id, done, total);
  if (!on_change_) return;
  auto job = store_.get(id);
  if (job) on_change_({*job, state_name(job->state), state_name(job->state), what, true});
}

void JobService::progress_reason(int64_t id, int64_t done, int64_t total, const std::string& what) {
  store_.set_progress(id, done, total, what);
  if (!on_change_) return;
  auto job = store_.get(id);
  if (job) on_change_({*job, state_name(job->state), state_name(job->state), what, true});
}

void JobService::clean_partial_outputs(const Job& job) const {
  std::set<std::string> keep = {job.name, kClaimFile};
  for (const std::string& suffix : companion_suffixes()) keep.insert(job.name + suffix);
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(job.work_dir, ec))
    if (!keep.count(entry.path().filename().string())) fs::remove_all(entry.path(), ec);
}

void JobService::move_and_record(const Job& job, const fs::path& folder, JobState to,
                                 const std::string& reason) {
  std::error_code ec;
  if (fs::exists(job.work_dir, ec)) {
    // finish.json first: a crash between the rename and the row is finished by recover().
    write_durable(fs::path(job.work_dir) / kFinishFile,
                  json_text({{"to", state_name(to)}, {"reason", reason}}));
    fs::remove_all(folder, ec);  // a stale folder from an earlier attempt
    fs::rename(job.work_dir, folder);
    fsync_dir(folder.parent_path());
  }
  store_.transition(job.id, to, reason, folder.string());
  // Only now: until the row has changed, claim.json tells recover() what the job was.
  fs::remove(folder / kClaimFile, ec);
  fs::remove(folder / kFinishFile, ec);
  if (on_change_) on_change_({*store_.get(job.id), state_name(job.state), state_name(to), reason});
}

void JobService::finish_converted(int64_t id, JobState to, const std::string& reason) {
  auto job = store_.get(id);
  if (!job) throw BadInput("job " + std::to_string(id) + " does not exist");
  move_and_record(*job, layout_.done(id), to, reason);
}

void JobService::fail(int64_t id, const std::string& reason, JobState to) {
  auto job = store_.get(id);
  if (!job) throw BadInput("job " + std::to_string(id) + " does not exist");
  std::error_code ec;
  if (fs::exists(job->work_dir, ec)) {
    clean_partial_outputs(*job);
    write_durable(fs::path(job->work_dir) / kReasonFile, reason + "\n");
  }
  move_and_record(*job, layout_.failed(id), to, reason);
}

void JobService::requeue(int64_t id, const std::string& reason) {
  auto job = store_.get(id);
  if (!job) return;
  clean_partial_outputs(*job);
  transition(id, JobState::queued, reason);
}

void JobService::retry(int64_t id) {
  auto job = store_.get(id);
  if (!job) throw BadInput("job " + std::to_string(id) + " does not exist");
  if (!transition_allowed(job->state, JobState::queued))
    throw BadInput("job " + std::to_string(id) + " is " + state_name(job->state) +
                             "; only failed, interrupted or canceled jobs can be retried");
  std::error_code ec;
  const fs::path work = layout_.work(id);
  fs::path from = job->output_dir.empty() ? fs::path(job->work_dir) : fs::path(job->output_dir);
  // An earlier retry may have moved the input already and been cut off before the state change.
  if (fs::is_regular_file(fs::symlink_status(work / job->name, ec))) from = work;
  if (fs::exists(fs::symlink_status(from / job->name, ec)) &&
      !fs::is_regular_file(fs::symlink_status(from / job->name, ec)))
    throw BadInput("job " + std::to_string(id) + ": " + job->name +
                             " is not a regular file and can never be converted; drop a copy instead");
  if (!fs::exists(from / job->name, ec))
    throw BadInput("job " + std::to_string(id) + ": its input " +
                             (from / job->name).string() + " is gone; submit the file again");
  if (from != work) {
    fs::create_directories(work);
    std::vector<std::string> suffixes{""};
    for (const std::string& suffix : companion_suffixes()) suffixes.push_back(suffix);
    for (const std::string& suffix : suffixes) {
      fs::path src = from / (job->name + suffix);
      if (fs::exists(src, ec)) fs::rename(src, work / (job->name + suffix));
    }
    fs::remove_all(from, ec);
  }
  transition(id, JobState::queued, "retry requested");
}

bool JobService::finish_cut_off_move(const Job& job) {
  std::error_code ec;
  for (const auto& [folder, fallback] : {std::pair{layout_.done(job.id), JobState::completed},
                                          std::pair{layout_.failed(job.id), JobState::failed}}) {
    if (!fs::exists(folder, ec)) continue;
    JobState to = fallback;
    std::string reason = fallback == JobState::completed ? "converted (recovered after a restart)" : "";
    try {
      auto finish = nlohmann::json::parse(read_text(folder / kFinishFile));
      to = state_from_name(finish.value("to", "")).value_or(fallback);
      reason = finish.value("reason", reason);
    } catch (const std::exception&) {
      if (reason.empty()) {
        reason = read_text(folder / kReasonFile);
        while (!reason.empty() && reason.back() == '\n') reason.pop_back();
      }
    }
    store_.transition(job.id, to, reason, folder.string());
    fs::remove(folder / kFinishFile, ec);
    fs::remove(folder / kClaimFile, ec);
    if (on_change_) on_change_({*store_.get(job.id), state_name(job.state), state_name(to), reason});
    return true;
  }
  return false;
}

std::vector<int64_t> JobService::recover() {
  std::error_code ec;
  // 1. Claimed files whose job row never committed (crash between rename and insert).
  for (const auto& entry : fs::directory_iterator(layout_.work(), ec)) {
    const std::string dir = entry.path().filename().string();
    if (dir.empty() || dir.find_first_not_of("0123456789") != std::string::npos) continue;
    const int64_t id = std::stoll(dir);
    if (store_.has_job(id)) continue;
    nlohmann::json claim;
    try {
      claim = nlohmann::json::parse(read_text(entry.path() / kClaimFile));
    } catch (const std::exception&) {
      claim = nullptr;
    }
    std::error_code e2;
    if (!claim.is_object() ||
        !fs::exists(fs::symlink_status(entry.path() / claim.value("name", ""), e2))) {
      fs::remove_all(entry.path(), e2);  // the rename never happened: the file is still in incoming/
      continue;
    }
    Job job;
    job.id = id;
    job.kind = claim.value("kind", "");
    job.name = claim.value("name", "");
    job.params = claim.value("params", "");
    job.reason = "recovered after a restart";
    job.work_dir = entry.path().string();
    std::string problem = claim.value("problem", "");
    if (!claim.value("examined", true)) {
      // Cut off between the rename and the examination: examine what was claimed now.
      try {
        Examined found = examine(entry.path(), job.name, claim.value("folder", ""));
        if (found.problem.empty()) found.problem = examine_companions(entry.path(), job.name);
        job.kind = found.kind;
        problem = found.problem;
      } catch (const std::exception& e) {
        log::error(entry.path().string() + ": cannot examine the claimed " + job.name + ": " + e.what() +
                   "; adopted at the next start");
        continue;
      }
    }
    insert(job);  // logged as queued, "recovered after a restart" (job_log.h)
    if (!problem.empty()) fail(id, problem);
  }
  // 2. Jobs caught mid-way by the crash.
  std::vector<int64_t> queue;
  JobFilter every;
  every.limit = -1;  // all jobs, however many
  for (const auto& job : store_.list(every)) {
    const bool pending = job.state == JobState::queued || job.state == JobState::converting;
    if (pending && !fs::exists(job.work_dir, ec) && finish_cut_off_move(job)) continue;
    if (pending) {
      // A claim that was rejected (symlink, unknown kind, ...) but whose failure was cut off.
      std::string problem;
      try {
        problem = nlohmann::json::parse(read_text(fs::path(job.work_dir) / kClaimFile)).value("problem", "");
      } catch (const std::exception&) {
      }
      if (!problem.empty()) {
        fail(job.id, problem);
        continue;
      }
    }
    if (job.state == JobState::converting) {
      requeue(job.id, "atelierd restarted during conversion; converting again from scratch");
      queue.push_back(job.id);
    } else if (job.state == JobState::queued) {
      queue.push_back(job.id);
    } else if (job.state == JobState::running) {
      transition(job.id, JobState::interrupted,
                 "atelierd restarted while the machine was working; resume or retry by hand");
    }
  }
  std::sort(queue.begin(), queue.end());
  return queue;
}

}  // namespace atelier

#include "daemon/laser_device.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "base/error.h"
#include "convert/kinds.h"
#include "daemon/job_log.h"
#include "daemon/laser_job_checks.h"
#include "daemon/log.h"

namespace fs = std::filesystem;

namespace atelier {
namespace {

std::string retry_hint(int64_t id) {
  return "a laser job never restarts on its own: check the workpiece, then `atelierctl retry " +
         std::to_string(id) + "` runs it again from the start";
}

std::string line_count(size_t done, size_t total) {
  return "line " + std::to_string(done) + " of " + std::to_string(total);
}

std::string duration_text(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  if (s < 60) return std::to_string(s) + " s";
  return std::to_string(s / 60) + " min " + std::to_string(s % 60) + " s";
}

}  // namespace

LaserDevice::LaserDevice(DeviceConfig config, JobService& jobs, Opener open, PortResolver resolve,
                         LaserOptions options, Clock& clock)
    : DeviceWorker(std::move(config), jobs, std::move(resolve), clock),
      open_(std::move(open)),
      options_(options) {}

LaserDevice::~LaserDevice() { stop(); }

std::string LaserDevice::gcode_file_for(const std::string& kind) {
  const KindInfo* k = find_kind(kind);
  if (!k || k->machine_input != MachineInput::gcode)
    throw BadInput("a laser cannot run '" + kind + "' jobs (they make no G-code)");
  return std::string(k->machine_file);
}

void LaserDevice::abort_running() {
  if (controls_) controls_->cancel.store(true);
}

bool LaserDevice::cancel_running(int64_t job_id) {
  if (frame_request_ == job_id) frame_request_.reset();
  if (current_ != job_id || !controls_) return false;
  controls_->cancel.store(true);
  // A job being framed is still ready: stopping the trace is not canceling it.
  return !framing_;
}

void LaserDevice::forget_requests() { frame_request_.reset(); }

void LaserDevice::hold(int64_t job_id) {
  {
    std::lock_guard lock(mu_);
    if (current_ != job_id || !controls_)
      throw BadInput(job_tag(job_id) + " is not running on " + config_.name);
    controls_->hold.store(true);
  }
  // Shown by `devices` until the job moves on (progress reports keep it while held).
  set_detail(job_tag(job_id) + ": held (feed hold, beam off); `atelierctl resume " + std::to_string(job_id) +
             "` continues");
  log::info("feed hold asked by atelierctl hold", job_fields(jobs_.store(), job_id, config_.name));
}

void LaserDevice::resume(int64_t job_id, int from_row) {
  if (from_row != 0)
    throw BadInput(config_.name + " is a laser: a laser job is never continued part-way; " +
                             "`atelierctl resume " + std::to_string(job_id) +
                             "` (without --from-row) releases a feed hold, `atelierctl retry " +
                             std::to_string(job_id) + "` runs an interrupted job again from the start");
  {
    std::lock_guard lock(mu_);
    if (current_ != job_id || !controls_ || (!paused_ && !controls_->hold.load()))
      throw BadInput(job_tag(job_id) + " is neither held nor paused on " + config_.name);
    // Both at once (a hold during a sheet swap): the session ends the program pause too, so
    // the next sheet's M0 is seen and reported afresh.
    if (paused_) {
      controls_->release_pause.store(true);
      paused_ = false;
    }
    controls_->hold.store(false);
  }
  set_detail(job_tag(job_id) + ": resumed");
  log::info("resume asked by atelierctl resume", job_fields(jobs_.store(), job_id, config_.name));
}

void LaserDevice::describe_more(nlohmann::json& out) const {
  // The time left of the job being burned (not of a framing), from the last progress report.
  if (out["job"].is_object() && !framing_ && seconds_left_ >= 0) out["job"]["time_left_s"] = std::lround(seconds_left_);
}

void LaserDevice::frame(int64_t job_id) {
  auto job = jobs_.store().get(job_id);
  if (!job || job->state != JobState::ready || !takes(job->kind))
    throw BadInput(job_tag(job_id) + " is not a ready job for " + config_.name +
                             "; only a ready job can be framed");
  {
    std::lock_guard lock(mu_);
    if (current_) throw BadInput(config_.name + " is busy with " + job_tag(*current_));
    frame_request_ = job_id;
  }
  require_online();
  wake();
}

bool LaserDevice::run_next() {
  std::optional<int64_t> frame;
  {
    std::lock_guard lock(mu_);
    frame.swap(frame_request_);
  }
  if (frame) {
    run_frame(*frame);
    return true;
  }
  auto id = claim_ready("running on " + config_.name);
  if (!id) return false;
  run_job(*id);
  return true;
}

LaserDevice::Connection LaserDevice::connect_for(int64_t id) {
  auto job = jobs_.store().get(id);
  if (!job) throw BadInput("no " + job_tag(id));
  const std::string file_name = gcode_file_for(job->kind);
  const fs::path file = fs::path(job->output_dir) / file_name;
  std::ifstream in(file);
  if (!in) throw BadInput(file.string() + " cannot be read");
  std::stringstream text;
  text << in.rdbuf();

  auto port = resolve_();
  if (!port) throw LinkLost("the laser is not connected");
  Connection c;
  c.link = open_(*port);
  c.session = std::make_unique<grbl::Session>(*c.link, options_.timeouts, clock_);
  c.info = c.session->connect();
  c.program = grbl::parse_program(text.str(), rapid_rate(c.info));
  if (auto problem = job_fit_problem(c.program, c.info, file_name))
    throw grbl::SetupError(*problem + "; nothing was sent");
  return c;
}

void LaserDevice::run_frame(int64_t id) {
  OnMachine<grbl::Controls> on_machine(*this, id, controls_);
  grbl::Controls& controls = on_machine.handle();
  struct Framing {
    LaserDevice* d;
    explicit Framing(LaserDevice* device) : d(device) {
      std::lock_guard lock(d->mu_);
      d->framing_ = true;
    }
    ~Framing() {
      std::lock_guard lock(d->mu_);
      d->framing_ = false;
    }
  } framing{this};
  if (stopping()) controls.cancel = true;  // stop() came between the request and now
  set_state("busy", "framing " + job_tag(id) + " (beam off)");
  const log::Fields fields = job_fields(jobs_.store(), id, config_.name);
  try {
    Connection c = connect_for(id);
    if (!c.program.bounds) throw BadInput("the job has no moves to frame");
    c.session->frame(*c.program.bounds, options_.frame_feed_mm_min, controls);
    c.link->close();
    set_last("framed " + job_tag(id) + " with the beam off");
    log::info("framed with the beam off", fields);
  } catch (const grbl::Canceled&) {
    set_last("framing of " + job_tag(id) + " stopped");
    log::info("framing stopped", fields);
  } catch (const std::exception& e) {
    // The job stays ready: framing is a check, and a failed check must not lose the job.
    set_last("framing " + job_tag(id) + " failed: " + e.what());
    log::warning(std::string("framing failed: ") + e.what(), fields);
  }
}

LaserDevice::Ending LaserDevice::ending_for(const Error& e, int64_t id, const std::string& at,
                                            bool beam_may_fire) {
  switch (e.category()) {
    case ErrorCategory::cancelled: {
      const auto* c = dynamic_cast<const grbl::Canceled*>(&e);
      const std::string where = beam_may_fire ? at : "before the beam fired";
      const std::string outcome = "feed hold, soft reset: " + grbl::stop_outcome(!c || c->position_kept);
      if (stopping())
        return {JobState::interrupted, "atelierd stopped " + where + " (" + outcome + "); " + retry_hint(id)};
      return {JobState::canceled, "canceled " + where + " (" + outcome + ")"};
    }
    case ErrorCategory::device:
      // The machine went away or quiet: the job may be retried. It refused or alarmed: it failed.
      if (dynamic_cast<const LinkLost*>(&e)) {
        set_state("offline", e.what());
        return {JobState::interrupted, "link to " + config_.name + " lost " + at + " (" + e.what() +
                                           "); " + retry_hint(id)};
      }
      if (dynamic_cast<const grbl::Silent*>(&e))
        return {JobState::interrupted, config_.name + " stopped answering " + at + " (" + e.what() +
                                           "); " + retry_hint(id)};
      if (dynamic_cast<const grbl::GrblAlarm*>(&e))
        return {JobState::failed, config_.name + ": " + e.what() + " " + at + "; the beam is off"};
      if (dynamic_cast<const grbl::GrblError*>(&e))
        return {JobState::failed, config_.name + " refused the G-code: " + e.what() +
                                      "; the job was stopped and the beam is off"};
      break;
    case ErrorCategory::bad_input:
    case ErrorCategory::internal:
      break;
  }
  // Setup problems (laser mode off, outside the travel, unreadable file): nothing was sent.
  return {JobState::failed, config_.name + ": " + e.what()};
}

void LaserDevice::run_job(int64_t id) {
  OnMachine<grbl::Controls> on_machine(*this, id, controls_);
  grbl::Controls& controls = on_machine.handle();
  if (stopping()) controls.cancel = true;  // stop() came between the claim and now
  {
    std::lock_guard lock(mu_);
    paused_ = false;
    seconds_left_ = -1;
  }
  set_state("busy", job_tag(id));

  size_t acked = 0, total = 0;
  bool beam_may_fire = false;  // the real run has started sending
  const auto started = clock_.now();
  auto last_report = started - std::chrono::seconds(1);
  std::string pause_note;  // the program pause (M0) reported last, "" when running
  auto on_progress = [&](const grbl::Progress& p) {
    acked = p.acked;
    if (p.paused != pause_note) {
      pause_note = p.paused;
      {
        std::lock_guard lock(mu_);
        paused_ = !pause_note.empty();
      }
      const std::string reason =
          pause_note.empty() ? "resumed after the program pause at " + line_count(p.acked, p.total)
                             : "paused by the program (M0): " + pause_note + "; `atelierctl resume " +
                                   std::to_string(id) + "` to continue";
      set_detail(job_tag(id) + ": " + reason);
      try {
        jobs_.note(id, reason);
      } catch (const std::exception& e) {
        log::warning(std::string("pause not recorded: ") + e.what(), job_fields(jobs_.store(), id, config_.name));
      }  // else logged by JobLog, as the note it is
      if (!pause_note.empty()) return;  // keep the pause in the detail until it ends
    }
    if (!pause_note.empty()) return;
    const auto now = clock_.now();
    // The store is written at most 5 times a second; the last line always.
    if (p.acked != p.total && now - last_report < std::chrono::milliseconds(200)) return;
    last_report = now;
    const std::string what = line_count(p.acked, p.total) + ", " + duration_text(p.seconds_left) + " left";
    {
      std::lock_guard lock(mu_);
      seconds_left_ = p.seconds_left;
    }
    if (!controls.hold.load()) set_detail(job_tag(id) + ": " + what);  // a hold stays shown
    try {
      jobs_.progress(id, static_cast<int64_t>(p.acked), static_cast<int64_t>(p.total), what);
    } catch (const std::exception& e) {
      // A store hiccup (full disk) must not stop a burn half-way: the next report retries.
      log::warning(std::string("progress not recorded: ") + e.what(), job_fields(jobs_.store(), id, config_.name));
    }
  };
  try {
    Connection c = connect_for(id);
    const grbl::Program& program = c.program;
    grbl::Session& session = *c.session;
    total = program.lines.size();
    if (c.info.alarm_locked)
      throw grbl::SetupError("the controller is locked by an alarm (it may need homing): home it "
                             "or unlock it ($X) at the machine, then retry the job; nothing was sent");
    jobs_.store().set_progress(id, 0, static_cast<int64_t>(total));
    if (options_.check_first) {
      set_detail(job_tag(id) + ": dry run in check mode");
      try {
        session.check(program, options_.mode, controls, [](const grbl::Progress&) {});
      } catch (const grbl::GrblError& e) {
        throw grbl::SetupError(std::string("check mode found an error, nothing was burned: ") + e.what());
      }
    }
    beam_may_fire = true;
    session.stream(program, options_.mode, controls, on_progress);
    c.link->close();
    const double seconds =
        std::chrono::duration<double>(clock_.now() - started).count();
    jobs_.progress(id, static_cast<int64_t>(total), static_cast<int64_t>(total), "done");
    jobs_.transition(id, JobState::completed, "ran " + std::to_string(total) + " G-code lines on " +
                                                  config_.name + " in " + duration_text(seconds));
  } catch (const Error& e) {
    const Ending end = ending_for(e, id, "at " + line_count(acked, total), beam_may_fire);
    jobs_.transition(id, end.state, end.reason);
  } catch (const std::exception& e) {
    jobs_.transition(id, JobState::failed, config_.name + ": " + e.what());
  }
  const std::string reason = jobs_.store().get(id)->reason;
  set_last(job_tag(id) + ": " + reason);  // the log has it from JobLog (job_log.h)
}

}  // namespace atelier

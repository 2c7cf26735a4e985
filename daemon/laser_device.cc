#include "daemon/laser_device.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "base/error.h"
#include "convert/common/job_start.h"
#include "convert/common/param_table.h"
#include "convert/kinds.h"
#include "drivers/grbl/codes.h"
#include "daemon/job_log.h"
#include "daemon/job_sets.h"
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

std::string joined(const std::vector<std::string>& parts, const char* sep) {
  std::string out;
  for (const auto& p : parts) out += (out.empty() ? "" : sep) + p;
  return out;
}

std::string mm_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

// The alarm's short name: "soft limit" of "soft limit: G-code motion target exceeds ...".
std::string alarm_title(int code) {
  const std::string m = grbl::alarm_meaning(code);
  return m.substr(0, m.find(':'));
}

// Why `line` may not go to the controller's console, or "" when it may: one line, printable,
// no real-time byte (GRBL acts on those at once, outside the line: `atelierctl hold`, cancel).
std::string console_problem(const std::string& line) {
  if (line.empty()) return "an empty line";
  if (line.size() > 80) return "longer than GRBL's 80-character line buffer";
  for (unsigned char c : line) {
    if (c == '\n' || c == '\r') return "several lines (send one line at a time)";
    if (c == '?' || c == '!' || c == '~' || c == 0x18 || c >= 0x80)
      return "a real-time command byte (?, !, ~, Ctrl-X or 0x80-0xFF), which GRBL acts on outside any line";
    if (c < 0x20 || c == 0x7f) return "a control character";
  }
  return "";
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

void LaserDevice::stop() {
  DeviceWorker::stop();
  drop_link();  // the worker has ended: nothing else uses the link now
}

LaserDevice::Link& LaserDevice::link() {
  auto port = resolve_();
  if (!port) {
    drop_link();
    throw LinkLost("the laser is not connected");
  }
  if (link_ && link_->port != *port) {
    log::info("the laser's port moved from " + link_->port + " to " + *port + ": reconnecting",
              log::device_fields(config_.name));
    drop_link();
  }
  if (link_) {
    try {
      link_->info = link_->session->revalidate();
      return *link_;
    } catch (const std::exception& e) {
      // Dead or confused before anything was sent: one fresh connection, then give up.
      log::warning(std::string("the kept connection failed its check (") + e.what() + "): reconnecting",
                   log::device_fields(config_.name));
      drop_link();
    }
  }
  auto fresh = std::make_unique<Link>();
  fresh->port = *port;
  fresh->transport = open_(*port);
  fresh->session = std::make_unique<grbl::Session>(*fresh->transport, options_.timeouts, clock_);
  try {
    fresh->info = fresh->session->connect();
  } catch (...) {
    try {
      fresh->transport->close();
    } catch (...) {
    }
    throw;
  }
  link_ = std::move(fresh);
  log::info("connected to GRBL " + link_->info.version + " on " + *port, log::device_fields(config_.name));
  return *link_;
}

void LaserDevice::drop_link() noexcept {
  if (!link_) return;
  try {
    link_->transport->close();
  } catch (...) {  // closing a link that is gone already
  }
  link_.reset();
}

void LaserDevice::after_failure(const std::exception& e) noexcept {
  const bool known_state = dynamic_cast<const grbl::Canceled*>(&e) || dynamic_cast<const grbl::GrblError*>(&e) ||
                           dynamic_cast<const grbl::GrblAlarm*>(&e) || dynamic_cast<const grbl::SetupError*>(&e) ||
                           dynamic_cast<const BadInput*>(&e) || dynamic_cast<const std::invalid_argument*>(&e);
  if (!known_state) drop_link();
}

struct LaserDevice::MachineRequest {
  MachineCommand cmd;
  std::promise<nlohmann::json> answer;
  bool taken = false;  // the worker runs it (guarded by mu_)
};

void LaserDevice::accept_start(const Job& job, const StartOptions& options) {
  StartOptions knitting = options;
  knitting.start_from.reset();
  DeviceWorker::accept_start(job, knitting);  // refuses the knitting machine's options
  if (!options.start_from) return;
  const auto from = grbl::parse_start_from(*options.start_from);
  if (!from)
    throw BadInput(job_tag(job.id) + ": --start-from '" + *options.start_from +
                   "' is no placement; expected bed (the bed's front-left corner), origin (the work zero "
                   "set with `atelierctl laser origin`) or here (the head's position at start)");
  std::lock_guard lock(mu_);
  start_from_[job.id] = *from;
}

nlohmann::json LaserDevice::machine_command(const MachineCommand& cmd) {
  if (cmd.op == MachineCommand::Op::send) {
    if (const std::string why = console_problem(cmd.line); !why.empty())
      throw BadInput(config_.name + ": the console takes one line of G-code or a $ command, not " + why +
                     "; nothing was sent");
  }
  if (cmd.op == MachineCommand::Op::jog && (!std::isfinite(cmd.dx_mm) || !std::isfinite(cmd.dy_mm) ||
                                            cmd.feed_mm_min < 0 || !std::isfinite(cmd.feed_mm_min)))
    throw BadInput(config_.name + ": a jog needs finite distances and a feed >= 0 mm/min");
  auto req = std::make_shared<MachineRequest>();
  req->cmd = cmd;
  std::future<nlohmann::json> answer = req->answer.get_future();
  {
    std::lock_guard lock(mu_);
    // A job whose end is already recorded is only being let go by the worker, which serves the
    // command right after: `atelierctl show` says completed, so the command must not be refused.
    const std::optional<Job> on = current_ ? jobs_.store().get(*current_) : std::nullopt;
    const bool winding_down = !framing_ && on && on->state != JobState::running;
    if (current_ && !winding_down) {
      const bool held = controls_ && controls_->hold.load();
      throw BadInput(config_.name + " is " + (framing_ ? "framing " : held ? "holding " : "running ") +
                     job_tag(*current_) + ": the controller takes operator commands only between jobs (`atelierctl "
                     "cancel " + std::to_string(*current_) + "` ends it); nothing was sent");
    }
    if (machine_request_)
      throw BadInput(config_.name + " is still running an operator command; ask again once it is done");
    machine_request_ = req;
  }
  try {
    require_online();
  } catch (...) {
    std::lock_guard lock(mu_);
    machine_request_.reset();
    throw;
  }
  wake();
  // Homing may take a minute; the session's own timeouts end anything stuck well before this.
  if (answer.wait_for(std::chrono::minutes(3)) != std::future_status::ready)
    throw BadInput(config_.name + ": the operator command did not finish within 3 minutes");
  return answer.get();
}

void LaserDevice::run_machine_command(MachineRequest& req) {
  const MachineCommand& cmd = req.cmd;
  nlohmann::json lines = nlohmann::json::array();
  auto logged = [&](const std::string& sent, const std::vector<std::string>& reply) {
    lines.push_back({{"sent", sent}, {"reply", reply}});
    try {
      jobs_.store().add_console_line({0, 0, config_.name, cmd.uid, sent, joined(reply, "\n")});
    } catch (const std::exception& e) {
      log::warning(std::string("console line not recorded: ") + e.what(), log::device_fields(config_.name));
    }
  };
  // A command the session runs to its end: logged as "ok" or with what went wrong.
  auto run_logged = [&](const std::string& sent, const std::function<void()>& run) {
    try {
      run();
    } catch (const std::exception& e) {
      logged(sent, {e.what()});
      throw;
    }
    logged(sent, {"ok"});
  };
  set_state("busy", "operator command");
  auto done = [this] {
    std::lock_guard lock(mu_);
    machine_request_.reset();
  };
  std::string effect;
  try {
    Link& kept = link();
    grbl::Session& session = *kept.session;
    const grbl::MachineInfo info = kept.info;
    switch (cmd.op) {
      case MachineCommand::Op::unlock: {
        const auto reply = session.console("$X");
        logged("$X", reply);
        if (!reply.empty() && reply.back().rfind("error:", 0) == 0)
          throw BadInput("$X refused: " + reply.back() + " (" + grbl::error_meaning(std::atoi(reply.back().c_str() + 6)) + ")");
        effect = "unlocked ($X); if the position may be lost (a stop in motion, an alarm), home the machine "
                 "(`atelierctl laser home`) before the next job";
        break;
      }
      case MachineCommand::Op::home:
        run_logged("$H", [&] { session.home(); });
        effect = "homed ($H)";
        break;
      case MachineCommand::Op::jog: {
        const double feed = cmd.feed_mm_min > 0 ? cmd.feed_mm_min : options_.frame_feed_mm_min;
        const grbl::MachineSpace space = grbl::machine_space(info);
        const grbl::Status now = session.query_status();
        const double target[2] = {now.x + cmd.dx_mm, now.y + cmd.dy_mm};
        if (info.max_travel_x > 0 && info.max_travel_y > 0) {
          for (int a = 0; a < 2; ++a) {
            const grbl::AxisRange r = space.axis[static_cast<size_t>(a)];
            if (target[a] < r.min - 1e-3 || target[a] > r.max + 1e-3)
              throw BadInput(std::string("the jog would take ") + "XY"[a] + " to " + mm_text(target[a]) +
                             " mm, outside the machine's " + "XY"[a] + " " + mm_text(r.min) + ".." + mm_text(r.max) +
                             " mm; nothing was sent");
          }
        }
        char line[96];
        std::snprintf(line, sizeof line, "$J=G91G21X%.3fY%.3fF%.0f", cmd.dx_mm, cmd.dy_mm, feed);
        run_logged(line, [&] { session.jog(cmd.dx_mm, cmd.dy_mm, feed); });
        effect = "jogged by X " + mm_text(cmd.dx_mm) + " Y " + mm_text(cmd.dy_mm) + " mm";
        break;
      }
      case MachineCommand::Op::origin:
        run_logged("G10L20P1X0Y0", [&] { session.set_origin_here(); });
        effect = "work zero (G54) set at the head's position; jobs started with --start-from origin begin there";
        break;
      case MachineCommand::Op::send: {
        const auto reply = session.console(cmd.line);
        logged(cmd.line, reply);
        effect = "sent";
        break;
      }
    }
    set_last("operator: " + effect);
    done();  // before the answer: the operator's next command must find the device free
    req.answer.set_value({{"device", config_.name}, {"lines", lines}, {"effect", effect}});
  } catch (const std::exception& e) {
    after_failure(e);
    if (dynamic_cast<const LinkLost*>(&e)) set_state("offline", e.what());
    set_last(std::string("operator command failed: ") + e.what());
    done();
    req.answer.set_exception(std::make_exception_ptr(BadInput(config_.name + ": " + e.what())));
  }
}

std::string LaserDevice::gcode_file_for(const std::string& kind) {
  const KindInfo* k = find_kind(kind);
  if (!k || k->machine_input != MachineInput::gcode)
    throw BadInput("a laser cannot run '" + kind + "' jobs (they make no G-code)");
  return std::string(k->machine_file);
}

void LaserDevice::abort_running() {
  if (controls_) controls_->cancel.store(true);
  // A command not yet taken will not run: the worker is stopping.
  if (machine_request_ && !machine_request_->taken) {
    machine_request_->answer.set_exception(
        std::make_exception_ptr(BadInput(config_.name + ": atelierd is stopping; nothing was sent")));
    machine_request_.reset();
  }
}

bool LaserDevice::cancel_running(int64_t job_id) {
  if (frame_request_ == job_id) frame_request_.reset();
  if (current_ != job_id) start_from_.erase(job_id);
  if (current_ != job_id || !controls_) return false;
  controls_->cancel.store(true);
  // A job being framed is still ready: stopping the trace is not canceling it.
  return !framing_;
}

void LaserDevice::forget_requests() {
  drop_link();  // on the worker thread: the port is gone, or is someone else's now
  frame_request_.reset();
  if (machine_request_ && !machine_request_->taken) {
    machine_request_->answer.set_exception(
        std::make_exception_ptr(BadInput(config_.name + " went offline; nothing was sent")));
    machine_request_.reset();
  }
}

std::string LaserDevice::held_text(int64_t job_id, size_t acked, size_t total) {
  return "held at " + line_count(acked, total) + ": feed hold, beam off; `atelierctl resume " +
         std::to_string(job_id) + "` continues";
}

void LaserDevice::hold(int64_t job_id) {
  size_t acked = 0, total = 0;
  {
    std::lock_guard lock(mu_);
    if (current_ != job_id || !controls_ || framing_)
      throw BadInput(job_tag(job_id) + " is not running on " + config_.name);
    controls_->hold.store(true);
    acked = acked_;
    total = total_;
  }
  // Shown by `devices`, `list` and `show` until resumed (progress reports keep it while held).
  const std::string what = held_text(job_id, acked, total);
  set_detail(job_tag(job_id) + ": " + what);
  try {
    jobs_.progress_reason(job_id, static_cast<int64_t>(acked), static_cast<int64_t>(total), what);
  } catch (const std::exception& e) {
    log::warning(std::string("hold not recorded: ") + e.what(), job_fields(jobs_.store(), job_id, config_.name));
  }
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
  std::shared_ptr<MachineRequest> command;
  {
    std::lock_guard lock(mu_);
    frame.swap(frame_request_);
    if (machine_request_ && !machine_request_->taken) {
      command = machine_request_;
      command->taken = true;
    }
  }
  if (command) {
    if (frame) {
      std::lock_guard lock(mu_);
      frame_request_ = frame;  // after the command
    }
    run_machine_command(*command);  // frees machine_request_ before it answers
    return true;
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

LaserDevice::JobPlacement LaserDevice::placement_for(int64_t id) {
  JobPlacement out;
  out.check_first = options_.check_first;
  out.from = options_.start_from;
  auto job = jobs_.store().get(id);
  if (!job) throw BadInput("no " + job_tag(id));
  // The job's sidecar (NAME.EXT.toml beside its output), as the conversion kept it.
  if (!job->output_dir.empty()) {
    const fs::path file = fs::path(job->output_dir) / (job->name + ".toml");
    std::error_code ec;
    if (fs::is_regular_file(file, ec)) {
      toml::table table;
      try {
        table = toml::parse_file(file.string());
      } catch (const toml::parse_error& e) {
        throw BadInput(toml_error_text(e, file.string()));
      }
      const LaserJobStart own = take_laser_job_start(table, file.string());
      if (own.check_first) out.check_first = *own.check_first;
      if (own.start_from) out.from = *grbl::parse_start_from(*own.start_from);
    }
  }
  // `atelierctl submit --set laser.start_from=here` over the sidecar (checked at submit).
  if (const std::vector<std::string> sets = params_to_sets(job->params); !sets.empty()) {
    toml::table table;
    for (const std::string& s : sets) apply_set(table, s);
    const LaserJobStart own = take_laser_job_start(table, "--set");
    if (own.check_first) out.check_first = *own.check_first;
    if (own.start_from) out.from = *grbl::parse_start_from(*own.start_from);
  }
  std::lock_guard lock(mu_);
  if (auto it = start_from_.find(id); it != start_from_.end()) out.from = it->second;  // --start-from
  return out;
}

std::string LaserDevice::place_job(grbl::Session& session, const grbl::MachineInfo& info, const grbl::Bounds* bounds,
                                   grbl::StartFrom from, const std::string& file) {
  const grbl::MachineSpace space = grbl::machine_space(info);
  const grbl::Status now = session.query_status();
  const std::array<double, 3> wco = session.work_offset();
  if (bounds) {
    const std::string why = grbl::check_fits(*bounds, from, space, info, now, wco);
    if (!why.empty())
      throw grbl::SetupError(file + " does not fit when started from " + grbl::start_from_name(from) + ": " + why +
                             "; nothing was sent");
  }
  const std::vector<std::string> lines = grbl::placement_lines(from, space, now, wco);
  for (const std::string& line : lines) session.command(line);
  return std::string("start from ") + grbl::start_from_name(from) +
         (lines.empty() ? "" : " (" + joined(lines, " ") + ")");
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

  Link& kept = link();
  Connection c{*kept.session, kept.info, {}};
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
    const JobPlacement placement = placement_for(id);
    Connection c = connect_for(id);
    if (!c.program.bounds) throw BadInput("the job has no moves to frame");
    // The same placement as the job will have, so the trace shows where it will burn.
    const std::string placed = place_job(c.session, c.info, &*c.program.bounds, placement.from,
                                         gcode_file_for(jobs_.store().get(id)->kind));
    c.session.frame(*c.program.bounds, options_.frame_feed_mm_min, controls);
    if (placement.from != grbl::StartFrom::origin) c.session.command(grbl::kClearPlacement);
    set_last("framed " + job_tag(id) + " with the beam off (" + placed + ")");
    log::info("framed with the beam off", fields);
  } catch (const grbl::Canceled&) {
    set_last("framing of " + job_tag(id) + " stopped");
    log::info("framing stopped", fields);
  } catch (const std::exception& e) {
    after_failure(e);
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
      if (const auto* alarm = dynamic_cast<const grbl::GrblAlarm*>(&e)) {
        // The line GRBL was executing when it alarmed (not the last one acknowledged), and
        // what the operator must do for this alarm (a limit alarm is never "safe to unlock").
        std::string where = at;
        if (alarm->line_number > 0) {  // job.gcode's source line: as the n-th line sent
          const auto it = std::find(source_lines_.begin(), source_lines_.end(), static_cast<int>(alarm->line_number));
          where = it != source_lines_.end()
                      ? "at " + line_count(static_cast<size_t>(it - source_lines_.begin()) + 1, source_lines_.size())
                      : "at line " + std::to_string(alarm->line_number) + " of the job's G-code";
        }
        return {JobState::failed, config_.name + ": ALARM:" + std::to_string(alarm->code) + " " +
                                      alarm_title(alarm->code) + " " + where + ": " +
                                      grbl::alarm_advice(alarm->code) + "; the beam is off"};
      }
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
    acked_ = total_ = 0;
  }
  set_state("busy", job_tag(id));

  size_t acked = 0, total = 0;
  bool beam_may_fire = false;  // the real run has started sending
  const auto started = clock_.now();
  auto last_report = started - std::chrono::seconds(1);
  std::string pause_note;  // the program pause (M0) reported last, "" when running
  bool shown_held = false;  // the job's reason says it is held
  std::string running_reason = "running on " + config_.name;
  auto on_progress = [&](const grbl::Progress& p) {
    acked = p.acked;
    {
      std::lock_guard lock(mu_);
      acked_ = p.acked;
      total_ = p.total;
    }
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
    // While held, every view says so (not a time left that does not run down); once resumed
    // the job's reason is its running one again.
    const bool held = controls.hold.load();
    const bool reason_changes = held || shown_held;
    shown_held = held;
    const std::string what = held ? held_text(id, p.acked, p.total)
                                  : line_count(p.acked, p.total) + ", " + duration_text(p.seconds_left) + " left";
    {
      std::lock_guard lock(mu_);
      seconds_left_ = p.seconds_left;
    }
    set_detail(job_tag(id) + ": " + what);
    try {
      if (reason_changes)
        jobs_.progress_reason(id, static_cast<int64_t>(p.acked), static_cast<int64_t>(p.total),
                              held ? what : running_reason);
      else
        jobs_.progress(id, static_cast<int64_t>(p.acked), static_cast<int64_t>(p.total), what);
    } catch (const std::exception& e) {
      // A store hiccup (full disk) must not stop a burn half-way: the next report retries.
      log::warning(std::string("progress not recorded: ") + e.what(), job_fields(jobs_.store(), id, config_.name));
    }
  };
  std::string placed;
  try {
    const JobPlacement placement = placement_for(id);
    Connection c = connect_for(id);
    const grbl::Program& program = c.program;
    grbl::Session& session = c.session;
    total = program.lines.size();
    source_lines_ = program.source_line;
    {
      std::lock_guard lock(mu_);
      total_ = total;
    }
    if (c.info.alarm_locked)
      throw grbl::SetupError("the controller is locked by an alarm (it may need homing): `atelierctl laser home` "
                             "or `atelierctl laser unlock`, then retry the job; nothing was sent");
    jobs_.store().set_progress(id, 0, static_cast<int64_t>(total));
    placed = place_job(session, c.info, program.bounds ? &*program.bounds : nullptr, placement.from,
                       gcode_file_for(jobs_.store().get(id)->kind));
    jobs_.note(id, placed);  // the history says where the job was placed
    running_reason = "running on " + config_.name + " (" + placed + ")";
    jobs_.progress_reason(id, 0, static_cast<int64_t>(total), running_reason);
    if (placement.check_first) {
      set_detail(job_tag(id) + ": dry run in check mode");
      try {
        session.check(program, options_.mode, controls, [](const grbl::Progress&) {});
      } catch (const grbl::GrblError& e) {
        throw grbl::SetupError(std::string("check mode found an error, nothing was burned: ") + e.what());
      }
    }
    beam_may_fire = true;
    session.stream(program, options_.mode, controls, on_progress);
    if (placement.from != grbl::StartFrom::origin) session.command(grbl::kClearPlacement);  // G54 as the operator left it
    const double seconds =
        std::chrono::duration<double>(clock_.now() - started).count();
    jobs_.progress(id, static_cast<int64_t>(total), static_cast<int64_t>(total), "done");
    jobs_.transition(id, JobState::completed, "ran " + std::to_string(total) + " G-code lines on " +
                                                  config_.name + " in " + duration_text(seconds) + " (" +
                                                  placed + ")");
  } catch (const Error& e) {
    after_failure(e);
    const Ending end = ending_for(e, id, "at " + line_count(acked, total), beam_may_fire);
    jobs_.transition(id, end.state, end.reason);
  } catch (const std::exception& e) {
    after_failure(e);
    jobs_.transition(id, JobState::failed, config_.name + ": " + e.what());
  }
  {
    std::lock_guard lock(mu_);
    start_from_.erase(id);
  }
  const std::string reason = jobs_.store().get(id)->reason;
  set_last(job_tag(id) + ": " + reason);  // the log has it from JobLog (job_log.h)
}

}  // namespace atelier

#include "daemon/daemon.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/file.h>
#include <signal.h>
#include <sys/signalfd.h>
#include <systemd/sd-daemon.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include "base/error.h"
#include "base/job_states.h"
#include "convert/convert.h"
#include "convert/kinds.h"
#include "convert/report_file.h"
#include "daemon/client_file.h"
#include "daemon/job_json.h"
#include "daemon/job_sets.h"
#include "daemon/file_drop_device.h"
#include "daemon/knit_device.h"
#include "daemon/laser_device.h"
#include "daemon/scan_check.h"
#include "daemon/status_text.h"
#include "daemon/wood_service.h"
#include "drivers/serial_transport.h"
#include "drivers/usb_device.h"
#include "daemon/log.h"

namespace fs = std::filesystem;

namespace atelier {
namespace {

int64_t job_id_arg(const nlohmann::json& args) {
  if (!args.contains("id") || !args["id"].is_number_integer())
    throw ControlError("this request needs an integer job \"id\"");
  return args["id"].get<int64_t>();
}

// A client's own text quoted back in an error, cut so that an answer stays one short line.
std::string shortened(const std::string& text) {
  return text.size() <= 80 ? text : text.substr(0, 80) + "...";
}

// `list` without a "limit": the newest this many jobs (the reply's "total" says how many match).
constexpr int64_t kDefaultListLimit = 1000;

JobFilter list_filter(const nlohmann::json& args) {
  JobFilter filter;
  if (args.contains("state")) {
    const std::string name = args["state"].is_string() ? args["state"].get<std::string>() : args["state"].dump();
    auto s = state_from_name(name);
    if (!s) throw ControlError("unknown state '" + shortened(name) + "'; job states: " + job_state_list_text());
    filter.state = s;
  }
  if (args.contains("kind")) {
    const std::string kind = args["kind"].is_string() ? args["kind"].get<std::string>() : args["kind"].dump();
    if (!is_known_kind(kind))
      throw ControlError("unknown kind '" + shortened(kind) + "'; this build converts: " + known_kinds_text());
    filter.kind = kind;
  }
  filter.limit = kDefaultListLimit;
  if (args.contains("limit")) {
    if (!args["limit"].is_number_integer() || args["limit"].get<int64_t>() < 0)
      throw ControlError("list needs a \"limit\" that is an integer >= 0 (0: every job)");
    const int64_t limit = args["limit"].get<int64_t>();
    filter.limit = limit == 0 ? -1 : limit;
  }
  if (args.contains("offset")) {
    if (!args["offset"].is_number_integer() || args["offset"].get<int64_t>() < 0)
      throw ControlError("list needs an \"offset\" that is an integer >= 0 (jobs to skip, newest first)");
    filter.offset = args["offset"].get<int64_t>();
  }
  return filter;
}

bool same_step(const Job& a, const Job& b) { return a.state == b.state && a.reason == b.reason; }

// A canceled job that has not stopped yet, in the operator's words.
std::string cancel_effect(const Job& job) {
  return progress_unit(job) == "rows" ? "canceling (the machine stops after the row being knitted)"
                                      : "canceling (stopping)";
}

}  // namespace

Daemon::Daemon(fs::path config_file, Config initial)
    : config_file_(std::move(config_file)),
      config_(std::make_shared<const Config>(std::move(initial))),
      started_(std::chrono::steady_clock::now()) {
  sigset_t mask;
  sigemptyset(&mask);
  for (int s : {SIGTERM, SIGINT, SIGHUP}) sigaddset(&mask, s);
  pthread_sigmask(SIG_BLOCK, &mask, nullptr);
  signal_fd_ = signalfd(-1, &mask, SFD_CLOEXEC | SFD_NONBLOCK);
  ::signal(SIGPIPE, SIG_IGN);

  const Config& c = *config_;
  // One daemon per spool: a second one would steal the socket and "recover" live jobs.
  std::filesystem::create_directories(c.spool_dir);
  const fs::path lock_file = c.spool_dir / ".atelierd.lock";
  lock_fd_ = ::open(lock_file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock_fd_ < 0 || ::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0)
    throw InternalError(lock_file.string() + ": another atelierd is already using the spool " +
                             c.spool_dir.string());
  store_ = std::make_unique<Store>(c.store_path);
  SpoolLayout layout{c.spool_dir};
  jobs_ = std::make_unique<JobService>(*store_, layout, [this](const JobChange& change) {
    job_log_.on_change(change);
    if (!control_) return;
    // "at": when this change happened (a progress step does not touch the job's "updated").
    nlohmann::json event = {{"at", iso8601_utc(now_ms())},
                            {"job", job_to_json(change.job)},
                            {"from", change.from},
                            {"to", change.to},
                            {"reason", change.reason}};
    if (change.progress_only) event["progress"] = true;
    control_->publish(event);
    if (web_) web_->publish_job(event);
  });
  jobs_->ensure_layout();
  purge_ = std::make_unique<PurgeWorker>(*store_, layout, [this] {
    auto c = config();
    return RetentionPolicy{c->keep_days, c->keep_jobs};
  });
  // Parquetry's wood library and stock of used wood (Config::state_dir()).
  fs::create_directories(c.state_dir() / "wood");
  fs::create_directories(c.state_dir() / "wood-stock");
  runner_ = std::make_unique<SubprocessRunner>(find_convert_executable(),
                                               static_cast<uint64_t>(c.job_memory_mb) << 20);
  scheduler_ = std::make_unique<Scheduler>(*jobs_, *runner_, [this] { return config(); });
  for (const DeviceConfig& d : c.devices) {
    DeviceWorker::PortResolver resolve;
    if (!d.usb.empty()) {
      const UsbId id = parse_usb_id(d.usb);
      resolve = [id] { return find_usb_tty(id); };
    } else {
      resolve = [port = d.port]() -> std::optional<std::string> {
        std::error_code ec;
        if (fs::exists(port, ec)) return port;
        return std::nullopt;
      };
    }
    auto opener = [](const std::string& port) -> std::unique_ptr<Transport> {
      return SerialTransport::open(port);
    };
    if (d.driver == kGrblDriver) {
      LaserOptions options;
      options.check_first = c.laser_check_first;
      // [laser] start_from (checked by the laser kinds' reader): the device's default placement.
      for (const auto& [kind, table] : c.kind_defaults) {
        const KindInfo* k = find_kind(kind);
        if (!k || k->machine_input != MachineInput::gcode) continue;
        if (auto from = table["laser"]["start_from"].value<std::string>())
          if (auto parsed = grbl::parse_start_from(*from)) options.start_from = *parsed;
      }
      options.mode = d.streaming == "send-response" ? grbl::StreamMode::send_response
                                                    : grbl::StreamMode::character_counting;
      devices_.push_back(std::make_unique<LaserDevice>(d, *jobs_, opener, resolve, options));
    } else if (d.driver == kFileDropDriver) {
      devices_.push_back(std::make_unique<FileDropDevice>(d, *jobs_));
    } else {  // kAyabDriver; config.cc accepts no other driver
      devices_.push_back(std::make_unique<KnitDevice>(d, *jobs_, opener, resolve));
    }
  }
  scheduler_->set_device_hooks(
      [this](const Job& job) -> std::string {
        for (const auto& d : devices_) {
          if (!d->takes(job.kind)) continue;
          if (d->autostarts(job)) return d->config().name;
          return d->config().name + " and `atelierctl start " + std::to_string(job.id) + "`";
        }
        return "";
      },
      [this] {
        for (const auto& d : devices_) d->wake();
      });
  control_ = std::make_unique<ControlServer>(c.socket_path, c.socket_group,
                                             [this](ControlRequest& request) { return serve(request); });
  if (c.web.enabled) {
    web::WebBackend backend;
    backend.call = [this](ControlRequest& request) { return serve(request); };
    backend.config = [this] { return config(); };
    backend.store = store_.get();
    web_ = std::make_unique<web::WebServer>(c.web, std::move(backend));
  }
}

Daemon::~Daemon() {
  // The control and web threads call into everything else: stop them first (also when run()
  // threw).
  if (web_) web_->stop();
  if (control_) control_->stop();
  if (usb_monitor_) usb_monitor_->stop();
  if (purge_) purge_->stop();
  for (auto& d : devices_) d->stop();
  if (scheduler_) scheduler_->stop();
  if (lock_fd_ >= 0) ::close(lock_fd_);
  if (signal_fd_ >= 0) ::close(signal_fd_);
}

std::shared_ptr<const Config> Daemon::config() const {
  std::lock_guard lock(config_mu_);
  return config_;
}

nlohmann::json Daemon::status() {
  nlohmann::json queue = nlohmann::json::object();
  for (const auto& [state, n] : store_->counts()) queue[state_name(state)] = n;
  auto c = config();
  auto uptime = std::chrono::duration_cast<std::chrono::seconds>(
      std::chrono::steady_clock::now() - started_);
  return {{"version", ATELIER_VERSION},
          {"pid", getpid()},
          {"uptime_s", uptime.count()},
          {"spool", c->spool_dir.string()},
          {"store", c->store_path.string()},
          {"watch", c->watch == WatchMode::poll ? "poll" : "inotify"},
          {"workers", c->workers},
          {"kinds", known_kinds()},
          {"queue", queue},
          {"devices", devices_json()},
          {"web", web_status()}};
}

nlohmann::json Daemon::web_status() const {
  auto c = config();
  if (!c->web.enabled) return {{"enabled", false}};
  nlohmann::json out = {{"enabled", true}, {"listen", c->web.listen}, {"listening", web_ && web_error_.empty()}};
  if (web_ && web_error_.empty()) out["url"] = web::page_url(c->web.host, web_->port());
  if (!web_error_.empty()) out["error"] = web_error_;
  return out;
}

nlohmann::json Daemon::serve(ControlRequest& request) {
  static const std::set<std::string> kReading = {"status", "list", "show", "devices"};
  if (kReading.count(request.verb)) return handle(request);
  std::lock_guard lock(act_mu_);
  return handle(request);
}

nlohmann::json Daemon::devices_json() const {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& d : devices_) out.push_back(d->describe());
  return out;
}

Device* Daemon::device_for(const Job& job) const {
  if (!job.device.empty())
    for (const auto& d : devices_)
      if (d->config().name == job.device) return d.get();
  for (const auto& d : devices_)
    if (d->takes(job.kind)) return d.get();
  return nullptr;
}

Device& Daemon::device_of_job(int64_t id) {
  auto job = store_->get(id);
  if (!job) throw ControlError("no job " + std::to_string(id));
  Device* d = device_for(*job);
  if (!d)
    throw ControlError("job " + std::to_string(id) + " (" + job->kind + "): no device is configured for kind " +
                       job->kind);
  return *d;
}

void Daemon::check_sets(const std::string& kind, const std::vector<std::string>& sets) {
  if (sets.empty()) return;
  auto c = config();
  ConversionTask task;
  task.kind = kind;
  task.input = "-";
  task.output_dir = "-";
  task.check_only = true;
  task.sets = sets;
  {
    std::ostringstream defaults;
    auto it = c->kind_defaults.find(kind);
    if (it != c->kind_defaults.end()) defaults << it->second;
    task.defaults_toml = defaults.str();
  }
  task.limits = c->limits;
  task.timeout = std::chrono::seconds(10);
  const std::atomic<bool> never{false};
  ConversionOutcome outcome = runner_->run(task, nullptr, never);
  if (outcome.status == ConversionOutcome::Status::ok) return;
  if (outcome.status == ConversionOutcome::Status::timed_out)
    throw ControlError("--set: checking the values took longer than " + std::to_string(task.timeout.count()) + " s");
  throw ControlError(outcome.message);
}

nlohmann::json Daemon::submit(ControlRequest& request) {
  const nlohmann::json& args = request.args;
  const std::string path = args.at("path").get<std::string>();
  const std::string kind = args.at("kind").get<std::string>();
  if (!is_known_kind(kind))
    throw ControlError("unknown kind '" + kind + "'; this build converts: " + known_kinds_text());
  const std::string name = client_file_name(path);
  std::vector<std::string> sets;
  for (const auto& s : args.value("set", nlohmann::json::array())) {
    std::string text = s.get<std::string>();
    const auto eq = text.find('=');
    if (eq == std::string::npos || eq == 0) throw ControlError("--set " + shortened(text) + ": expected key=value");
    // Each value becomes one argument of the converter child, and Linux takes at most 128 KiB.
    constexpr size_t kMaxSetBytes = 65536;
    if (text.size() > kMaxSetBytes)
      throw ControlError("--set " + shortened(text.substr(0, eq)) + ": " + std::to_string(text.size()) +
                         " bytes is longer than the limit of " + std::to_string(kMaxSetBytes) + " bytes");
    sets.push_back(std::move(text));
  }
  // Read with the client's rights: the file it opened and passed (or, for a peer with our own
  // rights, the path).
  UniqueFd file = client_file(request, 0, path, "atelierctl submit FILE --kind " + kind);
  // Refuse bad parameters now, while the user is at the terminal; TOML is parsed in the child.
  check_sets(kind, sets);
  int64_t id;
  try {
    id = jobs_->submit(file.get(), name, kind, sets_to_params(sets), config()->limits.max_file_bytes,
                       request.via.empty() ? "submitted with atelierctl" : "submitted through " + request.via);
  } catch (const std::runtime_error& e) {
    throw ControlError(e.what());
  }
  scheduler_->enqueue(id);
  return job_to_json(*store_->get(id));
}

nlohmann::json Daemon::handle(ControlRequest& request) {
  const std::string& verb = request.verb;
  const nlohmann::json& args = request.args;
  if (verb == "status") return status();
  if (verb == "list") {
    const JobFilter filter = list_filter(args);
    nlohmann::json out = nlohmann::json::array();
    for (const auto& job : store_->list(filter)) out.push_back(job_to_json(job));
    return {{"jobs", out}, {"total", store_->count(filter)}};
  }
  if (verb == "show") {
    const int64_t id = job_id_arg(args);
    auto job = store_->get(id);
    if (!job) throw ControlError("no job " + std::to_string(id));
    nlohmann::json out = job_to_json(*job);
    nlohmann::json outputs = nlohmann::json::array();
    std::error_code ec;
    if (!job->output_dir.empty()) {
      std::vector<std::string> names;
      for (const auto& e : fs::directory_iterator(job->output_dir, ec))
        names.push_back(e.path().filename().string());
      std::sort(names.begin(), names.end());
      for (auto& n : names) outputs.push_back(n);
    }
    out["outputs"] = outputs;
    out["history"] = events_to_json(store_->history(id));
    if (!job->output_dir.empty()) {
      const nlohmann::json parsed = read_report(job->output_dir);
      if (auto seconds = estimated_seconds(parsed)) out["estimated_s"] = *seconds;
      if (auto warnings = report_warnings(parsed); !warnings.empty()) out["warnings"] = warnings;
    }
    if (job->state == JobState::running) {
      if (Device* d = device_for(*job)) {
        const nlohmann::json described = d->describe();
        const nlohmann::json& on = described["job"];
        if (on.is_object() && on.value("id", int64_t{0}) == id && on.contains("time_left_s"))
          out["time_left_s"] = on["time_left_s"];
      }
    }
    return out;
  }
  if (verb == "submit") return submit(request);
  if (verb == "cancel") {
    if (args.value("all", false)) return cancel_all();
    const int64_t id = job_id_arg(args);
    auto job = store_->get(id);
    if (!job) throw ControlError("no job " + std::to_string(id));
    request_cancel(*job);
    nlohmann::json out = after_command(*job, true);
    if (auto now = store_->get(id); now && (now->state == JobState::converting || now->state == JobState::running))
      out["effect"] = cancel_effect(*now);
    return out;
  }
  if (verb == "retry") {
    const int64_t id = job_id_arg(args);
    try {
      jobs_->retry(id);
    } catch (const std::runtime_error& e) {
      throw ControlError(e.what());
    }
    scheduler_->enqueue(id);
    return job_to_json(*store_->get(id));
  }
  if (verb == "start" || verb == "resume" || verb == "hold" || verb == "frame") {
    const int64_t id = job_id_arg(args);
    Device& device = device_of_job(id);
    const std::string name = device.config().name;
    const Job before = *store_->get(id);
    const std::string tag = std::to_string(id);
    std::string effect;  // what the command set under way, for an answer before it shows
    bool settles = true;  // the job moves on shortly (running, or canceled)
    try {
      if (verb == "start") {
        StartOptions options;
        if (args.contains("from_row")) {
          if (!args["from_row"].is_number_integer()) throw ControlError("start needs an integer \"from_row\"");
          options.from_row = args["from_row"].get<int>();
        }
        if (args.contains("start_needle")) {
          if (!args["start_needle"].is_string())
            throw ControlError("start needs \"start_needle\" as a string (\"L20\", \"R5\" or \"30\")");
          options.start_needle = args["start_needle"].get<std::string>();
        }
        if (args.contains("start_from")) {
          if (!args["start_from"].is_string())
            throw ControlError("start needs \"start_from\" as a string (\"bed\", \"origin\" or \"here\")");
          if (device.config().driver != kGrblDriver)
            throw ControlError("job " + tag + ": " + name + " is not a laser; --start-from places laser jobs");
          options.start_from = args["start_from"].get<std::string>();
        }
        device.start(id, options);
        effect = "armed (runs on " + name + " as soon as it is free)";
        if (options.start_from) effect += ", started from " + *options.start_from;
        if (options.from_row) effect += ", from row " + std::to_string(*options.from_row);
        if (options.start_needle) effect += ", leftmost stitch on needle " + *options.start_needle;
      } else if (verb == "hold") {
        device.hold(id);
        effect = "held (feed hold: motion stopped, beam off; `atelierctl resume " + tag + "` continues)";
        settles = false;  // a hold leaves the job running with its reason
      } else if (verb == "frame") {
        device.frame(id);
        effect = "framing on " + name + " with the beam off (`atelierctl devices` shows the outcome under LAST)";
        settles = false;  // the job stays ready; the outcome is the device's
      } else {
        int from_row = 0;  // none: a laser's feed hold is released
        if (args.contains("from_row")) {
          if (!args["from_row"].is_number_integer())
            throw ControlError("resume needs an integer \"from_row\"");
          from_row = args["from_row"].get<int>();
        }
        device.resume(id, from_row);
        effect = from_row > 0 ? "resuming from row " + std::to_string(from_row) + " (runs on " + name +
                                    " as soon as it is free)"
                              : "resumed";
        settles = from_row > 0;  // a laser continues at once; its job stays running
      }
    } catch (const std::runtime_error& e) {
      throw ControlError(e.what());
    }
    return after_command(before, settles, effect);
  }
  if (verb == "devices") return devices_json();
  if (verb == "laser") return laser(request);
  if (verb == "wood") return wood(request);
  throw ControlError("unknown verb '" + verb + "'");
}

Device& Daemon::laser_device(const nlohmann::json& args) {
  std::vector<Device*> lasers;
  for (const auto& d : devices_)
    if (d->config().driver == kGrblDriver) lasers.push_back(d.get());
  std::string names;
  for (Device* d : lasers) names += (names.empty() ? "" : ", ") + d->config().name;
  if (args.contains("device")) {
    if (!args["device"].is_string()) throw ControlError("laser needs \"device\" as a string (a [[device]] name)");
    const std::string want = args["device"].get<std::string>();
    for (Device* d : lasers)
      if (d->config().name == want) return *d;
    throw ControlError("no laser device '" + shortened(want) + "'" +
                       (names.empty() ? std::string("; atelierd.toml has none") : "; lasers: " + names));
  }
  if (lasers.empty()) throw ControlError("atelierd.toml has no laser device ([[device]] with driver = \"grbl\")");
  if (lasers.size() > 1) throw ControlError("several laser devices (" + names + "): say which with --device NAME");
  return *lasers.front();
}

nlohmann::json Daemon::laser(ControlRequest& request) {
  const nlohmann::json& args = request.args;
  const std::string action = args.value("action", "");
  auto number = [&](const char* key, double fallback) {
    if (!args.contains(key)) return fallback;
    if (!args[key].is_number()) throw ControlError(std::string("laser ") + action + " needs \"" + key + "\" as a number");
    return args[key].get<double>();
  };
  if (action == "log") {
    int64_t limit = 20;
    if (args.contains("limit")) {
      if (!args["limit"].is_number_integer() || args["limit"].get<int64_t>() < 1)
        throw ControlError("laser log needs a \"limit\" that is an integer >= 1");
      limit = args["limit"].get<int64_t>();
    }
    const std::string device = args.contains("device") ? laser_device(args).config().name : "";
    nlohmann::json lines = nlohmann::json::array();
    for (const ConsoleLine& l : store_->console_lines(device, limit))
      lines.push_back({{"at", iso8601_utc(l.at_ms)}, {"device", l.device}, {"uid", l.uid}, {"line", l.line}, {"reply", l.reply}});
    return {{"lines", lines}};
  }
  MachineCommand cmd;
  cmd.uid = static_cast<int64_t>(request.peer.uid);
  if (action == "unlock") cmd.op = MachineCommand::Op::unlock;
  else if (action == "home") cmd.op = MachineCommand::Op::home;
  else if (action == "origin") cmd.op = MachineCommand::Op::origin;
  else if (action == "jog") {
    cmd.op = MachineCommand::Op::jog;
    cmd.dx_mm = number("x", 0);
    cmd.dy_mm = number("y", 0);
    cmd.feed_mm_min = number("feed", 0);
    if (cmd.dx_mm == 0 && cmd.dy_mm == 0) throw ControlError("laser jog needs a distance: \"x\" and/or \"y\" in mm");
  } else if (action == "send") {
    cmd.op = MachineCommand::Op::send;
    if (!args.contains("line") || !args["line"].is_string())
      throw ControlError("laser send needs the \"line\" to send, as a string");
    cmd.line = args["line"].get<std::string>();
  } else {
    throw ControlError("laser needs an \"action\": unlock, home, jog, origin, send or log");
  }
  Device& device = laser_device(args);
  try {
    return device.machine_command(cmd);
  } catch (const std::runtime_error& e) {
    throw ControlError(e.what());
  }
}

nlohmann::json Daemon::wood(ControlRequest& request) {
  const nlohmann::json& args = request.args;
  auto c = config();
  const KindInfo* wood_kind = nullptr;
  for (const KindInfo& k : kinds())
    if (k.uses_wood) wood_kind = &k;
  auto it = wood_kind ? c->kind_defaults.find(std::string(wood_kind->name)) : c->kind_defaults.end();
  if (it == c->kind_defaults.end())
    throw ControlError("the veneer stock belongs to jobs that plan on wood, which this build does not convert");
  WoodPlaces places;
  places.parquetry = it->second;
  places.source = c->source.string();
  if (auto stock = it->second["stock"].value<std::string>(); stock && !stock->empty()) places.stock = *stock;
  places.limits = c->limits;
  std::string busy;
  for (int64_t id : scheduler_->converting_ids())
    if (auto job = store_->get(id); job && job->kind == wood_kind->name)
      busy += (busy.empty() ? "job " : ", ") + std::to_string(id);
  places.busy_hint = busy.empty() ? "" : busy + " being planned";
  places.staging = c->state_dir() / ".wood-add";
  places.check_decode = [memory_mb = c->job_memory_mb](const std::vector<fs::path>& files) {
    check_scans_decode(find_convert_executable(), files,
                       {std::chrono::seconds(30), 30, static_cast<uint64_t>(memory_mb) << 20});
  };
  WoodScans scans;
  if (args.value("action", "") == "add") {
    // Read with the client's rights, like submit: image first, then the mask.
    const std::string usage = "atelierctl wood add IMAGE";
    if (args.contains("image") && args["image"].is_string())
      scans.image = client_file(request, 0, args["image"].get<std::string>(), usage);
    if (args.contains("mask") && args["mask"].is_string())
      scans.mask = client_file(request, 1, args["mask"].get<std::string>(), usage);
  }
  try {
    return wood_request(places, args, std::move(scans));
  } catch (const WoodError& e) {
    throw ControlError(e.what());
  }
}

void Daemon::request_cancel(const Job& job) {
  const int64_t id = job.id;
  Device* device = device_for(job);
  // Ready: canceled at once. Running: the machine finishes its row (knitting) or stops at once
  // (laser: feed hold, soft reset), then the job turns canceled.
  if ((job.state == JobState::ready || job.state == JobState::running) && device && device->cancel(id))
    return;
  // Queued or converting: a converter is killed, which takes well under a second.
  if (!scheduler_->cancel(id))
    throw ControlError("job " + std::to_string(id) + " is " + state_name(job.state) +
                       "; only queued, converting, ready or running jobs can be canceled");
}

nlohmann::json Daemon::after_command(const Job& before, bool settles, const std::string& effect) {
  // Answered at once: the control thread serves every client, so it never waits for a device.
  // A job that has not moved on yet carries what is under way ("effect") and, when it will
  // move on shortly (a start turning it running), "settling": atelierctl then follows it with
  // `show` for a moment and prints the job as it became.
  const int64_t id = before.id;
  std::optional<Job> job = store_->get(id);
  if (!job) throw ControlError("no job " + std::to_string(id));
  nlohmann::json out = job_to_json(*job);
  if (!same_step(*job, before)) return out;
  if (!effect.empty()) out["effect"] = effect;
  if (settles) out["settling"] = true;
  return out;
}

nlohmann::json Daemon::cancel_all() {
  // Queued and ready jobs first, so none of them starts while the others are being stopped.
  std::vector<Job> targets;
  for (JobState s : {JobState::queued, JobState::ready, JobState::converting, JobState::running}) {
    JobFilter filter;
    filter.state = s;
    filter.limit = -1;
    for (Job& job : store_->list(filter)) targets.push_back(std::move(job));
  }
  std::vector<Job> asked;
  for (const Job& job : targets) {
    auto now = store_->get(job.id);
    if (!now || (now->state != JobState::queued && now->state != JobState::ready &&
                 now->state != JobState::converting && now->state != JobState::running))
      continue;  // finished meanwhile
    try {
      request_cancel(*now);
      asked.push_back(*now);
    } catch (const ControlError&) {
      // Finished between the look and the cancel: nothing left to cancel.
    }
  }
  nlohmann::json jobs = nlohmann::json::array();
  int64_t stopping = 0;
  for (const Job& job : asked) {
    auto now = store_->get(job.id);
    if (!now) continue;
    nlohmann::json j = job_to_json(*now);
    if (now->state == JobState::converting || now->state == JobState::running) {
      j["effect"] = cancel_effect(*now);
      ++stopping;
    }
    jobs.push_back(j);
  }
  return {{"jobs", jobs}, {"canceled", static_cast<int64_t>(asked.size())}, {"stopping", stopping}};
}

void Daemon::reload() {
  try {
    Config fresh = load_config(config_file_);
    auto old = config();
    if (fresh.spool_dir != old->spool_dir || fresh.store_path != old->store_path ||
        fresh.socket_path != old->socket_path || fresh.workers != old->workers ||
        fresh.watch != old->watch || fresh.web.enabled != old->web.enabled ||
        fresh.web.listen != old->web.listen || fresh.web.allow_from != old->web.allow_from) {
      log::warning("reload: spool, store, socket, watch, workers and [web] enabled, listen and allow_from "
                   "take effect at restart");
    }
    {
      std::lock_guard lock(config_mu_);
      config_ = std::make_shared<const Config>(std::move(fresh));
    }
    log::info("reloaded " + config_file_.string());
    purge_->wake();  // retention ([store] keep_days, keep_jobs) as now configured
  } catch (const std::exception& e) {
    log::error("reload failed, keeping the running configuration: " + std::string(e.what()));
  }
}

void Daemon::notify_status() {
  sd_notify(0, ("STATUS=" + status_text(store_->counts())).c_str());
}

int Daemon::run() {
  const auto cfg = config();
  // Watch before scanning, so nothing dropped in between is missed.
  hot_folder_ = std::make_unique<HotFolder>(jobs_->layout(), cfg->watch, cfg->settle_ms);
  pickup_ = std::make_unique<Pickup>(*hot_folder_, *jobs_, [this](int64_t id) { scheduler_->enqueue(id); });
  for (int64_t id : jobs_->recover()) scheduler_->enqueue(id);
  purge_->start();  // old finished jobs go now and every hour (only finished ones: not these)
  scheduler_->start(cfg->workers);
  for (auto& d : devices_) static_cast<DeviceWorker&>(*d).start_worker();
  if (std::any_of(devices_.begin(), devices_.end(), [](const auto& d) { return !d->config().usb.empty(); })) {
    usb_monitor_ = std::make_unique<UsbHotplugMonitor>([this](UsbEvent, const UsbDeviceInfo&) {
      for (const auto& d : devices_) d->wake();
    });
    try {
      usb_monitor_->start();
      log::info(usb_monitor_->mode() == UsbHotplugMonitor::Mode::hotplug
                    ? "USB devices: libusb hotplug events"
                    : "USB devices: polled (libusb offers no hotplug here)");
    } catch (const std::exception& e) {
      log::warning(std::string("USB hotplug unavailable, devices are polled: ") + e.what());
      usb_monitor_.reset();
    }
  }
  pickup_->scan();
  if (web_) {
    try {
      web_->start();
    } catch (const std::exception& e) {
      // The machines and the hot folder matter more than the page: run on without it, and say
      // why in the log and in `atelierctl status` (set before the control thread starts).
      web_error_ = e.what();
      log::error(web_error_);
    }
  }
  control_->start();

  uint64_t watchdog_usec = 0;
  const bool watchdog = sd_watchdog_enabled(0, &watchdog_usec) > 0;
  sd_notify(0, "READY=1");
  log::info("atelierd ready: spool " + cfg->spool_dir.string() + ", socket " +
            cfg->socket_path.string());
  notify_status();

  using clock = std::chrono::steady_clock;
  auto next_tick = clock::now();
  const auto tick = std::chrono::milliseconds(
      watchdog ? std::min<uint64_t>(1000, watchdog_usec / 2000) : 1000);
  bool running = true;
  while (running) {
    std::vector<struct pollfd> fds = {{signal_fd_, POLLIN, 0}};
    if (hot_folder_->fd() >= 0) fds.push_back({hot_folder_->fd(), POLLIN, 0});
    auto timeout = hot_folder_->fd() >= 0 ? tick : std::min<std::chrono::milliseconds>(
                                                       tick, hot_folder_->poll_interval());
    if (auto retry = pickup_->next_retry_in())  // a pick-up waiting to be tried again
      timeout = std::min(timeout, std::chrono::ceil<std::chrono::milliseconds>(*retry));
    if (::poll(fds.data(), fds.size(), static_cast<int>(timeout.count())) < 0 && errno != EINTR) {
      log::error(std::string("poll: ") + strerror(errno));
      break;
    }
    if (fds[0].revents & POLLIN) {
      struct signalfd_siginfo si;
      while (::read(signal_fd_, &si, sizeof si) == sizeof si) {
        if (si.ssi_signo == SIGHUP) {
          sd_notify(0, "RELOADING=1");
          reload();
          sd_notify(0, "READY=1");
        } else {
          running = false;
        }
      }
    }
    if (!running) break;
    pickup_->step();
    if (clock::now() >= next_tick) {
      next_tick = clock::now() + tick;
      if (watchdog) sd_notify(0, "WATCHDOG=1");
      notify_status();
    }
  }
  sd_notify(0, "STOPPING=1");
  log::info("stopping: no new jobs; conversions in progress are re-queued");
  if (web_) web_->stop();
  pickup_.reset();
  hot_folder_.reset();
  purge_->stop();
  if (usb_monitor_) usb_monitor_->stop();
  scheduler_->stop();
  for (auto& d : devices_) d->stop();  // a job being knitted ends interrupted, never resumed alone
  control_->stop();
  log::info("stopped");
  return 0;
}

}  // namespace atelier

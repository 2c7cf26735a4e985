// atelierd put together: config, store, hot folder, scheduler, control socket and systemd
// notification, driven by one main loop (signals, inotify, timers).
//
// Threading: run() is the main loop and must be called from the main thread with SIGTERM,
// SIGINT and SIGHUP blocked (the constructor blocks them). Workers, the control server and
// the web server run on their own threads; requests from the last two meet in serve().
#pragma once

#include <chrono>
#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>

#include "daemon/config.h"
#include "daemon/control_server.h"
#include "daemon/conversion_runner.h"
#include "daemon/device.h"
#include "daemon/hot_folder.h"
#include "daemon/job_log.h"
#include "daemon/job_service.h"
#include "daemon/pickup.h"
#include "daemon/purge.h"
#include "daemon/scheduler.h"
#include "daemon/store.h"
#include "daemon/web/web_server.h"
#include "drivers/usb_hotplug.h"

namespace atelier {

class Daemon {
 public:
  // Loads nothing itself: `config_file` is re-read on SIGHUP. Throws on startup failures
  // (store cannot open, socket cannot bind) with a message naming the path.
  Daemon(std::filesystem::path config_file, Config initial);
  ~Daemon();

  // Runs until SIGTERM/SIGINT; returns the process exit code (0 on a clean stop).
  int run();

 private:
  // A request from the control socket or the web server: reading verbs at once (the store and
  // the devices are thread-safe), verbs that act one at a time (act_mu_), as the control
  // socket alone always served them.
  nlohmann::json serve(ControlRequest& request);
  nlohmann::json handle(ControlRequest& request);
  nlohmann::json status();
  nlohmann::json web_status() const;  // status's "web": enabled, listen, listening, url, error
  // `submit`: the file read from the client's descriptor (client_file.h), the --set values
  // checked by an `atelier-convert --check` child and stored unparsed (job_sets.h).
  nlohmann::json submit(ControlRequest& request);
  // Refuses bad --set values with the checker child's reason (ControlError).
  void check_sets(const std::string& kind, const std::vector<std::string>& sets);
  nlohmann::json wood(ControlRequest& request);  // the `wood` verb (wood_service.h)
  // The `laser` verb: operator commands to a laser's controller, and its console log.
  nlohmann::json laser(ControlRequest& request);
  // The laser device `args["device"]` names, or the only one. Throws ControlError.
  Device& laser_device(const nlohmann::json& args);
  nlohmann::json devices_json() const;
  Device* device_for(const Job& job) const;
  Device& device_of_job(int64_t id);
  // `cancel ID`: asks the job's device or the scheduler to stop it; throws ControlError when
  // the job is finished.
  void request_cancel(const Job& job);
  // `cancel --all`: every queued, converting, ready and running job.
  nlohmann::json cancel_all();
  // The answer to a command on job `before.id`, at once: the job as it is now; when it does
  // not show the command yet, `effect` (what the command set under way) and, if it will move
  // on shortly (`settles`), "settling": true, so the client may follow it with `show`.
  nlohmann::json after_command(const Job& before, bool settles, const std::string& effect = "");
  void reload();
  void notify_status();
  std::shared_ptr<const Config> config() const;

  std::filesystem::path config_file_;
  mutable std::mutex config_mu_;
  std::shared_ptr<const Config> config_;
  std::chrono::steady_clock::time_point started_;
  int signal_fd_ = -1;
  int lock_fd_ = -1;  // flock on <spool>/.atelierd.lock, held for the daemon's life
  std::unique_ptr<Store> store_;
  JobLog job_log_;  // every job change, as a record with the job's fields (job_log.h)
  std::unique_ptr<ControlServer> control_;
  std::mutex act_mu_;  // serve(): one acting request at a time, from either server
  // [web] enabled: the page and JSON API (docs/web.md); null when off. web_error_: why it
  // could not listen, for `status` (the daemon runs on without it).
  std::unique_ptr<web::WebServer> web_;
  std::string web_error_;
  std::unique_ptr<JobService> jobs_;
  std::unique_ptr<PurgeWorker> purge_;  // retention: at start-up, then hourly
  std::unique_ptr<SubprocessRunner> runner_;
  std::unique_ptr<Scheduler> scheduler_;
  std::unique_ptr<HotFolder> hot_folder_;
  std::unique_ptr<Pickup> pickup_;  // claims what hot_folder_ reports, retries transient failures
  std::vector<std::unique_ptr<Device>> devices_;  // one worker each, from [[device]]
  // Wakes the devices when a USB device comes or goes (only when a device is found by USB id),
  // so plugging a machine in brings it online at once.
  std::unique_ptr<UsbHotplugMonitor> usb_monitor_;
};

}  // namespace atelier

// The workshop's web page and JSON API (docs/web.md), served by cpp-httplib on threads of
// its own: a slow or stuck browser holds one of those threads, never the daemon's control
// thread, its scheduler or its machines.
//
// What it may do: everything goes through the backend, the same handler the control socket
// uses (Daemon::handle), with verbs and arguments the server builds itself; no request names
// a path. Files are served by web/job_files.h from a job's own output folder only.
//
// Threading: start()/stop() from one thread (the daemon's main thread). publish_job() from
// any thread. Requests run on the server's thread pool (kThreads); event streams hold one
// thread each while open (at most kMaxEventStreams). A poller thread watches the devices
// and publishes their list when it changes.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>

#include "base/clock.h"
#include "daemon/config.h"
#include "daemon/control_server.h"
#include "daemon/store.h"
#include "daemon/web/address_filter.h"
#include "daemon/web/event_hub.h"
#include "daemon/web/web_auth.h"

namespace httplib {
class ContentReader;
class Server;
struct Request;
struct Response;
}  // namespace httplib

namespace atelier::web {

// What the server needs of the daemon. Every function may be called from any server thread.
struct WebBackend {
  // Serves one control request as the control socket does (Daemon's handler). Throws
  // ControlError with the message for the client.
  std::function<nlohmann::json(ControlRequest& request)> call;
  // The configuration as now loaded: [web] token, users and session_hours, and [limits]
  // max_file_bytes, apply to each request as they are now (a SIGHUP changes them).
  std::function<std::shared_ptr<const Config>()> config;
  // The job store (thread-safe), read for each job's times (its history).
  Store* store = nullptr;
};

// "http://127.0.0.1:8631/", "http://[::1]:8631/": the page's address.
std::string page_url(const std::string& host, int port);

class WebServer {
 public:
  static constexpr int kThreads = 48;
  static constexpr size_t kMaxEventStreams = 32;
  static constexpr size_t kMaxQueuedEvents = 2048;  // per stream; beyond, the stream ends
  static constexpr size_t kMaxJsonBody = 64 * 1024;  // bytes, any request but an upload
  static constexpr int kMaxPasswordChecks = 4;       // yescrypt checks at once

  // `web`: the [web] table as at start (listen and allow_from take effect at restart).
  // `clock` (borrowed) times sessions and the login throttle.
  WebServer(const WebConfig& web, WebBackend backend, Clock& clock = real_clock());
  ~WebServer();

  // Binds the listening address and starts serving. Throws InternalError naming the address
  // and the cause (in use, not allowed by the systemd unit's address families, ...).
  void start();
  void stop();
  // The port listened on ([web] listen's).
  int port() const { return web_.port; }

  // A job event as `watch` sends it ({"at", "job", "from", "to", "reason", "progress"?}).
  void publish_job(const nlohmann::json& event);

 private:
  void routes();
  // Pages and the API; each answers JSON errors ({"error": ...}) with the status of docs/web.md.
  void serve_asset(const httplib::Request& req, httplib::Response& res);
  void serve_jobs(const httplib::Request& req, httplib::Response& res);
  void serve_job(const httplib::Request& req, httplib::Response& res);
  void serve_file(const httplib::Request& req, httplib::Response& res);
  void serve_action(const httplib::Request& req, httplib::Response& res);
  void serve_events(const httplib::Request& req, httplib::Response& res);
  void serve_session(const httplib::Request& req, httplib::Response& res);
  void serve_login(const httplib::Request& req, httplib::Response& res);
  void serve_logout(const httplib::Request& req, httplib::Response& res);
  void serve_submit(const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& reader);

  // Whether the request may act; answers 401/403 itself when not (`user` is who acts).
  bool allowed_to_act(const httplib::Request& req, httplib::Response& res, std::string& user);
  // A control verb on behalf of a web client (no Unix credentials: it may read no path).
  nlohmann::json call(const std::string& verb, nlohmann::json args);
  // The job object plus elapsed_s, state_s and time_left_s (job_timing.h).
  nlohmann::json with_timing(nlohmann::json job);
  void poll_devices();

  WebConfig web_;
  WebBackend backend_;
  Clock& clock_;
  AddressFilter allowed_;
  std::vector<std::string> names_;  // Host names answered: [web] server_names, the box's own
  SessionTable sessions_;
  LoginThrottle throttle_;
  EventHub hub_;
  std::unique_ptr<httplib::Server> server_;
  std::thread listener_;
  std::thread poller_;
  std::mutex mu_;
  std::condition_variable cv_;
  bool stopping_ = false;
  bool poll_now_ = false;
  std::atomic<int> password_checks_{0};  // logins being checked now
  std::atomic<bool> stopped_{false};     // stop() began: uploads still streaming give up  // a job changed state: the poller looks at the devices at once
  std::string devices_json_ = "[]";  // the last device list published (guarded by mu_)
  nlohmann::json devices_ = nlohmann::json::array();  // the same, parsed
};

}  // namespace atelier::web

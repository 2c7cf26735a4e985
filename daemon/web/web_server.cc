// WebServer: lifecycle, the page's files, sessions and the live event stream. The job
// endpoints are in web_api.cc.
#include "daemon/web/web_server.h"

#include <sys/socket.h>
#include <unistd.h>
#include <netinet/in.h>

#include <cerrno>
#include <cstring>
#include <httplib.h>

#include "base/error.h"
#include "base/unique_fd.h"
#include "convert/kinds.h"
#include "daemon/log.h"
#include "daemon/web/http_reply.h"
#include "daemon/web/web_assets.h"

namespace atelier::web {
namespace {

// The page's own policy: its script and stylesheet only, data only from this server.
constexpr const char* kPagePolicy =
    "default-src 'self'; img-src 'self' data: blob:; script-src 'self'; style-src 'self'; "
    "connect-src 'self'; frame-ancestors 'none'; base-uri 'none'; form-action 'self'";

// Each kind's machine as the page needs to know it (a laser start asks first; a knitting job
// resumes from a row), from the registry of kinds.
nlohmann::json kind_machines() {
  nlohmann::json out = nlohmann::json::object();
  for (const KindInfo& k : kinds()) {
    const char* machine = "none";
    switch (k.machine_input) {
      case MachineInput::knit_pattern:
      case MachineInput::lace_chart:
        machine = "knitting";
        break;
      case MachineInput::gcode:
        machine = "laser";
        break;
      case MachineInput::stitch_files:
        machine = "files";
        break;
      case MachineInput::none:
        break;
    }
    out[std::string(k.name)] = machine;
  }
  return out;
}

// Why the listening socket cannot be had, in the operator's words.
std::string bind_failure(const WebConfig& web) {
  const int family = is_ipv6_host(web.host) ? AF_INET6 : AF_INET;
  UniqueFd probe(::socket(family, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!probe.valid() && (errno == EAFNOSUPPORT || errno == EPERM || errno == EACCES))
    return std::string("this process may not open ") + (family == AF_INET6 ? "IPv6" : "IPv4") +
           " sockets (" + std::strerror(errno) + "); under systemd run `systemctl daemon-reload` after "
           "enabling [web], so the unit's generator allows the address family";
  return "the address is in use or not on this machine";
}

}  // namespace

std::string page_url(const std::string& host, int port) {
  return "http://" + (is_ipv6_host(host) ? "[" + host + "]" : host) + ":" + std::to_string(port) + "/";
}

WebServer::WebServer(const WebConfig& web, WebBackend backend, Clock& clock)
    : web_(web),
      backend_(std::move(backend)),
      clock_(clock),
      allowed_(web.allow_from),
      sessions_(clock),
      throttle_(clock),
      hub_(kMaxEventStreams, kMaxQueuedEvents),
      server_(std::make_unique<httplib::Server>()) {
  names_ = web.server_names;
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) == 0 && name[0]) {
    names_.emplace_back(name);
    names_.emplace_back(std::string(name) + ".local");  // mDNS, as avahi announces the box
  }
  server_->new_task_queue = [] { return new httplib::ThreadPool(kThreads); };
  server_->set_keep_alive_timeout(5);
  server_->set_read_timeout(5);  // s: a stalled client frees its thread (and a stop) soon
  server_->set_write_timeout(10);
  // Bodies are capped per request as [limits] is now (a SIGHUP may change it): by the stated
  // Content-Length before reading (pre-routing, serve_submit) and by counting an upload as it
  // streams. httplib's own cap is only the last resort.
  server_->set_payload_max_length(uint64_t{1} << 40);
  routes();
}

WebServer::~WebServer() { stop(); }

void WebServer::start() {
  if (!server_->bind_to_port(web_.host, web_.port))
    throw InternalError("web: cannot listen on " + web_.listen + ": " + bind_failure(web_));
  listener_ = std::thread([this] {
    if (!server_->listen_after_bind()) {
      std::lock_guard lock(mu_);
      if (!stopping_) log::error("web: the page stopped listening on " + page_url(web_.host, web_.port));
    }
  });
  // stop() is a no-op until the listener runs: wait for it, so a stop right after a start
  // (the daemon failing further on) does not leave the listener running and join() waiting.
  for (int i = 0; i < 500 && !server_->is_running(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  poller_ = std::thread([this] { poll_devices(); });
  std::string allow;
  for (const auto& a : web_.allow_from) allow += (allow.empty() ? "" : ", ") + a;
  log::info("web page on " + page_url(web_.host, web_.port) + " (allow_from " + allow + ")");
}

void WebServer::stop() {
  {
    std::lock_guard lock(mu_);
    if (stopping_) return;
    stopping_ = true;
  }
  stopped_ = true;
  cv_.notify_all();
  hub_.close();  // event streams end, so the pool's threads come back
  if (server_) server_->stop();
  if (listener_.joinable()) listener_.join();
  if (poller_.joinable()) poller_.join();
}

void WebServer::publish_job(const nlohmann::json& event) {
  hub_.publish(sse_message("job", event.dump()));
  if (event.value("progress", false)) return;
  // A job that changed state has usually changed its machine's too: look at once.
  {
    std::lock_guard lock(mu_);
    poll_now_ = true;
  }
  cv_.notify_all();
}

void WebServer::poll_devices() {
  // Device states change without a job event (offline, online, a prompt cleared): look four
  // times a second and publish the list when it differs.
  std::unique_lock lock(mu_);
  while (!stopping_) {
    lock.unlock();
    std::string now;
    nlohmann::json parsed;
    try {
      parsed = call("devices", nlohmann::json::object());
      now = parsed.dump();
    } catch (const std::exception& e) {
      log::warning(std::string("web: cannot read the devices: ") + e.what());
    }
    lock.lock();
    if (!now.empty() && now != devices_json_) {
      devices_json_ = now;
      devices_ = std::move(parsed);
      hub_.publish(sse_message("devices", now));
    }
    cv_.wait_for(lock, std::chrono::milliseconds(250), [this] { return stopping_ || poll_now_; });
    poll_now_ = false;
  }
}

nlohmann::json WebServer::call(const std::string& verb, nlohmann::json args) {
  ControlRequest request;
  request.verb = verb;
  request.args = std::move(args);
  // No Unix credentials (uid -1): client_file() then reads only the descriptors passed.
  return backend_.call(request);
}

void WebServer::routes() {
  httplib::Server& s = *server_;
  s.set_default_headers({{"X-Content-Type-Options", "nosniff"},
                         {"Referrer-Policy", "no-referrer"},
                         {"X-Frame-Options", "DENY"}});
  s.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    if (!allowed_.allows(req.remote_addr)) {
      json_error(res, 403, "refused: " + req.remote_addr + " is not in [web] allow_from");
      return httplib::Server::HandlerResponse::Handled;
    }
    if (!host_allowed(req.get_header_value("Host"), names_)) {
      json_error(res, 403, "refused: this server is not known by that name; add it to [web] server_names");
      return httplib::Server::HandlerResponse::Handled;
    }
    if (req.method != "GET" && req.method != "HEAD" && req.method != "POST") {
      json_error(res, 405, req.method + " is not served here (GET and POST only)");
      return httplib::Server::HandlerResponse::Handled;
    }
    // httplib caps only bodies of a stated length, and counts compressed bytes: a body that is
    // chunked, unannounced or compressed could grow without bound in memory. Browsers and
    // curl state the length of forms and uploads and never compress them.
    const std::string coding = req.get_header_value("Content-Encoding");
    if (req.has_header("Transfer-Encoding") || (!coding.empty() && coding != "identity") ||
        (req.method == "POST" && !req.has_header("Content-Length"))) {
      json_error(res, 411, "send the body uncompressed with a Content-Length");
      return httplib::Server::HandlerResponse::Handled;
    }
    // Only an upload may be large; anything else is refused before its body is read.
    if (req.path != "/api/submit" && req.get_header_value<uint64_t>("Content-Length") > kMaxJsonBody) {
      json_error(res, 413, "request body over " + std::to_string(kMaxJsonBody) + " bytes");
      return httplib::Server::HandlerResponse::Handled;
    }
    // Several ranges would make httplib build the whole multipart answer in memory (or read a
    // file once per range); one range is all a browser or download tool asks for.
    if (req.ranges.size() > 1) {
      json_error(res, 416, "one byte range at a time");
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  s.set_error_handler(httplib::Server::HandlerWithResponse([this](const httplib::Request& req, httplib::Response& res) {
    if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
    if (res.status == 413) {
      json_error(res, 413, "the upload is larger than the hot folder's limit of " +
                               std::to_string(backend_.config()->limits.max_file_bytes) +
                               " bytes ([limits] max_file_bytes)");
    } else if (res.status == 404) {
      json_error(res, 404, "no such page: " + req.path);
    } else {
      json_error(res, res.status, "HTTP error " + std::to_string(res.status));
    }
    return httplib::Server::HandlerResponse::Handled;
  }));
  s.set_exception_handler([](const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
    std::string what = "unknown error";
    try {
      std::rethrow_exception(ep);
    } catch (const std::exception& e) {
      what = e.what();
    } catch (...) {
    }
    log::error("web: " + req.method + " " + req.path + ": " + what);
    json_error(res, 500, "internal error: " + what);
  });

  auto asset = [this](const httplib::Request& req, httplib::Response& res) { serve_asset(req, res); };
  s.Get("/", asset);
  s.Get(R"(/[a-z]+\.(js|css|svg))", asset);
  s.Get("/api/status", [this](const httplib::Request&, httplib::Response& res) {
    nlohmann::json status = call("status", nlohmann::json::object());
    status["kind_machines"] = kind_machines();
    reply_json(res, 200, status);
  });
  s.Get("/api/devices", [this](const httplib::Request&, httplib::Response& res) {
    reply_json(res, 200, call("devices", nlohmann::json::object()));
  });
  s.Get("/api/jobs", [this](const httplib::Request& req, httplib::Response& res) { serve_jobs(req, res); });
  s.Get(R"(/api/jobs/(\d+))", [this](const httplib::Request& req, httplib::Response& res) { serve_job(req, res); });
  s.Get(R"(/api/jobs/(\d+)/files/(.*))",
        [this](const httplib::Request& req, httplib::Response& res) { serve_file(req, res); });
  s.Post(R"(/api/jobs/(\d+)/(start|cancel|hold|resume|frame|retry))",
         [this](const httplib::Request& req, httplib::Response& res) { serve_action(req, res); });
  s.Post("/api/submit", [this](const httplib::Request& req, httplib::Response& res,
                               const httplib::ContentReader& reader) { serve_submit(req, res, reader); });
  s.Get("/api/events", [this](const httplib::Request& req, httplib::Response& res) { serve_events(req, res); });
  s.Get("/api/session", [this](const httplib::Request& req, httplib::Response& res) { serve_session(req, res); });
  s.Post("/api/login", [this](const httplib::Request& req, httplib::Response& res) { serve_login(req, res); });
  s.Post("/api/logout", [this](const httplib::Request& req, httplib::Response& res) { serve_logout(req, res); });
}

void WebServer::serve_asset(const httplib::Request& req, httplib::Response& res) {
  const Asset* a = find_asset(req.path);
  if (!a) {
    json_error(res, 404, "no such page: " + req.path);
    return;
  }
  res.set_header("Content-Security-Policy", kPagePolicy);
  res.set_header("Cache-Control", "no-cache");
  res.set_content(std::string(a->body), std::string(a->content_type));
}

void WebServer::serve_events(const httplib::Request&, httplib::Response& res) {
  auto stream = hub_.subscribe();
  if (!stream) {
    json_error(res, 503, "too many event streams open (at most " + std::to_string(kMaxEventStreams) +
                             "); close another tab of this page");
    return;
  }
  std::string first;
  {
    std::lock_guard lock(mu_);
    // The browser reconnects after a second if the stream breaks; the device list at once,
    // so a page that opens the stream knows the machines.
    first = "retry: 1000\n\n" + sse_message("devices", devices_json_);
  }
  res.set_header("X-Accel-Buffering", "no");  // a reverse proxy must not hold events back
  res.set_header("Cache-Control", "no-store");
  res.set_chunked_content_provider(
      "text/event-stream", [stream, first](size_t, httplib::DataSink& sink) mutable {
        if (!first.empty()) {
          std::string out = std::move(first);
          first.clear();
          return sink.write(out.data(), out.size());
        }
        // A comment every 15 s keeps proxies and the browser from timing the stream out and
        // tells us soon when the browser has gone.
        std::optional<std::string> message = stream->next(std::chrono::seconds(15));
        if (stream->ended()) {
          sink.done();
          return true;
        }
        const std::string out = message ? *message : std::string(": keep-alive\n\n");
        return sink.write(out.data(), out.size());
      });
}

namespace {

nlohmann::json logins(const WebConfig& web) {
  return {{"password", !web.users.empty()}, {"token", !web.token.empty()}};
}

// The session object of docs/web.md, for `user` acting by `auth` (nulls when nobody).
nlohmann::json session_json(const Config& config, const std::optional<std::string>& user, const char* auth,
                            const std::optional<std::string>& csrf) {
  auto or_null = [](const std::optional<std::string>& s) { return s ? nlohmann::json(*s) : nlohmann::json(nullptr); };
  return {{"user", or_null(user)},
          {"auth", auth ? nlohmann::json(auth) : nlohmann::json(nullptr)},
          {"csrf", or_null(csrf)},
          {"can_act", user.has_value()},
          {"logins", logins(config.web)},
          // The page refuses a larger file before sending it (the server would cut it off).
          {"max_upload_bytes", config.limits.max_file_bytes}};
}

ActionRequest action_request(const httplib::Request& req) {
  return {req.get_header_value("Authorization"), req.get_header_value("Cookie"), req.get_header_value(kCsrfHeader),
          req.get_header_value("Origin"),        req.get_header_value("Host"),   req.get_header_value("Sec-Fetch-Site")};
}

}  // namespace

bool WebServer::allowed_to_act(const httplib::Request& req, httplib::Response& res, std::string& user) {
  const auto config = backend_.config();
  const Verdict v = judge_action(action_request(req), config->web, sessions_);
  if (v.outcome == Verdict::Outcome::allowed) {
    user = v.user;
    return true;
  }
  json_error(res, v.outcome == Verdict::Outcome::unauthorised ? 401 : 403, v.message);
  return false;
}

void WebServer::serve_session(const httplib::Request& req, httplib::Response& res) {
  const auto config = backend_.config();
  const WebConfig& web = config->web;
  const ActionRequest r = action_request(req);
  if (r.authorization.rfind("Bearer ", 0) == 0 && token_ok(web, r.authorization.substr(7))) {
    reply_json(res, 200, session_json(*config, "token", "token", std::nullopt));
  } else if (auto s = sessions_.find(cookie_value(r.cookie, kSessionCookie)); s && still_allowed(*s, web)) {
    reply_json(res, 200, session_json(*config, s->user, "session", s->csrf));
  } else {
    reply_json(res, 200, session_json(*config, std::nullopt, nullptr, std::nullopt));
  }
}

void WebServer::serve_login(const httplib::Request& req, httplib::Response& res) {
  const auto config = backend_.config();
  const WebConfig& web = config->web;
  if (is_cross_site(action_request(req))) {
    json_error(res, 403, "refused: a login from another site's page");
    return;
  }
  if (!web.can_act()) {
    json_error(res, 403, "this page is read-only: atelierd.toml has no [web] token and no [web.users]");
    return;
  }
  if (throttle_.blocked(req.remote_addr)) {
    json_error(res, 429, "too many failed logins from " + req.remote_addr + "; wait a minute");
    return;
  }
  // A password check costs yescrypt's memory and time: a few at once, the rest wait their turn
  // by asking again.
  struct Slot {
    std::atomic<int>& n;
    ~Slot() { --n; }
  } slot{password_checks_};
  if (++password_checks_ > kMaxPasswordChecks) {
    json_error(res, 503, "too many logins at once; try again in a moment");
    return;
  }
  nlohmann::json body = nlohmann::json::parse(req.body, nullptr, false);
  if (!body.is_object()) {
    json_error(res, 400, "login needs a JSON object: {\"user\", \"password\"} or {\"token\"}");
    return;
  }
  // Counted as failed before it is checked, so logins sent in parallel cannot slip past the
  // throttle while the checks run; a success clears the count.
  throttle_.failed(req.remote_addr);
  std::string user;
  if (body.contains("token") && body["token"].is_string()) {
    if (token_ok(web, body["token"].get<std::string>())) user = "token";
  } else if (body.contains("user") && body["user"].is_string() && body.contains("password") &&
             body["password"].is_string()) {
    const std::string name = body["user"].get<std::string>();
    if (user_password_ok(web, name, body["password"].get<std::string>())) user = name;
  } else {
    json_error(res, 400, "login needs {\"user\", \"password\"} or {\"token\"}, as strings");
    return;
  }
  if (user.empty()) {
    log::warning("web: failed login from " + req.remote_addr);
    json_error(res, 401, "wrong user name, password or token");
    return;
  }
  throttle_.succeeded(req.remote_addr);
  const auto lifetime = std::chrono::hours(web.session_hours);
  const Session s = sessions_.create(user, lifetime);
  res.set_header("Set-Cookie", std::string(kSessionCookie) + "=" + s.id + "; Path=/; HttpOnly; SameSite=Strict; Max-Age=" +
                                   std::to_string(std::chrono::seconds(lifetime).count()));
  log::info("web: " + user + " logged in from " + req.remote_addr);
  reply_json(res, 200, session_json(*config, user, "session", s.csrf));
}

void WebServer::serve_logout(const httplib::Request& req, httplib::Response& res) {
  std::string user;
  if (!allowed_to_act(req, res, user)) return;
  sessions_.remove(cookie_value(req.get_header_value("Cookie"), kSessionCookie));
  res.set_header("Set-Cookie", std::string(kSessionCookie) + "=; Path=/; HttpOnly; SameSite=Strict; Max-Age=0");
  reply_json(res, 200, session_json(*backend_.config(), std::nullopt, nullptr, std::nullopt));
}

}  // namespace atelier::web

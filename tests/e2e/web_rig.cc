#include "tests/e2e/web_rig.h"

#include <signal.h>

#include <stdexcept>
#include <thread>

#include "daemon/store.h"
#include "daemon/web/password.h"

namespace fs = std::filesystem;

namespace atelier::test {

namespace {

// Completed jobs written straight into a new store, as if the workshop had run them.
void preload(const fs::path& store_path, int count) {
  Store store(store_path);
  const int64_t now = now_ms();
  for (int i = 0; i < count; ++i) {
    Job j;
    j.id = store.reserve_id();
    j.kind = i % 3 == 0 ? "knit" : (i % 3 == 1 ? "cut" : "embroidery");
    j.name = "archive-" + std::to_string(i) + ".png";
    j.state = JobState::completed;
    j.reason = "converted and delivered";
    j.created_ms = now - (count - i) * 60000;
    j.updated_ms = j.created_ms + 30000;
    store.insert_job(j);
  }
}

}  // namespace

WebRig::WebRig(WebRigOptions options) {
  // A client still sending a body the server has already refused (401, 411, 413) gets EPIPE
  // from httplib, not a SIGPIPE that would end the whole test binary.
  ::signal(SIGPIPE, SIG_IGN);
  if (options.knitter) knitter_.emplace(options.row_ms);
  port_ = free_tcp_port();
  daemon_ = std::make_unique<DaemonProcess>(dir_.path());
  std::string toml = "[spool]\ndir = \"spool\"\n[store]\npath = \"jobs.sqlite\"\nkeep_days = 0\nkeep_jobs = 0\n"
                     "[control]\nsocket = \"" + daemon_->socket().string() + "\"\n"
                     "[web]\nenabled = true\nlisten = \"127.0.0.1:" + std::to_string(port_) + "\"\n"
                     "token = \"" + std::string(kToken) + "\"\n"
                     "[web.users]\n" + kUser + " = \"" + web::hash_password(kPassword) + "\"\n" +
                     "[knit]\nwidth = 40\n" + options.extra_toml;
  if (knitter_)
    toml += "[[device]]\nname = \"knitter\"\ndriver = \"ayab\"\nport = \"" + knitter_->link().string() +
            "\"\nmachine = \"kh930\"\nkinds = [\"knit\"]\nautostart = true\n";
  write_file(daemon_->config(), toml);
  if (options.preload_jobs > 0) preload(dir_.path() / "jobs.sqlite", options.preload_jobs);
  daemon_->start();
  // The web server starts just before the control socket answers; wait for it to answer too.
  auto c = client();
  for (int i = 0; i < 100; ++i) {
    if (auto r = c->Get("/api/status"); r && r->status == 200) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  throw std::runtime_error("the web server did not answer on port " + std::to_string(port_) + ":\n" + daemon_->log());
}

std::unique_ptr<httplib::Client> WebRig::client() const {
  auto c = std::make_unique<httplib::Client>("127.0.0.1", port_);
  c->set_connection_timeout(5);
  c->set_read_timeout(30);
  c->set_write_timeout(30);
  return c;
}

httplib::Headers WebRig::token_headers() { return {{"Authorization", std::string("Bearer ") + kToken}}; }

std::pair<std::string, std::string> WebRig::login() const {
  auto r = client()->Post("/api/login", nlohmann::json{{"user", kUser}, {"password", kPassword}}.dump(),
                          "application/json");
  if (!r || r->status != 200) throw std::runtime_error("login failed");
  const std::string set_cookie = r->get_header_value("Set-Cookie");
  const std::string cookie = set_cookie.substr(0, set_cookie.find(';'));
  return {cookie, nlohmann::json::parse(r->body)["csrf"].get<std::string>()};
}

nlohmann::json WebRig::submit(const std::string& kind, const std::string& name, const std::string& bytes) const {
  httplib::MultipartFormDataItems items = {{"kind", kind, "", ""}, {"file", bytes, name, "application/octet-stream"}};
  auto r = client()->Post("/api/submit", token_headers(), items);
  if (!r) return {{"status", 0}, {"error", "no answer"}};
  nlohmann::json out = nlohmann::json::parse(r->body, nullptr, false);
  if (!out.is_object()) out = {{"error", r->body}};
  out["status"] = r->status;
  return out;
}

bool WebRig::wait_state(int64_t id, const std::string& state, std::chrono::milliseconds timeout) const {
  auto c = client();
  return daemon_->wait_for([&] {
    auto r = c->Get("/api/jobs/" + std::to_string(id));
    return r && r->status == 200 && nlohmann::json::parse(r->body)["state"] == state;
  }, timeout);
}

}  // namespace atelier::test

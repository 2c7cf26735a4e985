// The web page's end-to-end rig: the real atelierd with [web] on a free loopback port, a
// token and a user "alice", optionally a knitting-machine emulator as its knitter, and an
// HTTP client to it. One per test; not thread-safe.
#pragma once

#include <httplib.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "tests/e2e/daemon_harness.h"

namespace atelier::test {

struct WebRigOptions {
  bool knitter = false;       // a KH930 emulator as device "knitter" for knit jobs
  int row_ms = 3;             // the emulator's time per row
  std::string extra_toml;     // more configuration (e.g. "[limits]\nmax_file_bytes = 1000\n")
  int preload_jobs = 0;       // completed jobs put in the store before the daemon starts
};

class WebRig {
 public:
  static constexpr const char* kToken = "test-token-0123456789abcdef";
  static constexpr const char* kUser = "alice";
  static constexpr const char* kPassword = "correct horse battery";

  explicit WebRig(WebRigOptions options = {});
  DaemonProcess& daemon() { return *daemon_; }
  int port() const { return port_; }
  std::string base_url() const { return "http://127.0.0.1:" + std::to_string(port_); }
  // A client with 30 s timeouts.
  std::unique_ptr<httplib::Client> client() const;
  // Headers that act with the bearer token.
  static httplib::Headers token_headers();
  // Logs alice in; returns the cookie header value and the CSRF token.
  std::pair<std::string, std::string> login() const;
  // A file submitted with the token as a job of `kind`; the answer's job object (or the error
  // answer, with "status").
  nlohmann::json submit(const std::string& kind, const std::string& name, const std::string& bytes) const;
  // Waits until job `id` is in `state` (polling GET /api/jobs/ID).
  bool wait_state(int64_t id, const std::string& state, std::chrono::milliseconds timeout = std::chrono::seconds(120)) const;
  std::optional<KnitEmulator>& knitter() { return knitter_; }

 private:
  TempDir dir_;
  std::optional<KnitEmulator> knitter_;
  int port_ = 0;
  std::unique_ptr<DaemonProcess> daemon_;
};

}  // namespace atelier::test

// The control socket: a Unix stream socket speaking JSON lines (docs/control-protocol.md).
// Requests are dispatched to a handler; `watch` clients get every published event.
//
// Threading: the server runs its own thread (start/stop). The handler is called on that
// thread, one request at a time. publish() may be called from any thread.
#pragma once

#include <filesystem>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "base/error.h"

namespace atelier {

// A request that cannot be served; its message goes back to the client as {"ok": false}.
class ControlError : public BadInput {
 public:
  using BadInput::BadInput;
};

class ControlServer {
 public:
  using Handler = std::function<nlohmann::json(const std::string& verb, const nlohmann::json& args)>;

  // Binds `socket_path` (a stale socket file is replaced), mode 0660, group `group` when it
  // exists. Throws std::runtime_error naming the path on failure.
  ControlServer(std::filesystem::path socket_path, const std::string& group, Handler handler);
  ~ControlServer();

  void start();
  void stop();
  void publish(const nlohmann::json& event);

 private:
  void loop();
  void serve_line(int fd, const std::string& line);
  void send_line(int fd, const nlohmann::json& message);
  void drop(int fd);

  std::filesystem::path path_;
  Handler handler_;
  int listen_fd_ = -1;
  int wake_fd_ = -1;  // eventfd: stop requested or events to deliver
  std::thread thread_;
  std::mutex mu_;
  std::vector<nlohmann::json> pending_;
  bool stopping_ = false;
  std::set<int> watchers_;
  std::vector<std::pair<int, std::string>> clients_;  // fd, partial input
};

}  // namespace atelier

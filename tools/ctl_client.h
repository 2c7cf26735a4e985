// Client side of the control socket (docs/control-protocol.md): JSON lines over a Unix
// stream socket. One ControlClient owns one connection; it is not thread-safe (use it from
// one thread). atelierctl is built on it; later tools and tests can reuse it.
#pragma once

#include <chrono>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/error.h"

namespace atelier::ctl {

// Where the daemon listens when no --socket is given: $ATELIER_SOCKET if set and
// non-empty, else /run/atelier/control.sock.
std::string default_socket_path();

// The daemon cannot be talked to: connect failed, the connection broke or closed, or no
// answer came in time. what() names the socket path and the cause.
class UnreachableError : public DeviceError {
 public:
  UnreachableError(const std::string& message, int error_number)
      : DeviceError(message), error_number_(error_number) {}
  // errno of the failing call, 0 when the cause was not a system call (EOF, timeout).
  int error_number() const { return error_number_; }

 private:
  int error_number_;
};

// The daemon answered something that is not a protocol message (not JSON, not an object,
// a line larger than kMaxLineBytes).
class ProtocolError : public InternalError {
 public:
  using InternalError::InternalError;
};

// Opens `path` for reading as a file to hand the daemon (O_RDONLY | O_CLOEXEC, not blocking on
// a FIFO) and checks that it is a regular file. Returns the descriptor (the caller closes it).
// Throws std::runtime_error naming the path and the problem.
int open_regular_file(const std::string& path);

class ControlClient {
 public:
  // How long request() waits for its answer unless told otherwise.
  static constexpr std::chrono::milliseconds kDefaultTimeout{30000};
  // Longest line accepted from the daemon (a long job list is a few MB at most).
  static constexpr std::size_t kMaxLineBytes = 64u << 20;

  // Connects at once; throws UnreachableError (with the path and errno text) on failure.
  explicit ControlClient(std::string socket_path);
  ~ControlClient();
  ControlClient(const ControlClient&) = delete;
  ControlClient& operator=(const ControlClient&) = delete;

  const std::string& socket_path() const { return path_; }

  // Sends {"verb": verb, "args": args} and returns the daemon's response object as is
  // ({"ok": true, "result": ...} or {"ok": false, "error": ...}); interpreting ok is the
  // caller's job. `files`: open descriptors passed with the request (SCM_RIGHTS), in order,
  // so the daemon reads them with our rights (the caller keeps and closes its own copies).
  // Throws UnreachableError or ProtocolError.
  nlohmann::json request(const std::string& verb, const nlohmann::json& args,
                         std::chrono::milliseconds timeout = kDefaultTimeout,
                         const std::vector<int>& files = {});

  // Writes one message as one line, `files` riding with its first byte. Throws
  // UnreachableError.
  void send(const nlohmann::json& message, const std::vector<int>& files = {});

  // Reads the next message. timeout nullopt waits forever (watch). Returns nullopt when the
  // daemon closed the connection cleanly between messages. Throws UnreachableError on a
  // timeout or I/O error and ProtocolError on a malformed line.
  std::optional<nlohmann::json> receive(std::optional<std::chrono::milliseconds> timeout);

 private:
  std::string path_;
  int fd_ = -1;
  std::string buffer_;  // bytes read past the last returned line
};

}  // namespace atelier::ctl

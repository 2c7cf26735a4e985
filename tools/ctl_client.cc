#include "tools/ctl_client.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace atelier::ctl {
namespace {

std::string errno_text(int error_number) { return std::strerror(error_number); }

}  // namespace

std::string default_socket_path() {
  const char* env = std::getenv("ATELIER_SOCKET");
  if (env != nullptr && *env != '\0') return env;
  return "/run/atelier/control.sock";
}

ControlClient::ControlClient(std::string socket_path) : path_(std::move(socket_path)) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (path_.empty() || path_.size() >= sizeof(address.sun_path)) {
    throw UnreachableError("cannot connect to " + path_ + ": " + errno_text(ENAMETOOLONG) +
                               " (a socket path has at most " +
                               std::to_string(sizeof(address.sun_path) - 1) + " bytes)",
                           ENAMETOOLONG);
  }
  std::memcpy(address.sun_path, path_.c_str(), path_.size() + 1);
  fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    int err = errno;
    throw UnreachableError("cannot create a socket for " + path_ + ": " + errno_text(err), err);
  }
  int rc;
  do {
    rc = ::connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof(address));
  } while (rc != 0 && errno == EINTR);
  if (rc != 0) {
    int err = errno;
    ::close(fd_);
    fd_ = -1;
    throw UnreachableError("cannot connect to " + path_ + ": " + errno_text(err), err);
  }
}

ControlClient::~ControlClient() {
  if (fd_ >= 0) ::close(fd_);
}

int open_regular_file(const std::string& path) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
  if (fd < 0) throw std::runtime_error(path + ": cannot open: " + errno_text(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw std::runtime_error(path + ": not a regular file");
  }
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  return fd;
}

void ControlClient::send(const nlohmann::json& message, const std::vector<int>& files) {
  std::string line = message.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  line.push_back('\n');
  std::size_t sent = 0;
  if (!files.empty()) {
    // The descriptors go with the line's first bytes: the daemon hands them to this request.
    std::vector<char> control(CMSG_SPACE(files.size() * sizeof(int)), 0);
    struct iovec iov = {line.data(), line.size()};
    struct msghdr msg {};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control.data();
    msg.msg_controllen = control.size();
    struct cmsghdr* c = CMSG_FIRSTHDR(&msg);
    c->cmsg_level = SOL_SOCKET;
    c->cmsg_type = SCM_RIGHTS;
    c->cmsg_len = CMSG_LEN(files.size() * sizeof(int));
    std::memcpy(CMSG_DATA(c), files.data(), files.size() * sizeof(int));
    ssize_t n;
    do {
      n = ::sendmsg(fd_, &msg, MSG_NOSIGNAL);
    } while (n < 0 && errno == EINTR);
    if (n < 0) {
      int err = errno;
      throw UnreachableError("cannot write to " + path_ + ": " + errno_text(err), err);
    }
    sent = static_cast<std::size_t>(n);
  }
  while (sent < line.size()) {
    // MSG_NOSIGNAL: a daemon that went away must give an error here, not kill us by SIGPIPE.
    ssize_t n = ::send(fd_, line.data() + sent, line.size() - sent, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      int err = errno;
      throw UnreachableError("cannot write to " + path_ + ": " + errno_text(err), err);
    }
    sent += static_cast<std::size_t>(n);
  }
}

std::optional<nlohmann::json> ControlClient::receive(
    std::optional<std::chrono::milliseconds> timeout) {
  using Clock = std::chrono::steady_clock;
  const auto deadline = timeout ? Clock::now() + *timeout : Clock::time_point::max();
  std::size_t scanned = 0;  // bytes of buffer_ already known to hold no newline
  for (;;) {
    std::size_t newline = buffer_.find('\n', scanned);
    if (newline != std::string::npos) {
      std::string line = buffer_.substr(0, newline);
      buffer_.erase(0, newline + 1);
      try {
        nlohmann::json message = nlohmann::json::parse(line);
        if (!message.is_object()) {
          throw ProtocolError("daemon at " + path_ + " sent a line that is not a JSON object");
        }
        return message;
      } catch (const nlohmann::json::parse_error& e) {
        throw ProtocolError("daemon at " + path_ + " sent a line that is not JSON: " +
                            e.what());
      }
    }
    scanned = buffer_.size();
    if (buffer_.size() > kMaxLineBytes) {
      throw ProtocolError("daemon at " + path_ + " sent a line longer than " +
                          std::to_string(kMaxLineBytes) + " bytes");
    }

    int wait_ms = -1;
    if (timeout) {
      auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
      if (left.count() <= 0) {
        throw UnreachableError("no answer from the daemon at " + path_ + " within " +
                                   std::to_string(timeout->count()) + " ms",
                               0);
      }
      wait_ms = static_cast<int>(std::min<long long>(left.count(), 1 << 30));
    }
    pollfd pfd{fd_, POLLIN, 0};
    int ready = ::poll(&pfd, 1, wait_ms);
    if (ready < 0) {
      if (errno == EINTR) continue;
      int err = errno;
      throw UnreachableError("cannot wait for " + path_ + ": " + errno_text(err), err);
    }
    if (ready == 0) continue;  // the deadline check above reports the timeout

    char chunk[65536];
    ssize_t n = ::read(fd_, chunk, sizeof(chunk));
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      int err = errno;
      throw UnreachableError("cannot read from " + path_ + ": " + errno_text(err), err);
    }
    if (n == 0) {
      if (buffer_.empty()) return std::nullopt;
      throw UnreachableError("the daemon at " + path_ + " closed the connection mid-message", 0);
    }
    buffer_.append(chunk, static_cast<std::size_t>(n));
  }
}

nlohmann::json ControlClient::request(const std::string& verb, const nlohmann::json& args,
                                      std::chrono::milliseconds timeout, const std::vector<int>& files) {
  send(nlohmann::json{{"verb", verb}, {"args", args}}, files);
  std::optional<nlohmann::json> response = receive(timeout);
  if (!response) {
    throw UnreachableError("the daemon at " + path_ + " closed the connection without answering",
                           0);
  }
  return *response;
}

}  // namespace atelier::ctl

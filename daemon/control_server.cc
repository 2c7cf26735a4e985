#include "daemon/control_server.h"

#include <grp.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "base/error.h"
#include "daemon/control_request.h"
#include "daemon/log.h"

namespace fs = std::filesystem;

namespace atelier {

ControlServer::ControlServer(fs::path socket_path, const std::string& group, Handler handler)
    : path_(std::move(socket_path)), handler_(std::move(handler)) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path_.string().size() >= sizeof addr.sun_path)
    throw InternalError(path_.string() + ": socket path too long");
  std::strcpy(addr.sun_path, path_.c_str());
  std::error_code ec;
  fs::create_directories(path_.parent_path(), ec);
  if (fs::is_socket(fs::symlink_status(path_, ec))) fs::remove(path_, ec);
  listen_fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (listen_fd_ < 0) throw InternalError(std::string("socket: ") + strerror(errno));
  if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
      ::listen(listen_fd_, 16) != 0) {
    std::string err = strerror(errno);
    ::close(listen_fd_);
    throw InternalError(path_.string() + ": cannot listen: " + err);
  }
  ::chmod(path_.c_str(), 0660);
  if (struct group* g = getgrnam(group.c_str())) {
    if (::chown(path_.c_str(), static_cast<uid_t>(-1), g->gr_gid) != 0)
      log::warning(path_.string() + ": cannot give the socket to group " + group + ": " +
                   strerror(errno));
  } else {
    log::debug(path_.string() + ": group " + group + " does not exist; socket keeps our group");
  }
  wake_fd_ = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
}

ControlServer::~ControlServer() {
  stop();
  if (listen_fd_ >= 0) ::close(listen_fd_);
  if (wake_fd_ >= 0) ::close(wake_fd_);
  std::error_code ec;
  fs::remove(path_, ec);
}

void ControlServer::start() { thread_ = std::thread([this] { loop(); }); }

void ControlServer::stop() {
  {
    std::lock_guard lock(mu_);
    stopping_ = true;
  }
  uint64_t one = 1;
  ssize_t ignored = ::write(wake_fd_, &one, sizeof one);
  (void)ignored;
  if (thread_.joinable()) thread_.join();
  for (auto& [fd, buf] : clients_) ::close(fd);
  clients_.clear();
  watchers_.clear();
}

void ControlServer::publish(const nlohmann::json& event) {
  {
    std::lock_guard lock(mu_);
    pending_.push_back(event);
  }
  uint64_t one = 1;
  ssize_t ignored = ::write(wake_fd_, &one, sizeof one);
  (void)ignored;
}

void ControlServer::send_line(int fd, const nlohmann::json& message) {
  // Lenient: a reason or file name from another system need not be valid UTF-8.
  std::string line = message.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  size_t off = 0;
  while (off < line.size()) {
    ssize_t n = ::send(fd, line.data() + off, line.size() - off, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      struct pollfd p = {fd, POLLOUT, 0};
      if (::poll(&p, 1, 1000) <= 0) return;  // a client that does not read loses the line
      continue;
    }
    if (n <= 0) return;
    off += static_cast<size_t>(n);
  }
}

void ControlServer::serve_line(int fd, const std::string& line) {
  ControlRequest request;
  try {
    request = parse_request(line);
  } catch (const ControlError& e) {
    send_line(fd, {{"ok", false}, {"error", e.what()}});
    return;
  }
  const std::string& verb = request.verb;
  const nlohmann::json& args = request.args;
  if (verb == "watch") {
    watchers_.insert(fd);
    send_line(fd, {{"ok", true}, {"result", "watching"}});
    return;
  }
  try {
    send_line(fd, {{"ok", true}, {"result", handler_(verb, args)}});
  } catch (const ControlError& e) {
    send_line(fd, {{"ok", false}, {"error", e.what()}});
  } catch (const nlohmann::json::exception& e) {
    send_line(fd, {{"ok", false}, {"error", std::string("bad arguments: ") + e.what()}});
  } catch (const std::exception& e) {
    send_line(fd, {{"ok", false}, {"error", e.what()}});
  }
}

void ControlServer::drop(int fd) {
  watchers_.erase(fd);
  ::close(fd);
}

void ControlServer::loop() {
  for (;;) {
    std::vector<struct pollfd> fds = {{listen_fd_, POLLIN, 0}, {wake_fd_, POLLIN, 0}};
    for (auto& [fd, buf] : clients_) fds.push_back({fd, POLLIN, 0});
    if (::poll(fds.data(), fds.size(), -1) < 0 && errno != EINTR) {
      log::error(std::string("control socket poll: ") + strerror(errno));
      return;
    }
    if (fds[1].revents & POLLIN) {
      uint64_t n;
      ssize_t ignored = ::read(wake_fd_, &n, sizeof n);
      (void)ignored;
      std::vector<nlohmann::json> events;
      {
        std::lock_guard lock(mu_);
        if (stopping_) return;
        events.swap(pending_);
      }
      for (const auto& ev : events)
        for (int w : watchers_) send_line(w, {{"event", ev}});
    }
    if (fds[0].revents & POLLIN) {
      int c = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
      if (c >= 0) clients_.emplace_back(c, std::string());
    }
    std::vector<int> closed;
    for (size_t i = 2; i < fds.size(); ++i) {
      if (!(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      int fd = fds[i].fd;
      auto it = std::find_if(clients_.begin(), clients_.end(),
                             [fd](const auto& c) { return c.first == fd; });
      char buf[8192];
      ssize_t n = ::read(fd, buf, sizeof buf);
      if (n <= 0) {
        closed.push_back(fd);
        continue;
      }
      it->second.append(buf, static_cast<size_t>(n));
      if (it->second.size() > (1u << 20)) {  // no request is a megabyte long
        closed.push_back(fd);
        continue;
      }
      size_t nl;
      while ((nl = it->second.find('\n')) != std::string::npos) {
        std::string line = it->second.substr(0, nl);
        it->second.erase(0, nl + 1);
        if (!line.empty()) serve_line(fd, line);
      }
    }
    for (int fd : closed) {
      drop(fd);
      clients_.erase(std::remove_if(clients_.begin(), clients_.end(),
                                    [fd](const auto& c) { return c.first == fd; }),
                     clients_.end());
    }
  }
}

}  // namespace atelier

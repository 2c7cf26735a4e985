#include "daemon/control_server.h"

#include <grp.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "base/error.h"
#include "daemon/control_request.h"
#include "daemon/log.h"

namespace fs = std::filesystem;

namespace atelier {
namespace {

constexpr size_t kMaxRequestBytes = 1u << 20;  // no request is a megabyte long

void wake(int fd) {
  uint64_t one = 1;
  ssize_t ignored = ::write(fd, &one, sizeof one);
  (void)ignored;
}

std::string json_line(const nlohmann::json& message) {
  // Lenient: a reason or file name from another system need not be valid UTF-8.
  return message.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

// A last word to a connection about to be closed: never waits for a client that does not read.
void send_farewell(int fd, const std::string& error) {
  const std::string line = json_line({{"ok", false}, {"error", error}});
  ssize_t ignored = ::send(fd, line.data(), line.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  (void)ignored;
}

bool out_of_descriptors(int err) {
  return err == EMFILE || err == ENFILE || err == ENOBUFS || err == ENOMEM;
}

}  // namespace

ControlServer::ControlServer(fs::path socket_path, const std::string& group, Handler handler,
                             ControlLimits limits, Clock& clock)
    : path_(std::move(socket_path)), handler_(std::move(handler)), limits_(limits), clock_(clock) {
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
      ::listen(listen_fd_, 64) != 0) {
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

void ControlServer::start() {
  {
    std::lock_guard lock(timer_mu_);
    timer_stop_ = false;
  }
  timer_thread_ = std::thread([this] { timer_loop(); });
  thread_ = std::thread([this] { loop(); });
}

void ControlServer::stop() {
  {
    std::lock_guard lock(mu_);
    stopping_ = true;
  }
  wake(wake_fd_);
  if (thread_.joinable()) thread_.join();
  {
    std::lock_guard lock(timer_mu_);
    timer_stop_ = true;
  }
  timer_cv_.notify_all();
  if (timer_thread_.joinable()) timer_thread_.join();
  clients_.clear();
}

void ControlServer::publish(const nlohmann::json& event) {
  {
    std::lock_guard lock(mu_);
    pending_.push_back(event);
  }
  wake(wake_fd_);
}

void ControlServer::timer_loop() {
  std::unique_lock lock(timer_mu_);
  while (!timer_stop_) {
    const Clock::time_point deadline = next_deadline_;
    const bool changed = clock_.wait_until(timer_cv_, lock, deadline, [&] {
      return timer_stop_ || next_deadline_ != deadline;
    });
    if (timer_stop_) return;
    if (!changed) {
      // The deadline passed: the loop looks at the clock and arms the next one.
      next_deadline_ = Clock::time_point::max();
      wake(wake_fd_);
    }
  }
}

void ControlServer::arm_timer() {
  Clock::time_point next = Clock::time_point::max();
  if (listen_paused_until_ > clock_.now()) next = listen_paused_until_;
  for (const Client& c : clients_)
    if (!c.watching && !c.closing) next = std::min(next, c.last_request + limits_.idle_timeout);
  {
    std::lock_guard lock(timer_mu_);
    if (next == next_deadline_) return;
    next_deadline_ = next;
  }
  timer_cv_.notify_all();
}

void ControlServer::send_line(int fd, const nlohmann::json& message) {
  const std::string line = json_line(message);
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

void ControlServer::serve_line(Client& client, const std::string& line, std::vector<UniqueFd> files) {
  const int fd = client.fd.get();
  ControlRequest request;
  request.peer = client.peer;
  request.files = std::move(files);
  ParsedRequest parsed;
  try {
    parsed = parse_request(line);
  } catch (const ControlError& e) {
    send_line(fd, {{"ok", false}, {"error", e.what()}});
    return;
  }
  if (request.files.size() > limits_.max_files) {
    send_line(fd, {{"ok", false},
                   {"error", "a request may pass at most " + std::to_string(limits_.max_files) +
                                 " open files"}});
    return;
  }
  request.verb = std::move(parsed.verb);
  request.args = std::move(parsed.args);
  if (request.verb == "watch") {
    client.watching = true;
    send_line(fd, {{"ok", true}, {"result", "watching"}});
    return;
  }
  try {
    send_line(fd, {{"ok", true}, {"result", handler_(request)}});
  } catch (const ControlError& e) {
    send_line(fd, {{"ok", false}, {"error", e.what()}});
  } catch (const nlohmann::json::exception& e) {
    send_line(fd, {{"ok", false}, {"error", std::string("bad arguments: ") + e.what()}});
  } catch (const std::exception& e) {
    send_line(fd, {{"ok", false}, {"error", e.what()}});
  }
}

void ControlServer::accept_clients() {
  for (int round = 0; round < 64; ++round) {  // then poll again: clients also want serving
    int c = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
    if (c < 0) {
      if (errno == EINTR || errno == ECONNABORTED) continue;
      if (out_of_descriptors(errno)) {
        // The connection stays in the backlog: leave the listening socket out of poll() for a
        // while instead of finding it readable again at once, forever.
        if (!backoff_logged_)
          log::warning(path_.string() + ": cannot accept a connection: " + strerror(errno) +
                       "; pausing new connections for " +
                       std::to_string(limits_.accept_backoff.count()) + " ms at a time");
        backoff_logged_ = true;
        listen_paused_until_ = clock_.now() + limits_.accept_backoff;
      }
      return;  // EAGAIN: nothing more waiting
    }
    backoff_logged_ = false;
    Client client;
    client.fd = UniqueFd(c);
    struct ucred cred {};
    socklen_t len = sizeof cred;
    if (::getsockopt(c, SOL_SOCKET, SO_PEERCRED, &cred, &len) == 0) {
      client.peer = {cred.pid, cred.uid, cred.gid};
    }
    // A client found closed in this same wake-up no longer holds a place.
    const size_t same_uid = static_cast<size_t>(std::count_if(clients_.begin(), clients_.end(), [&](const Client& o) {
      return !o.closing && o.peer.uid == client.peer.uid;
    }));
    const size_t open_clients = static_cast<size_t>(
        std::count_if(clients_.begin(), clients_.end(), [](const Client& o) { return !o.closing; }));
    if (same_uid >= limits_.per_uid) {
      send_farewell(c, "too many connections from uid " + std::to_string(client.peer.uid) + " (at most " +
                           std::to_string(limits_.per_uid) + "); close some and try again");
      continue;
    }
    if (open_clients >= limits_.total) {
      send_farewell(c, "atelierd has too many connections (at most " + std::to_string(limits_.total) +
                           "); try again later");
      continue;
    }
    client.last_request = clock_.now();
    clients_.push_back(std::move(client));
  }
}

bool ControlServer::read_client(Client& client) {
  char buf[8192];
  alignas(struct cmsghdr) char control[CMSG_SPACE(8 * sizeof(int))];
  struct iovec iov = {buf, sizeof buf};
  struct msghdr msg {};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control;
  msg.msg_controllen = sizeof control;
  ssize_t n;
  do {
    n = ::recvmsg(client.fd.get(), &msg, MSG_CMSG_CLOEXEC);
  } while (n < 0 && errno == EINTR);
  if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return true;
  // Descriptors come with the first byte of the line they belong to.
  for (struct cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level != SOL_SOCKET || c->cmsg_type != SCM_RIGHTS) continue;
    const size_t count = (c->cmsg_len - CMSG_LEN(0)) / sizeof(int);
    for (size_t i = 0; i < count; ++i) {
      int fd;
      std::memcpy(&fd, CMSG_DATA(c) + i * sizeof(int), sizeof fd);
      client.files.emplace_back(client.received, UniqueFd(fd));
    }
  }
  if (n <= 0) return false;
  if (msg.msg_flags & MSG_CTRUNC) {
    send_farewell(client.fd.get(), "a request may pass at most " + std::to_string(limits_.max_files) +
                                       " open files");
    return false;
  }
  client.received += static_cast<uint64_t>(n);
  client.buffer.append(buf, static_cast<size_t>(n));
  size_t nl;
  while ((nl = client.buffer.find('\n')) != std::string::npos) {
    const uint64_t line_start = client.received - client.buffer.size();
    const uint64_t line_end = line_start + nl;
    std::string line = client.buffer.substr(0, nl);
    client.buffer.erase(0, nl + 1);
    std::vector<UniqueFd> files;
    auto it = client.files.begin();
    for (; it != client.files.end() && it->first <= line_end; ++it) files.push_back(std::move(it->second));
    client.files.erase(client.files.begin(), it);
    if (line.empty()) continue;
    client.last_request = clock_.now();  // a complete request: the idle time starts again
    serve_line(client, line, std::move(files));
  }
  if (client.buffer.size() > kMaxRequestBytes) {
    send_farewell(client.fd.get(), "request longer than " + std::to_string(kMaxRequestBytes) + " bytes");
    return false;
  }
  if (client.files.size() > limits_.max_files) {
    send_farewell(client.fd.get(), "a request may pass at most " + std::to_string(limits_.max_files) +
                                       " open files");
    return false;
  }
  return true;
}

void ControlServer::expire_idle() {
  const Clock::time_point now = clock_.now();
  for (Client& c : clients_) {
    if (c.watching || c.closing || now < c.last_request + limits_.idle_timeout) continue;
    send_farewell(c.fd.get(), "closed: no request within " +
                                  std::to_string(limits_.idle_timeout.count() / 1000) + " s");
    c.closing = true;
  }
}

void ControlServer::loop() {
  std::vector<struct pollfd> fds;
  std::vector<Client*> polled;
  for (;;) {
    clients_.remove_if([](const Client& c) { return c.closing; });
    arm_timer();
    const bool listening = clock_.now() >= listen_paused_until_;
    fds.assign({{wake_fd_, POLLIN, 0}, {listening ? listen_fd_ : -1, POLLIN, 0}});
    polled.clear();
    for (Client& c : clients_) {
      fds.push_back({c.fd.get(), POLLIN, 0});
      polled.push_back(&c);
    }
    if (::poll(fds.data(), fds.size(), -1) < 0) {
      if (errno == EINTR) continue;
      log::error(std::string("control socket poll: ") + strerror(errno));
      return;
    }
    wakeups_.fetch_add(1);
    if (fds[0].revents & POLLIN) {
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
        for (Client& c : clients_)
          if (c.watching && !c.closing) send_line(c.fd.get(), {{"event", ev}});
    }
    for (size_t i = 2; i < fds.size(); ++i) {
      if (!(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      if (!read_client(*polled[i - 2])) polled[i - 2]->closing = true;
    }
    if (fds[1].revents & POLLIN) accept_clients();
    expire_idle();
  }
}

}  // namespace atelier

// The control socket: a Unix stream socket speaking JSON lines (docs/control-protocol.md).
// Requests are dispatched to a handler; `watch` clients get every published event.
//
// Whose rights: each connection carries its peer's credentials (SO_PEERCRED at accept), and a
// request may carry open file descriptors (SCM_RIGHTS, sent with the request line's bytes), so
// the handler can read a file with the rights of the client that opened it instead of its own.
//
// Floods: at most ControlLimits::per_uid connections per peer uid and ControlLimits::total in
// all; an extra one gets one error line and is closed at once. A connection that completes no
// request for ControlLimits::idle_timeout is told so and closed (watchers are exempt). When
// accept() fails for want of descriptors (EMFILE, ENFILE, ...) the listening socket is left
// out of poll() for ControlLimits::accept_backoff, so the loop never spins on it.
//
// Time: the idle timeout and the accept backoff are measured on the Clock given (a helper
// thread waits on it and wakes the loop), so tests move a FakeClock instead of sleeping.
// Threading: the server runs its own thread (start/stop) and a timer thread. The handler is
// called on the server thread, one request at a time. publish() may be called from any thread.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <list>
#include <mutex>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "base/clock.h"
#include "base/error.h"
#include "base/unique_fd.h"

namespace atelier {

// A request that cannot be served; its message goes back to the client as {"ok": false}.
class ControlError : public BadInput {
 public:
  using BadInput::BadInput;
};

// Who is at the other end of a connection (SO_PEERCRED, taken when it connected).
struct PeerCredentials {
  pid_t pid = 0;
  uid_t uid = static_cast<uid_t>(-1);
  gid_t gid = static_cast<gid_t>(-1);
};

// One request line as the handler gets it.
struct ControlRequest {
  std::string verb;
  nlohmann::json args = nlohmann::json::object();
  PeerCredentials peer;
  // Descriptors the client passed with this line (SCM_RIGHTS), in the order it sent them; owned
  // by the request (closed with it unless the handler takes them).
  std::vector<UniqueFd> files;
  // Who asked, for the job's history, when not a control-socket client: set by the web server
  // ("the web page by alice from 192.168.1.7"); "" for the control socket.
  std::string via;
};

struct ControlLimits {
  size_t per_uid = 32;                         // connections open at once from one uid
  size_t total = 256;                          // connections open at once, all uids together
  std::chrono::milliseconds idle_timeout{60000};  // without a complete request (not watchers)
  std::chrono::milliseconds accept_backoff{100};  // listening paused after EMFILE and the like
  size_t max_files = 4;                        // descriptors one request line may carry
};

class ControlServer {
 public:
  using Handler = std::function<nlohmann::json(ControlRequest& request)>;

  // Binds `socket_path` (a stale socket file is replaced), mode 0660, group `group` when it
  // exists. `clock` (borrowed; must outlive the server) measures the idle timeout and backoff.
  // Throws InternalError naming the path on failure.
  ControlServer(std::filesystem::path socket_path, const std::string& group, Handler handler,
                ControlLimits limits = {}, Clock& clock = real_clock());
  ~ControlServer();

  void start();
  void stop();
  void publish(const nlohmann::json& event);

  // How often the server loop has woken up so far (for tests: an idle or flooded server must
  // not spin).
  uint64_t wakeups() const { return wakeups_.load(); }

 private:
  struct Client {
    UniqueFd fd;
    PeerCredentials peer;
    std::string buffer;   // bytes received past the last complete line
    uint64_t received = 0;  // bytes received so far on this connection
    // Descriptors received, each with the stream offset of the bytes it came with.
    std::vector<std::pair<uint64_t, UniqueFd>> files;
    Clock::time_point last_request;
    bool watching = false;
    bool closing = false;
  };

  void loop();
  void timer_loop();
  void accept_clients();
  // Reads what is there; false when the connection is to be closed.
  bool read_client(Client& client);
  void serve_line(Client& client, const std::string& line, std::vector<UniqueFd> files);
  void send_line(int fd, const nlohmann::json& message);
  void expire_idle();
  void arm_timer();  // tells the timer thread the next deadline

  std::filesystem::path path_;
  Handler handler_;
  ControlLimits limits_;
  Clock& clock_;
  int listen_fd_ = -1;
  int wake_fd_ = -1;  // eventfd: stop requested, events to deliver or a deadline passed
  std::thread thread_;
  std::thread timer_thread_;
  std::mutex mu_;
  std::vector<nlohmann::json> pending_;
  bool stopping_ = false;
  std::list<Client> clients_;  // server thread only
  Clock::time_point listen_paused_until_{};
  bool backoff_logged_ = false;
  std::atomic<uint64_t> wakeups_{0};

  std::mutex timer_mu_;
  std::condition_variable_any timer_cv_;
  Clock::time_point next_deadline_ = Clock::time_point::max();
  bool timer_stop_ = false;
};

}  // namespace atelier

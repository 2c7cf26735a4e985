// Who may act through the web server (docs/web.md "Who may do what"): the bearer token of
// `[web] token`, or a page login (a session cookie plus its CSRF token in a header). Reading
// needs neither. Pure apart from the clock and the random tokens.
//
// Threading: SessionTable and LoginThrottle lock internally; any thread may call them.
// Time: both measure on the Clock given (borrowed; must outlive them), so tests move a
// FakeClock.
#pragma once

#include <chrono>
#include <cstddef>
#include <map>
#include <mutex>
#include <optional>
#include <string>

#include "base/clock.h"
#include "daemon/config.h"

namespace atelier::web {

inline constexpr const char* kSessionCookie = "atelier_session";
inline constexpr const char* kCsrfHeader = "X-Atelier-CSRF";

struct Session {
  std::string id;    // the cookie's value (random, 256 bits)
  std::string user;  // a [web.users] name, or "token" for a login with the bearer token
  std::string csrf;  // must come back in the X-Atelier-CSRF header of every action
  Clock::time_point expires;
};

class SessionTable {
 public:
  explicit SessionTable(Clock& clock = real_clock(), size_t max_sessions = 1000);
  // A new session for `user`, valid for `lifetime`. At `max_sessions` the one nearest to
  // expiry is dropped first.
  Session create(const std::string& user, std::chrono::seconds lifetime);
  // The session with this cookie value, unless unknown or expired (then it is forgotten).
  std::optional<Session> find(const std::string& id);
  void remove(const std::string& id);

 private:
  Clock& clock_;
  size_t max_;
  std::mutex mu_;
  std::map<std::string, Session> sessions_;
};

// Refuses logins from an address after `max_failures` failures within `window`, for
// `lockout` after the last one: a password cannot be guessed at the speed of the network.
class LoginThrottle {
 public:
  explicit LoginThrottle(Clock& clock = real_clock(), int max_failures = 5,
                         std::chrono::seconds window = std::chrono::seconds(60),
                         std::chrono::seconds lockout = std::chrono::seconds(60));
  bool blocked(const std::string& address);
  void failed(const std::string& address);
  void succeeded(const std::string& address);

 private:
  struct Record {
    int failures = 0;
    Clock::time_point first, last;
  };
  Clock& clock_;
  int max_failures_;
  std::chrono::seconds window_, lockout_;
  std::mutex mu_;
  std::map<std::string, Record> records_;
};

// What one request brings to be judged (header values as received; "" when absent).
struct ActionRequest {
  std::string authorization;   // Authorization
  std::string cookie;          // Cookie
  std::string csrf;            // X-Atelier-CSRF
  std::string origin;          // Origin
  std::string host;            // Host
  std::string sec_fetch_site;  // Sec-Fetch-Site
};

struct Verdict {
  enum class Outcome { allowed, unauthorised, forbidden } outcome = Outcome::unauthorised;
  std::string user;     // who acts, when allowed ("token" for the bearer token)
  std::string message;  // why not, for the client
};

// Whether the request may act. A correct bearer token is enough (browsers never send one on
// their own). Otherwise it needs a live session cookie, the session's CSRF token in the
// header, and no sign of coming from another site (Origin not this Host, Sec-Fetch-Site
// cross-site).
Verdict judge_action(const ActionRequest& request, const WebConfig& config, SessionTable& sessions);

// Whether a session's login still stands under the configuration as now loaded: its user is
// still in [web.users] (or, for a token login, a token is still set). A SIGHUP that removes a
// user or the token ends their sessions.
bool still_allowed(const Session& session, const WebConfig& config);

// Whether a request that comes from a page of another site (Origin not this Host, or
// Sec-Fetch-Site "cross-site"): logins refuse those too, so no other site can log a browser in.
bool is_cross_site(const ActionRequest& request);

// The value of cookie `name` in a Cookie header, or "".
std::string cookie_value(const std::string& header, const std::string& name);

// The user whose password this is, if [web.users] has `user` and the password matches.
bool user_password_ok(const WebConfig& config, const std::string& user, const std::string& password);
// Whether `token` is the configured bearer token (never true when none is configured).
bool token_ok(const WebConfig& config, const std::string& token);

}  // namespace atelier::web

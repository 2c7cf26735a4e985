#include "daemon/web/web_auth.h"

#include <algorithm>

#include "daemon/web/password.h"
#include "daemon/web/secret.h"

namespace atelier::web {

SessionTable::SessionTable(Clock& clock, size_t max_sessions) : clock_(clock), max_(max_sessions) {}

Session SessionTable::create(const std::string& user, std::chrono::seconds lifetime) {
  Session s{random_token(), user, random_token(), clock_.deadline_after(lifetime)};
  std::lock_guard lock(mu_);
  const auto now = clock_.now();
  for (auto it = sessions_.begin(); it != sessions_.end();)
    it = it->second.expires <= now ? sessions_.erase(it) : std::next(it);
  if (sessions_.size() >= max_) {
    auto soonest = std::min_element(sessions_.begin(), sessions_.end(), [](const auto& a, const auto& b) {
      return a.second.expires < b.second.expires;
    });
    sessions_.erase(soonest);
  }
  sessions_[s.id] = s;
  return s;
}

std::optional<Session> SessionTable::find(const std::string& id) {
  if (id.empty()) return std::nullopt;
  std::lock_guard lock(mu_);
  auto it = sessions_.find(id);
  if (it == sessions_.end()) return std::nullopt;
  if (it->second.expires <= clock_.now()) {
    sessions_.erase(it);
    return std::nullopt;
  }
  return it->second;
}

void SessionTable::remove(const std::string& id) {
  std::lock_guard lock(mu_);
  sessions_.erase(id);
}

LoginThrottle::LoginThrottle(Clock& clock, int max_failures, std::chrono::seconds window,
                             std::chrono::seconds lockout)
    : clock_(clock), max_failures_(max_failures), window_(window), lockout_(lockout) {}

bool LoginThrottle::blocked(const std::string& address) {
  std::lock_guard lock(mu_);
  auto it = records_.find(address);
  if (it == records_.end()) return false;
  const auto now = clock_.now();
  if (it->second.failures >= max_failures_) {
    if (now < it->second.last + lockout_) return true;
    records_.erase(it);  // served its time
  }
  return false;
}

void LoginThrottle::failed(const std::string& address) {
  std::lock_guard lock(mu_);
  const auto now = clock_.now();
  Record& r = records_[address];
  if (r.failures == 0 || now - r.first > window_) r = Record{0, now, now};
  ++r.failures;
  r.last = now;
  // Forget quiet addresses, so the table stays small under a scan of many addresses.
  if (records_.size() > 10000)
    for (auto it = records_.begin(); it != records_.end();)
      it = now - it->second.last > window_ + lockout_ ? records_.erase(it) : std::next(it);
}

void LoginThrottle::succeeded(const std::string& address) {
  std::lock_guard lock(mu_);
  records_.erase(address);
}

std::string cookie_value(const std::string& header, const std::string& name) {
  size_t pos = 0;
  while (pos < header.size()) {
    size_t end = header.find(';', pos);
    if (end == std::string::npos) end = header.size();
    std::string part = header.substr(pos, end - pos);
    const auto first = part.find_first_not_of(' ');
    part = first == std::string::npos ? "" : part.substr(first);
    const auto eq = part.find('=');
    if (eq != std::string::npos && part.compare(0, eq, name) == 0 && eq == name.size())
      return part.substr(eq + 1);
    pos = end + 1;
  }
  return "";
}

bool is_cross_site(const ActionRequest& r) {
  if (r.sec_fetch_site == "cross-site") return true;
  if (r.origin.empty()) return false;  // curl, scripts, older browsers on same-origin GETs
  // The page is served plainly or behind a TLS proxy: either scheme, but this very host.
  return r.origin != "http://" + r.host && r.origin != "https://" + r.host;
}

bool token_ok(const WebConfig& config, const std::string& token) {
  return !config.token.empty() && equal_in_constant_time(token, config.token);
}

bool user_password_ok(const WebConfig& config, const std::string& user, const std::string& password) {
  auto it = config.users.find(user);
  if (it == config.users.end()) {
    // The same work for an unknown user, so response times do not tell which names exist.
    static const std::string dummy = hash_password(random_token(16));
    password_matches(password, dummy);
    return false;
  }
  return password_matches(password, it->second);
}

bool still_allowed(const Session& session, const WebConfig& config) {
  return session.user == "token" ? !config.token.empty() : config.users.count(session.user) > 0;
}

Verdict judge_action(const ActionRequest& r, const WebConfig& config, SessionTable& sessions) {
  using O = Verdict::Outcome;
  static const std::string kBearer = "Bearer ";
  if (r.authorization.compare(0, kBearer.size(), kBearer) == 0) {
    if (token_ok(config, r.authorization.substr(kBearer.size()))) return {O::allowed, "token", ""};
    return {O::unauthorised, "", "the bearer token is not the one in [web] token"};
  }
  if (!config.can_act())
    return {O::forbidden, "", "this page is read-only: atelierd.toml has no [web] token and no [web.users]"};
  auto session = sessions.find(cookie_value(r.cookie, kSessionCookie));
  if (!session || !still_allowed(*session, config))
    return {O::unauthorised, "", "log in to act (or send Authorization: Bearer TOKEN)"};
  if (is_cross_site(r)) return {O::forbidden, "", "refused: the request comes from another site (Origin " + r.origin + ")"};
  if (r.csrf.empty() || !equal_in_constant_time(r.csrf, session->csrf))
    return {O::forbidden, "", std::string("refused: missing or wrong ") + kCsrfHeader + " header (cross-site request?)"};
  return {O::allowed, session->user, ""};
}

}  // namespace atelier::web

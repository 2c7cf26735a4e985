// Who may act through the web page: the token, a login with its CSRF token, nobody else; and
// password guessing is slowed to a crawl.
#include "daemon/web/web_auth.h"

#include <gtest/gtest.h>

#include "base/fake_clock.h"
#include "daemon/web/password.h"
#include "daemon/web/secret.h"

namespace atelier::web {
namespace {

using namespace std::chrono_literals;
using O = Verdict::Outcome;

WebConfig config_with_login() {
  WebConfig w;
  w.token = "0123456789abcdef0123";
  w.users["alice"] = hash_password("correct horse");
  return w;
}

TEST(Password, HashMatchesOnlyItsPassword) {
  const std::string h = hash_password("correct horse");
  EXPECT_EQ(h.rfind("$y$", 0), 0u) << h;
  EXPECT_TRUE(password_matches("correct horse", h));
  EXPECT_FALSE(password_matches("correct horsE", h));
  EXPECT_FALSE(password_matches("", h));
  EXPECT_NE(hash_password("correct horse"), h);  // a fresh salt each time
  EXPECT_FALSE(password_matches("x", "not a hash"));
  EXPECT_FALSE(password_matches("x", ""));
}

TEST(Password, ReadsShadowStyleSha512Hashes) {
  // `openssl passwd -6 -salt saltsalt secret`
  EXPECT_TRUE(password_matches("secret", "$6$saltsalt$TVLlQcbpFVof5W3Yz4DTP6gRstiNuHwwTt6GLc1E5n0U0aDehy0S5knV8wiOQSpT0Y77vwPZN.Pq.H91p5hVO1"));
}

TEST(Secret, TokensAreLongRandomHex) {
  const std::string a = random_token(), b = random_token();
  EXPECT_EQ(a.size(), 64u);
  EXPECT_NE(a, b);
  EXPECT_EQ(a.find_first_not_of("0123456789abcdef"), std::string::npos);
  EXPECT_TRUE(equal_in_constant_time(a, a));
  EXPECT_FALSE(equal_in_constant_time(a, b));
  EXPECT_FALSE(equal_in_constant_time("abc", "abcd"));
}

TEST(Cookies, FindsTheNamedCookieAmongOthers) {
  EXPECT_EQ(cookie_value("a=1; atelier_session=xyz; b=2", "atelier_session"), "xyz");
  EXPECT_EQ(cookie_value("atelier_session=xyz", "atelier_session"), "xyz");
  EXPECT_EQ(cookie_value("my_atelier_session=evil", "atelier_session"), "");
  EXPECT_EQ(cookie_value("", "atelier_session"), "");
}

TEST(SessionTable, SessionsExpire) {
  FakeClock clock;
  SessionTable t(clock);
  const Session s = t.create("alice", std::chrono::hours(12));
  EXPECT_NE(s.id, s.csrf);
  ASSERT_TRUE(t.find(s.id));
  EXPECT_EQ(t.find(s.id)->user, "alice");
  clock.advance(std::chrono::hours(11));
  EXPECT_TRUE(t.find(s.id));
  clock.advance(std::chrono::hours(2));
  EXPECT_FALSE(t.find(s.id));
  EXPECT_FALSE(t.find(""));
}

TEST(SessionTable, RemoveLogsOutAndTheTableStaysBounded) {
  FakeClock clock;
  SessionTable t(clock, 3);
  const Session first = t.create("a", 1h);
  clock.advance(1s);
  std::vector<Session> later;
  for (int i = 0; i < 3; ++i) later.push_back(t.create("b", 1h));
  EXPECT_FALSE(t.find(first.id));  // the one nearest its end made room
  for (const auto& s : later) EXPECT_TRUE(t.find(s.id));
  t.remove(later[0].id);
  EXPECT_FALSE(t.find(later[0].id));
}

TEST(LoginThrottle, FiveFailuresInAMinuteBlockForAMinute) {
  FakeClock clock;
  LoginThrottle t(clock);
  for (int i = 0; i < 4; ++i) t.failed("10.0.0.5");
  EXPECT_FALSE(t.blocked("10.0.0.5"));
  t.failed("10.0.0.5");
  EXPECT_TRUE(t.blocked("10.0.0.5"));
  EXPECT_FALSE(t.blocked("10.0.0.6"));  // another address is not punished
  clock.advance(59s);
  EXPECT_TRUE(t.blocked("10.0.0.5"));
  clock.advance(2s);
  EXPECT_FALSE(t.blocked("10.0.0.5"));
}

TEST(LoginThrottle, SlowFailuresAndASuccessDoNotBlock) {
  FakeClock clock;
  LoginThrottle t(clock);
  for (int i = 0; i < 10; ++i) {
    t.failed("10.0.0.5");
    clock.advance(20s);  // 3 a minute at most
    if (i % 3 == 2) clock.advance(30s);
  }
  EXPECT_FALSE(t.blocked("10.0.0.5"));
  for (int i = 0; i < 4; ++i) t.failed("10.0.0.7");
  t.succeeded("10.0.0.7");
  t.failed("10.0.0.7");
  EXPECT_FALSE(t.blocked("10.0.0.7"));
}

ActionRequest from_page(const Session& s) {
  ActionRequest r;
  r.cookie = std::string(kSessionCookie) + "=" + s.id;
  r.csrf = s.csrf;
  r.origin = "http://box.local:8631";
  r.host = "box.local:8631";
  r.sec_fetch_site = "same-origin";
  return r;
}

TEST(JudgeAction, BearerTokenIsEnoughAndAWrongOneIsUnauthorised) {
  FakeClock clock;
  SessionTable sessions(clock);
  const WebConfig w = config_with_login();
  ActionRequest r;
  r.authorization = "Bearer " + w.token;
  EXPECT_EQ(judge_action(r, w, sessions).outcome, O::allowed);
  EXPECT_EQ(judge_action(r, w, sessions).user, "token");
  r.authorization = "Bearer " + w.token + "x";
  EXPECT_EQ(judge_action(r, w, sessions).outcome, O::unauthorised);
  WebConfig no_token = w;
  no_token.token.clear();
  r.authorization = "Bearer ";
  EXPECT_EQ(judge_action(r, no_token, sessions).outcome, O::unauthorised);
}

TEST(JudgeAction, NoCredentialsIsUnauthorised) {
  FakeClock clock;
  SessionTable sessions(clock);
  const Verdict v = judge_action({}, config_with_login(), sessions);
  EXPECT_EQ(v.outcome, O::unauthorised);
  EXPECT_NE(v.message.find("log in"), std::string::npos);
}

TEST(JudgeAction, ALoggedInPageActsWithItsCsrfToken) {
  FakeClock clock;
  SessionTable sessions(clock);
  const WebConfig w = config_with_login();
  const Session s = sessions.create("alice", 1h);
  const Verdict v = judge_action(from_page(s), w, sessions);
  EXPECT_EQ(v.outcome, O::allowed);
  EXPECT_EQ(v.user, "alice");
}

TEST(JudgeAction, CrossSiteRequestsAreForbiddenEvenWithTheCookie) {
  FakeClock clock;
  SessionTable sessions(clock);
  const WebConfig w = config_with_login();
  const Session s = sessions.create("alice", 1h);
  ActionRequest r = from_page(s);
  r.csrf.clear();  // a form on another site cannot set the header
  EXPECT_EQ(judge_action(r, w, sessions).outcome, O::forbidden);
  r = from_page(s);
  r.csrf = sessions.create("mallory", 1h).csrf;  // another session's token
  EXPECT_EQ(judge_action(r, w, sessions).outcome, O::forbidden);
  r = from_page(s);
  r.origin = "http://evil.example";
  EXPECT_EQ(judge_action(r, w, sessions).outcome, O::forbidden);
  r = from_page(s);
  r.sec_fetch_site = "cross-site";
  EXPECT_EQ(judge_action(r, w, sessions).outcome, O::forbidden);
  r = from_page(s);
  r.origin = "https://box.local:8631";  // behind a TLS proxy: the same host
  EXPECT_EQ(judge_action(r, w, sessions).outcome, O::allowed);
}

TEST(JudgeAction, AnExpiredSessionMustLogInAgain) {
  FakeClock clock;
  SessionTable sessions(clock);
  const Session s = sessions.create("alice", 1h);
  clock.advance(2h);
  EXPECT_EQ(judge_action(from_page(s), config_with_login(), sessions).outcome, O::unauthorised);
}

TEST(JudgeAction, WithoutTokenOrUsersThePageIsReadOnly) {
  FakeClock clock;
  SessionTable sessions(clock);
  const Session s = sessions.create("alice", 1h);
  const Verdict v = judge_action(from_page(s), WebConfig{}, sessions);
  EXPECT_EQ(v.outcome, O::forbidden);
  EXPECT_NE(v.message.find("read-only"), std::string::npos);
}

TEST(UserPassword, OnlyAConfiguredUserWithItsPassword) {
  const WebConfig w = config_with_login();
  EXPECT_TRUE(user_password_ok(w, "alice", "correct horse"));
  EXPECT_FALSE(user_password_ok(w, "alice", "wrong"));
  EXPECT_FALSE(user_password_ok(w, "bob", "correct horse"));
  EXPECT_TRUE(token_ok(w, w.token));
  EXPECT_FALSE(token_ok(WebConfig{}, ""));
}

}  // namespace
}  // namespace atelier::web

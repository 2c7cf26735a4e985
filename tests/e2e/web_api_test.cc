// The web page's JSON API against the real daemon (docs/web.md): reading is open, acting
// needs the token or a login with its CSRF token, files come only from the job's own output
// folder, uploads keep to the hot folder's limit, and no browser can hold up the daemon.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <fstream>
#include <thread>

#include "tests/e2e/web_rig.h"

namespace atelier::test {
namespace {

using namespace std::chrono_literals;
using json = nlohmann::json;
namespace fs = std::filesystem;

std::string image_bytes(const std::string& name) { return read_file(test_image(name)); }

json body(const httplib::Result& r) { return r ? json::parse(r->body, nullptr, false) : json(); }

// A plain TCP connection to the web server, for requests no HTTP client would send.
int connect_tcp(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (fd < 0 || ::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0)
    throw std::runtime_error("cannot connect to port " + std::to_string(port));
  return fd;
}

// A finished knit job of pic1.png, submitted with the token.
int64_t converted_job(WebRig& rig) {
  const json job = rig.submit("knit", "pic1.png", image_bytes("pic1.png"));
  EXPECT_EQ(job["status"], 201) << job.dump();
  const int64_t id = job.value("id", int64_t{0});
  EXPECT_TRUE(rig.wait_state(id, "completed")) << rig.daemon().log();
  return id;
}

TEST(WebApi, ReadingNeedsNoLoginAndThePageCarriesItsPolicy) {
  WebRig rig;
  auto c = rig.client();
  auto page = c->Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("app.js"), std::string::npos);
  EXPECT_NE(page->get_header_value("Content-Security-Policy").find("script-src 'self'"), std::string::npos);
  EXPECT_EQ(page->get_header_value("X-Frame-Options"), "DENY");
  for (const char* path : {"/app.js", "/app.css"}) {
    auto r = c->Get(path);
    ASSERT_TRUE(r) << path;
    EXPECT_EQ(r->status, 200) << path;
    EXPECT_GT(r->body.size(), 100u) << path;
  }
  auto status = body(c->Get("/api/status"));
  EXPECT_EQ(status["web"]["listening"], true) << status.dump();
  EXPECT_EQ(status["web"]["url"], rig.base_url() + "/");
  EXPECT_TRUE(body(c->Get("/api/devices")).is_array());
  auto jobs = body(c->Get("/api/jobs"));
  EXPECT_EQ(jobs["total"], 0);
  EXPECT_EQ(jobs["limit"], 50);
  auto session = body(c->Get("/api/session"));
  EXPECT_EQ(session["can_act"], false);
  EXPECT_EQ(session["logins"]["password"], true);
  auto missing = c->Get("/api/nothing");
  ASSERT_TRUE(missing);
  EXPECT_EQ(missing->status, 404);
  EXPECT_TRUE(body(missing).contains("error"));
}

TEST(WebApi, ActingWithoutCredentialsIsRefusedAndNothingHappens) {
  WebRig rig;
  auto c = rig.client();
  auto r = c->Post("/api/jobs/1/cancel", "", "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 401);
  EXPECT_NE(body(r)["error"].get<std::string>().find("log in"), std::string::npos);
  httplib::MultipartFormDataItems items = {{"kind", "knit", "", ""}, {"file", image_bytes("pic1.png"), "pic1.png", "image/png"}};
  r = c->Post("/api/submit", items);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 401);
  httplib::Headers wrong = {{"Authorization", "Bearer not-the-token-at-all-xx"}};
  r = rig.client()->Post("/api/submit", wrong, items);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 401);
  EXPECT_EQ(body(rig.client()->Get("/api/jobs"))["total"], 0);  // no job was made
}

TEST(WebApi, ALoginActsOnlyWithItsCsrfTokenFromThisSite) {
  WebRig rig;
  const int64_t id = converted_job(rig);
  auto [cookie, csrf] = rig.login();
  auto c = rig.client();
  const std::string path = "/api/jobs/" + std::to_string(id) + "/retry";
  // A form on another site: the browser sends the cookie, never our header.
  auto r = c->Post(path, {{"Cookie", cookie}, {"Origin", "http://evil.example"}}, "", "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 403) << r->body;
  r = c->Post(path, {{"Cookie", cookie}, {"X-Atelier-CSRF", "0000"}}, "", "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 403) << r->body;
  r = c->Post(path, {{"Cookie", cookie}, {"X-Atelier-CSRF", csrf}, {"Origin", "http://evil.example"}}, "",
              "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 403) << r->body;
  // From the page itself: understood, and refused by the job's state (completed) with its reason.
  r = c->Post(path, {{"Cookie", cookie}, {"X-Atelier-CSRF", csrf}, {"Origin", rig.base_url()}}, "",
              "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 409) << r->body;
  EXPECT_NE(body(r)["error"].get<std::string>().find("completed"), std::string::npos) << r->body;
  auto session = body(c->Get("/api/session", {{"Cookie", cookie}}));
  EXPECT_EQ(session["user"], "alice");
  EXPECT_EQ(session["csrf"], csrf);
  // Logged out: the cookie no longer acts.
  r = c->Post("/api/logout", {{"Cookie", cookie}, {"X-Atelier-CSRF", csrf}}, "", "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  r = c->Post(path, {{"Cookie", cookie}, {"X-Atelier-CSRF", csrf}}, "", "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 401);
}

TEST(WebApi, LoginsFromAnotherSiteAndGuessesAreRefused) {
  WebRig rig;
  auto c = rig.client();
  const std::string good = json{{"user", WebRig::kUser}, {"password", WebRig::kPassword}}.dump();
  auto r = c->Post("/api/login", {{"Origin", "http://evil.example"}}, good, "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 403);
  const std::string bad = json{{"user", WebRig::kUser}, {"password", "guess"}}.dump();
  for (int i = 0; i < 5; ++i) {
    r = c->Post("/api/login", bad, "application/json");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 401);
  }
  r = c->Post("/api/login", good, "application/json");  // even the right one, for a minute
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 429);
  EXPECT_NE(rig.daemon().log().find("failed login from 127.0.0.1"), std::string::npos);
}

TEST(WebApi, SubmitShowAndServeTheJobsFiles) {
  WebRig rig;
  const int64_t id = converted_job(rig);
  auto c = rig.client();
  json job = body(c->Get("/api/jobs/" + std::to_string(id)));
  EXPECT_EQ(job["name"], "pic1.png");
  EXPECT_EQ(job["previews"], json::array({"preview.png", "pattern.png"})) << job.dump();
  EXPECT_GT(job["history"].size(), 2u);
  EXPECT_GE(job["elapsed_s"].get<double>(), 0.0);
  EXPECT_TRUE(job["time_left_s"].is_null());
  auto r = c->Get("/api/jobs/" + std::to_string(id) + "/files/preview.png");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(r->get_header_value("Content-Type"), "image/png");
  EXPECT_EQ(r->body, read_file(job["output_dir"].get<std::string>() + "/preview.png"));
  EXPECT_NE(r->get_header_value("Content-Security-Policy").find("sandbox"), std::string::npos);
  EXPECT_EQ(r->get_header_value("X-Content-Type-Options"), "nosniff");
  r = c->Get("/api/jobs/" + std::to_string(id) + "/files/pattern.k?download=1");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(r->get_header_value("Content-Disposition").rfind("attachment", 0), 0u);
  EXPECT_NE(r->body.find(";!knitout"), std::string::npos);
}

TEST(WebApi, NoFileOutsideTheJobsOutputFolderIsServed) {
  WebRig rig;
  const int64_t id = converted_job(rig);
  const json job = body(rig.client()->Get("/api/jobs/" + std::to_string(id)));
  const std::string out = job["output_dir"];
  // A file of the spool outside the job's folder, and one outside the spool.
  write_file(rig.daemon().spool() / "secret.txt", "SPOOL SECRET");
  fs::create_symlink(rig.daemon().config(), fs::path(out) / "config.txt");
  fs::create_symlink(rig.daemon().spool(), fs::path(out) / "up");
  const std::string base = "/api/jobs/" + std::to_string(id) + "/files/";
  for (const std::string& path : std::vector<std::string>
       {base + "../../secret.txt", base + "..%2F..%2Fsecret.txt", base + "%2e%2e/%2e%2e/secret.txt",
        base + "%2E%2E%2F%2E%2E%2Fatelierd.toml", base + "config.txt", base + "up/secret.txt", base + "up",
        base + "..", base + "", base + "%00preview.png", std::string("/api/jobs/999/files/preview.png"),
        "/api/jobs/" + std::to_string(id) + "/files/..%252F..%252Fsecret.txt"}) {
    auto c = rig.client();
    auto r = c->Get(path);
    ASSERT_TRUE(r) << path;
    EXPECT_EQ(r->status, 404) << path << ": " << r->body;
    EXPECT_EQ(r->body.find("SECRET"), std::string::npos) << path;
    EXPECT_EQ(r->body.find("[spool]"), std::string::npos) << path;
  }
  // A raw request line with the dots unencoded (clients normalise them; browsers too).
  const int fd = connect_tcp(rig.port());
  const std::string req = "GET " + base + "../../../atelierd.toml HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
  ASSERT_EQ(::write(fd, req.data(), req.size()), static_cast<ssize_t>(req.size()));
  std::string answer;
  char buf[4096];
  for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) > 0;) answer.append(buf, static_cast<size_t>(n));
  ::close(fd);
  EXPECT_EQ(answer.rfind("HTTP/1.1 404", 0), 0u) << answer;
  EXPECT_EQ(answer.find("[spool]"), std::string::npos);
}

TEST(WebApi, AnUploadOverTheHotFoldersLimitIsRefusedClearly) {
  WebRigOptions options;
  options.extra_toml = "[limits]\nmax_file_bytes = 100000\n";
  WebRig rig(options);
  const std::string big(300000, 'x');
  json answer = rig.submit("knit", "huge.png", big);
  EXPECT_EQ(answer["status"], 413) << answer.dump();
  EXPECT_NE(answer["error"].get<std::string>().find("100000 bytes ([limits] max_file_bytes)"), std::string::npos)
      << answer.dump();
  // Within what the form may announce, but the file itself is over: cut off as it streams.
  answer = rig.submit("knit", "a-bit-big.png", std::string(120000, 'x'));
  EXPECT_EQ(answer["status"], 413) << answer.dump();
  EXPECT_NE(answer["error"].get<std::string>().find("a-bit-big.png: larger than the hot folder's limit of 100000 bytes"),
            std::string::npos) << answer.dump();
  // Announced too large: refused before a byte of it is read.
  auto c = rig.client();
  auto r = c->Post("/api/login", {{"Content-Length", "99999999"}}, "", "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 413);
  EXPECT_EQ(body(rig.client()->Get("/api/jobs"))["total"], 0);
  // Under the limit, the same route takes it.
  answer = rig.submit("knit", "pic1.png", image_bytes("pic1.png"));
  EXPECT_EQ(answer["status"], 201) << answer.dump();
}

TEST(WebApi, BadUploadsAreRefusedWithTheReason) {
  WebRig rig;
  json a = rig.submit("weaving", "pic1.png", image_bytes("pic1.png"));
  EXPECT_EQ(a["status"], 400);
  EXPECT_NE(a["error"].get<std::string>().find("unknown kind 'weaving'"), std::string::npos) << a.dump();
  httplib::MultipartFormDataItems items = {{"kind", "knit", "", ""}, {"set", "width=nonsense", "", ""},
                                           {"file", image_bytes("pic1.png"), "pic1.png", "image/png"}};
  auto r = rig.client()->Post("/api/submit", WebRig::token_headers(), items);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 400);
  EXPECT_NE(body(r)["error"].get<std::string>().find("width"), std::string::npos) << r->body;
  // Not an image: accepted as a job, which fails with the reason naming the file.
  a = rig.submit("knit", "notes.png", "just some text");
  ASSERT_EQ(a["status"], 201);
  EXPECT_TRUE(rig.wait_state(a["id"], "failed"));
  const json failed = body(rig.client()->Get("/api/jobs/" + std::to_string(a["id"].get<int64_t>())));
  EXPECT_NE(failed["reason"].get<std::string>().find("notes.png"), std::string::npos) << failed.dump();
}

TEST(WebApi, ListsPageThroughAThousandJobs) {
  WebRigOptions options;
  options.preload_jobs = 1000;
  WebRig rig(options);
  auto c = rig.client();
  json page = body(c->Get("/api/jobs"));
  EXPECT_EQ(page["total"], 1000);
  ASSERT_EQ(page["jobs"].size(), 50u);
  EXPECT_EQ(page["jobs"][0]["id"], 1000);  // newest first
  page = body(c->Get("/api/jobs?offset=990&limit=50"));
  ASSERT_EQ(page["jobs"].size(), 10u);
  EXPECT_EQ(page["jobs"][9]["id"], 1);
  page = body(c->Get("/api/jobs?kind=cut&limit=200&offset=0"));
  EXPECT_EQ(page["total"], 333);
  EXPECT_EQ(page["jobs"].size(), 200u);
  for (const char* bad : {"/api/jobs?limit=0", "/api/jobs?limit=201", "/api/jobs?offset=-1", "/api/jobs?state=done",
                          "/api/jobs?kind=weaving"}) {
    auto r = c->Get(bad);
    ASSERT_TRUE(r) << bad;
    EXPECT_EQ(r->status, 400) << bad;
    EXPECT_FALSE(body(r)["error"].get<std::string>().empty()) << bad;
  }
}

TEST(WebApi, EventsStreamEveryChangeOfASubmittedJob) {
  WebRig rig;
  std::mutex mu;
  std::string received;
  std::atomic<bool> stop{false};
  std::thread reader([&] {
    auto c = rig.client();
    c->Get("/api/events", [&](const char* data, size_t n) {
      std::lock_guard lock(mu);
      received.append(data, n);
      return !stop.load();
    });
  });
  ASSERT_TRUE(rig.daemon().wait_for([&] {
    std::lock_guard lock(mu);
    return received.find("event: devices") != std::string::npos;
  }, 10s));
  const int64_t id = converted_job(rig);
  const std::string tag = "\"id\":" + std::to_string(id);
  EXPECT_TRUE(rig.daemon().wait_for([&] {
    std::lock_guard lock(mu);
    return received.find("\"to\":\"completed\"") != std::string::npos;
  }, 10s)) << received;
  stop = true;
  rig.submit("knit", "pic1.png", image_bytes("pic1.png"));  // wakes the reader so it can stop
  reader.join();
  for (const char* state : {"\"to\":\"queued\"", "\"to\":\"converting\"", "\"to\":\"completed\""})
    EXPECT_NE(received.find(state), std::string::npos) << state << "\n" << received;
  EXPECT_NE(received.find("event: job\ndata: {"), std::string::npos);
  EXPECT_NE(received.find(tag), std::string::npos);
}

TEST(WebApi, ASlowOrSilentBrowserDoesNotHoldUpTheDaemon) {
  WebRig rig;
  // Connections that send half a request and stop, and event streams never read.
  std::vector<int> stalled;
  for (int i = 0; i < 20; ++i) {
    const int fd = connect_tcp(rig.port());
    const std::string part = i % 2 ? "GET /api/events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n" : "GET /api/jobs HTTP/1.1\r\nHo";
    ASSERT_EQ(::write(fd, part.data(), part.size()), static_cast<ssize_t>(part.size()));
    stalled.push_back(fd);
  }
  // The control socket answers and the daemon converts, as if no browser were there.
  EXPECT_EQ(rig.daemon().request("status")["ok"], true);
  drop_file(test_image("pic1.png"), rig.daemon().incoming("knit") / "pic1.png");
  EXPECT_TRUE(rig.daemon().wait_job_state("pic1.png", "completed", 60s)) << rig.daemon().log();
  // And the web server still serves others.
  auto r = rig.client()->Get("/api/status");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  for (int fd : stalled) ::close(fd);
  EXPECT_EQ(rig.daemon().stop(), 0);  // and it stops cleanly with streams open
}

TEST(WebApi, BodiesThatCouldGrowWithoutBoundAreRefusedUnread) {
  WebRig rig;
  auto c = rig.client();
  // Chunked: no length stated, so no cap httplib would keep to. Sent by hand: the answer comes
  // before the body is read, and a client library would write on into a closed connection.
  const int fd = connect_tcp(rig.port());
  timeval tv{10, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  const std::string head = "POST /api/login HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
                           "Transfer-Encoding: chunked\r\n\r\n2\r\n{}\r\n";
  ASSERT_EQ(::send(fd, head.data(), head.size(), MSG_NOSIGNAL), static_cast<ssize_t>(head.size()));
  char buf[512] = {};
  const ssize_t n = ::recv(fd, buf, sizeof buf - 1, 0);
  ::close(fd);
  ASSERT_GT(n, 0);
  EXPECT_EQ(std::string(buf).rfind("HTTP/1.1 411", 0), 0u) << buf;
  auto r = rig.client()->Get("/api/status");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);  // and the server goes on
  // Compressed: its size in memory is not what it states.
  r = rig.client()->Post("/api/login", {{"Content-Encoding", "gzip"}}, "xx", "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 411) << r->body;
  // Many ranges of one file: one answer would hold them all.
  r = rig.client()->Get("/app.js", {{"Range", "bytes=0-,0-,0-,0-"}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 416);
  r = rig.client()->Get("/app.js", {{"Range", "bytes=0-9"}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 206);
  EXPECT_EQ(r->body.size(), 10u);
  r = rig.client()->Put("/api/jobs/1/cancel", "", "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 405);
}

TEST(WebApi, ALoginEndsWhenItsUserIsRemovedFromTheConfig) {
  WebRig rig;
  auto [cookie, csrf] = rig.login();
  auto c = rig.client();
  auto session = body(c->Get("/api/session", {{"Cookie", cookie}}));
  EXPECT_EQ(session["can_act"], true);
  // The administrator removes alice and reloads: her open page can no longer act.
  std::string config = read_file(rig.daemon().config());
  config = config.substr(0, config.find("[web.users]")) + config.substr(config.find("[knit]"));
  write_file(rig.daemon().config(), config);
  ::kill(rig.daemon().pid(), SIGHUP);
  EXPECT_TRUE(rig.daemon().wait_for([&] {
    return body(rig.client()->Get("/api/session", {{"Cookie", cookie}}))["can_act"] == false;
  }, 10s)) << rig.daemon().log();
  auto r = rig.client()->Post("/api/jobs/1/cancel", {{"Cookie", cookie}, {"X-Atelier-CSRF", csrf}}, "",
                              "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 401);
}

TEST(WebApi, AnotherSitesNameForTheBoxIsRefused) {
  WebRig rig;
  auto c = rig.client();
  // DNS rebinding: evil.example made to resolve to this box; the browser sends its own name.
  auto r = c->Get("/api/jobs", {{"Host", "evil.example:" + std::to_string(rig.port())}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 403);
  EXPECT_NE(r->body.find("server_names"), std::string::npos);
  r = c->Get("/api/jobs", {{"Host", "localhost:" + std::to_string(rig.port())}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
}

TEST(WebApi, AddressesOutsideAllowFromAreRefused) {
  // allow_from without loopback: this very client is outside it.
  TempDir dir;
  const int port = free_tcp_port();
  DaemonProcess d(dir.path(), "[web]\nenabled = true\nlisten = \"127.0.0.1:" + std::to_string(port) +
                                  "\"\nallow_from = [\"192.168.77.0/24\"]\n");
  d.start();
  httplib::Client c("127.0.0.1", port);
  c.set_read_timeout(10);
  auto r = c.Get("/api/status");
  for (int i = 0; i < 100 && !r; ++i) {
    std::this_thread::sleep_for(50ms);
    r = c.Get("/api/status");
  }
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 403);
  EXPECT_NE(r->body.find("allow_from"), std::string::npos);
}

}  // namespace
}  // namespace atelier::test

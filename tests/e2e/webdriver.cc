#include "tests/e2e/webdriver.h"

#include "tests/e2e/daemon_harness.h"

#include <fcntl.h>
#include <httplib.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

extern char** environ;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace atelier::test {
namespace {

constexpr const char* kDriver = "/usr/bin/chromedriver";
constexpr const char* kChromium = "/usr/bin/chromium";
constexpr const char* kElementKey = "element-6066-11e4-a52e-4f735466cecf";
constexpr auto kPoll = std::chrono::milliseconds(50);

std::vector<unsigned char> base64_decode(const std::string& text) {
  auto sextet = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+' || c == '-') return 62;  // also the URL-safe alphabet
    if (c == '/' || c == '_') return 63;
    return -1;
  };
  std::vector<unsigned char> out;
  out.reserve(text.size() / 4 * 3);
  unsigned bits = 0;
  int nbits = 0;
  for (char c : text) {
    if (c == '=') break;
    if (c == '\n' || c == '\r' || c == ' ') continue;
    int v = sextet(c);
    if (v < 0) throw std::runtime_error("webdriver: screenshot is not base64");
    bits = (bits << 6) | static_cast<unsigned>(v);
    nbits += 6;
    if (nbits >= 8) {
      nbits -= 8;
      out.push_back(static_cast<unsigned char>(bits >> nbits));
    }
  }
  return out;
}

std::string element_id(const json& value, const std::string& command) {
  if (!value.is_object() || !value.contains(kElementKey))
    throw std::runtime_error("WebDriver " + command + ": answer is not an element: " +
                             value.dump());
  return value[kElementKey].get<std::string>();
}

std::string quoted(const std::string& s) { return "\"" + s + "\""; }

}  // namespace

bool Browser::available() {
  return access(kDriver, X_OK) == 0 && access(kChromium, X_OK) == 0;
}

Browser::Browser(int width, int height) {
  try {
    if (!available())
      throw std::runtime_error(std::string("webdriver: ") + kDriver + " or " + kChromium +
                               " is not installed");
    std::string tmpl = (fs::temp_directory_path() / "atelier-browser-XXXXXX").string();
    if (!mkdtemp(tmpl.data()))
      throw std::runtime_error(std::string("webdriver: mkdtemp: ") + strerror(errno));
    dir_ = tmpl;

    port_ = free_tcp_port();
    start_driver();
    http_ = std::make_unique<httplib::Client>("127.0.0.1", port_);
    http_->set_connection_timeout(5);
    // Screenshots and page loads on a busy CI machine can take a while.
    http_->set_read_timeout(60);
    http_->set_write_timeout(60);
    wait_driver_ready(std::chrono::seconds(20));

    json args = {"--headless=new",
                 "--no-sandbox",  // tests run as root in containers
                 "--disable-gpu",
                 "--disable-dev-shm-usage",  // /dev/shm is tiny in containers
                 "--no-first-run",
                 "--disable-background-networking",
                 "--disable-component-update",
                 "--disable-sync",
                 "--disable-quic",
                 "--user-data-dir=" + (dir_ / "profile").string(),
                 "--window-size=" + std::to_string(width) + "," + std::to_string(height)};
    json caps = {{"browserName", "chrome"},
                 {"goog:chromeOptions", {{"binary", kChromium}, {"args", args}}},
                 // Keeps console messages for browser_log().
                 {"goog:loggingPrefs", {{"browser", "ALL"}}},
                 // Below the HTTP read timeout, so that a hanging page or script fails with the
                 // driver's "timeout" error rather than a dropped connection.
                 {"timeouts", {{"pageLoad", 30000}, {"script", 30000}}}};
    json answer = call("New Session", "POST", "/session",
                       {{"capabilities", {{"alwaysMatch", caps}}}});
    session_ = answer.at("sessionId").get<std::string>();
  } catch (const std::exception& e) {
    // The destructor does not run for a half-built object, so clean up here; the log goes
    // with the folder, hence its tail in the message.
    std::string message = e.what();
    if (!dir_.empty()) {
      std::string log = driver_log();
      if (log.size() > 4000) log = "..." + log.substr(log.size() - 4000);
      if (!log.empty()) message += "\n--- chromedriver log ---\n" + log;
    }
    shutdown();
    throw std::runtime_error(message);
  } catch (...) {
    shutdown();
    throw;
  }
}

Browser::~Browser() { shutdown(); }

namespace {

bool has_exited(pid_t pid) {
  // WNOWAIT leaves the zombie in place, so that its pid (and process group) is not reused
  // before the caller is done signalling it.
  siginfo_t info{};
  if (waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT) != 0)
    return errno == ECHILD;  // already reaped (SIGCHLD ignored?): gone all the same
  return info.si_pid == pid;
}

void nap_10ms() {
  timespec ts{0, 10'000'000};
  nanosleep(&ts, nullptr);
}

// The watchdog, in a fork of the test process: runs chromedriver in a process group of its own
// (Chromium joins it) and ends that group once `lifeline` has a byte (the Browser is done) or
// reaches EOF (the test process died without running its destructors; then it also removes the
// temporary folder with `rm_argv`). Only async-signal-safe calls from here on: the test process
// may have had other threads.
[[noreturn]] void watchdog(int lifeline, char* const argv[], char* const rm_argv[],
                           char* const envp[]) {
  pid_t driver = fork();
  if (driver == 0) {
    setpgid(0, 0);
    close_range(3, ~0U, 0);  // the lifeline, and the test's own sockets and files
    execve(argv[0], argv, envp);
    _exit(127);
  }
  if (driver < 0) _exit(126);
  setpgid(driver, driver);  // also here, so the group exists whichever side runs first
  bool orphaned = false;
  for (;;) {
    pollfd fd{lifeline, POLLIN, 0};
    int ready = poll(&fd, 1, 100);
    if (ready < 0 && errno != EINTR) break;
    if (ready > 0) {
      char byte;
      ssize_t n = read(lifeline, &byte, 1);
      if (n > 0) break;
      if (n == 0 || errno != EINTR) {
        orphaned = true;
        break;
      }
    }
    if (has_exited(driver)) break;  // chromedriver died by itself: the Browser sees us exit
  }
  // SIGTERM to the whole group: chromedriver does not pass it on to Chromium, which would
  // otherwise outlive it whenever the session was not deleted.
  kill(-driver, SIGTERM);
  for (int i = 0; i < 500 && !has_exited(driver); ++i) nap_10ms();
  kill(-driver, SIGKILL);  // whatever is left of the group; the unreaped leader holds its id
  int status = 0;
  while (waitpid(driver, &status, 0) < 0 && errno == EINTR) {
  }
  if (orphaned) execve(rm_argv[0], rm_argv, envp);
  _exit(WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status));
}

}  // namespace

void Browser::start_driver() {
  // Everything the children need is prepared before fork(): between fork and exec only
  // async-signal-safe calls are allowed.
  // INFO logs each command and Chromium's launch, which explains most failures (~40 kB a test).
  std::vector<std::string> args = {kDriver, "--port=" + std::to_string(port_),
                                   "--log-level=INFO"};
  // No --allowed-ips: with it chromedriver listens on all interfaces; by default it listens on
  // 127.0.0.1 and ::1 and accepts local connections only.
  std::vector<std::string> env;
  for (char** e = environ; *e; ++e)
    if (strncmp(*e, "XDG_CONFIG_HOME=", 16) != 0) env.emplace_back(*e);
  // Chromium keeps its crash-report database under the config home, not the profile.
  env.push_back("XDG_CONFIG_HOME=" + (dir_ / "config").string());
  std::vector<std::string> rm_args = {"/bin/rm", "-rf", "--", dir_.string()};
  std::vector<char*> argv, rm_argv, envp;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  for (auto& a : rm_args) rm_argv.push_back(a.data());
  rm_argv.push_back(nullptr);
  for (auto& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);

  fs::path log = dir_ / "chromedriver.log";
  int log_fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0644);
  if (log_fd < 0)
    throw std::runtime_error("webdriver: cannot create " + log.string() + ": " + strerror(errno));
  int null_fd = open("/dev/null", O_RDONLY | O_CLOEXEC);
  // A socket pair rather than a pipe: send() can then skip SIGPIPE if the watchdog is gone.
  int lifeline[2];
  if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, lifeline) != 0) {
    int err = errno;
    close(log_fd);
    if (null_fd >= 0) close(null_fd);
    throw std::runtime_error(std::string("webdriver: socketpair: ") + strerror(err));
  }
  pid_t pid = fork();
  if (pid == 0) {
    // Its own group, so that a Ctrl-C meant for the test leaves the clean-up to it.
    setpgid(0, 0);
    // Ignored signals and the signal mask would survive exec; chromedriver wants the defaults.
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    for (int sig = 1; sig < NSIG; ++sig) sigaction(sig, &dfl, nullptr);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    if (null_fd >= 0) dup2(null_fd, 0);
    dup2(log_fd, 1);
    dup2(log_fd, 2);
    dup2(lifeline[0], 3);
    close_range(4, ~0U, 0);  // above all the test's end, or EOF would never come
    watchdog(3, argv.data(), rm_argv.data(), envp.data());
  }
  int fork_errno = errno;
  close(log_fd);
  if (null_fd >= 0) close(null_fd);
  close(lifeline[0]);
  if (pid < 0) {
    close(lifeline[1]);
    throw std::runtime_error(std::string("webdriver: fork: ") + strerror(fork_errno));
  }
  watchdog_pid_ = pid;
  lifeline_ = lifeline[1];
}

void Browser::wait_driver_ready(std::chrono::milliseconds timeout) {
  auto deadline = std::chrono::steady_clock::now() + timeout;
  http_->set_read_timeout(1);
  for (;;) {
    if (has_exited(watchdog_pid_))
      throw std::runtime_error("webdriver: chromedriver exited before it was ready (port " +
                               std::to_string(port_) + ")");
    if (auto res = http_->Get("/status"); res && res->status == 200) {
      json status = json::parse(res->body, nullptr, false);
      json value = status.is_object() ? status["value"] : json();
      if (value.is_object() && value.value("ready", false)) break;
    }
    if (std::chrono::steady_clock::now() >= deadline)
      throw std::runtime_error("WebDriver Status: chromedriver not ready after " +
                               std::to_string(timeout.count()) + " ms");
    std::this_thread::sleep_for(kPoll);
  }
  http_->set_read_timeout(60);
}

void Browser::shutdown() noexcept {
  try {
    if (!session_.empty() && http_ && watchdog_pid_ > 0 && !has_exited(watchdog_pid_)) {
      http_->set_read_timeout(15);
      http_->Delete("/session/" + session_);  // quits Chromium cleanly; errors do not matter here
    }
  } catch (...) {
  }
  session_.clear();
  http_.reset();
  if (lifeline_ >= 0) {
    // A byte rather than just EOF: the folder is ours to remove, the log may still be wanted.
    send(lifeline_, "q", 1, MSG_NOSIGNAL);
    close(lifeline_);  // the watchdog now ends chromedriver and Chromium
    lifeline_ = -1;
  }
  if (watchdog_pid_ > 0) {
    // It needs at most 5 s; only a watchdog stuck beyond that is killed (leaking the driver).
    auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (!has_exited(watchdog_pid_) && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (!has_exited(watchdog_pid_)) kill(watchdog_pid_, SIGKILL);
    while (waitpid(watchdog_pid_, nullptr, 0) < 0 && errno == EINTR) {
    }
    watchdog_pid_ = -1;
  }
  if (!dir_.empty()) {
    std::error_code ec;
    fs::remove_all(dir_, ec);
    dir_.clear();
  }
}

std::string Browser::driver_log() const {
  return dir_.empty() ? std::string() : read_file(dir_ / "chromedriver.log");
}

json Browser::call(const std::string& command, const char* method, const std::string& path,
                   const json& body) {
  if (!http_) throw std::runtime_error("WebDriver " + command + ": no chromedriver");
  httplib::Result res = [&] {
    std::string m = method;
    // W3C wants a JSON object even for commands without parameters.
    std::string payload = body.is_null() ? std::string("{}") : body.dump();
    if (m == "GET") return http_->Get(path);
    if (m == "DELETE") return http_->Delete(path);
    return http_->Post(path, payload, "application/json; charset=utf-8");
  }();
  if (!res)
    throw std::runtime_error("WebDriver " + command + ": no answer from chromedriver (" +
                             httplib::to_string(res.error()) + ")");
  json answer = json::parse(res->body, nullptr, false);
  if (answer.is_discarded() || !answer.is_object())
    throw std::runtime_error("WebDriver " + command + ": HTTP " + std::to_string(res->status) +
                             " with a body that is not JSON: " + res->body.substr(0, 300));
  json value = answer.contains("value") ? answer["value"] : json();
  if (res->status != 200 || (value.is_object() && value.contains("error"))) {
    std::string error = value.is_object() ? value.value("error", "") : "";
    std::string message = value.is_object() ? value.value("message", "") : "";
    // chromedriver repeats the error code in the message and appends "(Session info: ...)".
    if (auto info = message.find("\n  (Session info:"); info != std::string::npos)
      message.erase(info);
    if (!error.empty() && message.starts_with(error + ": ")) message.erase(0, error.size() + 2);
    while (!message.empty() && (message.back() == '\n' || message.back() == ' '))
      message.pop_back();
    throw std::runtime_error("WebDriver " + command + " failed: " +
                             (error.empty() ? "HTTP " + std::to_string(res->status) : error) +
                             (message.empty() ? "" : ": " + message));
  }
  return value;
}

json Browser::session_call(const std::string& command, const char* method,
                           const std::string& path, const json& body) {
  if (session_.empty()) throw std::runtime_error("WebDriver " + command + ": no session");
  return call(command, method, "/session/" + session_ + path, body);
}

void Browser::go(const std::string& url) {
  session_call("Navigate To " + quoted(url), "POST", "/url", {{"url", url}});
}

std::string Browser::url() {
  return session_call("Get Current URL", "GET", "/url").get<std::string>();
}

void Browser::set_window_size(int width, int height) {
  session_call("Set Window Rect", "POST", "/window/rect", {{"width", width}, {"height", height}});
}

void Browser::set_viewport_size(int width, int height) {
  set_window_size(width, height);
  json inner = execute("return [window.innerWidth, window.innerHeight];");
  int frame_w = width - inner.at(0).get<int>(), frame_h = height - inner.at(1).get<int>();
  if (frame_w != 0 || frame_h != 0) set_window_size(width + frame_w, height + frame_h);
}

std::string Browser::find(const std::string& css) {
  std::string command = "Find Element " + quoted(css);
  return element_id(
      session_call(command, "POST", "/element", {{"using", "css selector"}, {"value", css}}),
      command);
}

std::vector<std::string> Browser::find_all(const std::string& css) {
  std::string command = "Find Elements " + quoted(css);
  json found =
      session_call(command, "POST", "/elements", {{"using", "css selector"}, {"value", css}});
  std::vector<std::string> ids;
  for (const json& e : found) ids.push_back(element_id(e, command));
  return ids;
}

std::optional<std::string> Browser::wait_for(const std::string& css,
                                             std::chrono::milliseconds timeout) {
  auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (auto found = find_all(css); !found.empty()) return found.front();
    if (std::chrono::steady_clock::now() >= deadline) return std::nullopt;
    std::this_thread::sleep_for(kPoll);
  }
}

bool Browser::wait_until(const std::string& js_expression, std::chrono::milliseconds timeout) {
  // Newlines around the expression so that a trailing // comment cannot swallow the rest.
  std::string script =
      "try { return !!(\n" + js_expression + "\n); } catch (e) { return false; }";
  auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (execute(script) == true) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(kPoll);
  }
}

void Browser::click(const std::string& element) {
  session_call("Element Click", "POST", "/element/" + element + "/click");
}

void Browser::send_keys(const std::string& element, const std::string& text) {
  session_call("Element Send Keys", "POST", "/element/" + element + "/value", {{"text", text}});
}

void Browser::clear(const std::string& element) {
  session_call("Element Clear", "POST", "/element/" + element + "/clear");
}

std::string Browser::text(const std::string& element) {
  return session_call("Get Element Text", "GET", "/element/" + element + "/text")
      .get<std::string>();
}

std::string Browser::attribute(const std::string& element, const std::string& name) {
  json v = session_call("Get Element Attribute " + quoted(name), "GET",
                        "/element/" + element + "/attribute/" + name);
  if (v.is_null()) return "";
  return v.is_string() ? v.get<std::string>() : v.dump();
}

json Browser::property(const std::string& element, const std::string& name) {
  return session_call("Get Element Property " + quoted(name), "GET",
                      "/element/" + element + "/property/" + name);
}

void Browser::select_option(const std::string& select_element, const std::string& value) {
  json chosen = execute(R"(
      const select = arguments[0], value = arguments[1];
      const i = Array.from(select.options).findIndex(o => o.value === value);
      if (i < 0) return false;
      select.selectedIndex = i;
      select.dispatchEvent(new Event('input', {bubbles: true}));
      select.dispatchEvent(new Event('change', {bubbles: true}));
      return true;)",
                        json::array({element_arg(select_element), value}));
  if (chosen != true)
    throw std::runtime_error("WebDriver select_option: no <option> with value " + quoted(value));
}

json Browser::execute(const std::string& script, const json& args) {
  return session_call("Execute Script", "POST", "/execute/sync",
                      {{"script", script}, {"args", args}});
}

json Browser::execute_async(const std::string& script, const json& args) {
  return session_call("Execute Async Script", "POST", "/execute/async",
                      {{"script", script}, {"args", args}});
}

json Browser::element_arg(const std::string& element) { return {{kElementKey, element}}; }

void Browser::screenshot(const fs::path& png) {
  json data = session_call("Take Screenshot", "GET", "/screenshot");
  if (!data.is_string()) throw std::runtime_error("WebDriver Take Screenshot: no image data");
  std::vector<unsigned char> bytes = base64_decode(data.get<std::string>());
  std::ofstream out(png, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw std::runtime_error("WebDriver Take Screenshot: cannot write " + png.string());
}

json Browser::browser_log() {
  try {
    // chromedriver's legacy log endpoint; not part of W3C, so absent from other drivers.
    json entries = session_call("Get Log \"browser\"", "POST", "/se/log", {{"type", "browser"}});
    return entries.is_array() ? entries : json::array();
  } catch (const std::runtime_error&) {
    return json::array();
  }
}

}  // namespace atelier::test

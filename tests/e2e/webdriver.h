// A small W3C WebDriver client for end-to-end browser tests: starts chromedriver and, through
// it, a headless Chromium, and drives the page over HTTP on loopback.
//
// Ownership: a Browser owns its WebDriver session, a temporary folder (browser profile,
// chromedriver's log) and a watchdog process (a fork of the test process) that runs
// chromedriver in a process group of its own, which the Chromium processes join. The destructor
// ends all of them, as does a constructor that throws part-way; the watchdog also ends the group
// when the test process dies without running destructors (crash, SIGKILL), and then removes the
// folder too: it watches a socket whose other end only the test process holds (close-on-exec;
// a child the test forks without exec would hold it too).
// Threading: not thread-safe; use a Browser from one thread at a time.
// Units: window sizes in CSS pixels; timeouts as std::chrono durations.
// Errors: a failing command throws std::runtime_error naming the WebDriver command and carrying
// the driver's error code and message (value.error / value.message).
#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace httplib {
class Client;
}

namespace atelier::test {

class Browser {
 public:
  // Starts /usr/bin/chromedriver on a free loopback port, waits (up to 20 s) until it is ready
  // and opens a session with a headless /usr/bin/chromium with that window size (see
  // set_window_size()), on a fresh profile. Takes about 1-2 s. Throws (with the tail of
  // chromedriver's log) if any of that fails.
  explicit Browser(int width = 1280, int height = 900);
  // Deletes the session, stops chromedriver and Chromium (SIGTERM to the group, then SIGKILL
  // after at most 5 s), reaps the watchdog and removes the temporary folder. Never throws.
  ~Browser();
  Browser(const Browser&) = delete;
  Browser& operator=(const Browser&) = delete;

  // Whether chromedriver and chromium are installed; tests GTEST_SKIP when not.
  static bool available();

  void go(const std::string& url);  // returns once the page has loaded (at most 30 s)
  std::string url();
  // The window's outer size. Headless Chromium still reserves room for a browser frame, so the
  // viewport (innerWidth x innerHeight) can be smaller: same width, 143 px less height in
  // Chromium 156.
  void set_window_size(int width, int height);
  // Resizes the window so that the viewport is exactly that size, e.g. 360 x 740 for a phone.
  void set_viewport_size(int width, int height);

  // Element handles are WebDriver element ids. They go stale when the page navigates or the
  // element leaves the DOM; a command on a stale one throws.
  std::string find(const std::string& css);  // the first match; throws if none
  std::vector<std::string> find_all(const std::string& css);  // in document order; may be empty
  // Polls every 50 ms (at least once) until `css` matches, returning the first match, or
  // nullopt once `timeout` has passed.
  std::optional<std::string> wait_for(const std::string& css, std::chrono::milliseconds timeout);
  // Polls every 50 ms (at least once) until the JavaScript expression is truthy; false once
  // `timeout` has passed. An exception inside the expression (say, an element not there yet)
  // counts as false; a syntax error throws.
  bool wait_until(const std::string& js_expression, std::chrono::milliseconds timeout);

  void click(const std::string& element);
  // Types `text` into the element. For <input type=file>, `text` is a local path (several:
  // separated by '\n'), which chromedriver hands to the input as the chosen file.
  void send_keys(const std::string& element, const std::string& text);
  void clear(const std::string& element);
  std::string text(const std::string& element);  // the rendered text (innerText-like)
  // Get Element Attribute: the HTML attribute as in the markup, "" when absent. Note that the
  // "value" attribute of an input stays the initial value; what was typed is property("value").
  std::string attribute(const std::string& element, const std::string& name);
  // Get Element Property: the live DOM property as JSON (null when undefined), e.g. "value",
  // "checked", "files".
  nlohmann::json property(const std::string& element, const std::string& name);
  // Sets a <select> to the option with that value and dispatches 'input' and 'change' (bubbling),
  // as a user's choice would. Throws if no option has that value.
  void select_option(const std::string& select_element, const std::string& value);

  // Runs `script` as a function body (arguments[0...] are `args`) and returns its result.
  // Element handles go in args as element_arg(id); elements come back as
  // {"element-6066-11e4-a52e-4f735466cecf": id}.
  nlohmann::json execute(const std::string& script,
                         const nlohmann::json& args = nlohmann::json::array());
  // Like execute(), but the script finishes by calling its last argument (the callback) with
  // the result; the session's script timeout (30 s) applies.
  nlohmann::json execute_async(const std::string& script,
                               const nlohmann::json& args = nlohmann::json::array());
  static nlohmann::json element_arg(const std::string& element);

  // Writes a PNG of the viewport to `png` (replacing it).
  void screenshot(const std::filesystem::path& png);
  // The page's console messages since the last call (chromedriver's "browser" log: objects with
  // level, message, source, timestamp in ms), or an empty array if the driver has none.
  nlohmann::json browser_log();
  // chromedriver's own log so far (its stdout and stderr, with Chromium's stderr), for
  // explaining a failure.
  std::string driver_log() const;

 private:
  // One WebDriver request; returns the response's "value". `command` names it in errors.
  nlohmann::json call(const std::string& command, const char* method, const std::string& path,
                      const nlohmann::json& body = nullptr);
  // The same under /session/<id>.
  nlohmann::json session_call(const std::string& command, const char* method,
                              const std::string& path, const nlohmann::json& body = nullptr);
  void start_driver();
  void wait_driver_ready(std::chrono::milliseconds timeout);
  void shutdown() noexcept;

  std::filesystem::path dir_;  // temporary: profile/, config/, chromedriver.log
  pid_t watchdog_pid_ = -1;    // exits once chromedriver's group has ended
  int lifeline_ = -1;          // a byte or EOF on it tells the watchdog to end the group
  int port_ = 0;
  std::unique_ptr<httplib::Client> http_;
  std::string session_;
};

}  // namespace atelier::test

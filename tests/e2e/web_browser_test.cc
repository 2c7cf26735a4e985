// The web page in a real browser (headless Chromium over WebDriver, tests/e2e/webdriver.h)
// against the real daemon and the knitting-machine emulator: the jobs page follows the daemon
// live, a file dropped through the page becomes a job that completes before the user's eyes,
// its page shows its previews, a running knit job is canceled from the page and the machine
// stops, the machines page says what the knitter does, and all of it fits a phone. Screenshots
// of every page go to <build>/test-output/web/ (printed at the end of each test).
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <numeric>
#include <set>

#include "tests/e2e/web_rig.h"
#include "tests/e2e/webdriver.h"

namespace atelier::test {
namespace {

using namespace std::chrono_literals;
using json = nlohmann::json;
namespace fs = std::filesystem;

fs::path shots_dir() {
  fs::path dir = fs::path(ATELIER_BINARY_DIR) / "test-output" / "web";
  fs::create_directories(dir);
  return dir;
}

// The id of the newest row of the jobs table, or 0.
int64_t newest_row(Browser& b) {
  json id = b.execute("const tr = document.querySelector('#jobs-body tr[data-job-id]');"
                      "return tr ? Number(tr.dataset.jobId) : 0;");
  return id.get<int64_t>();
}

// Whether the page's layout fits its viewport (no sideways scrolling).
bool fits_width(Browser& b) {
  return b.execute("return document.documentElement.scrollWidth <= window.innerWidth + 1;").get<bool>();
}

// Console errors of the page (CSP violations and script errors land here).
std::vector<std::string> page_errors(Browser& b) {
  std::vector<std::string> out;
  for (const json& entry : b.browser_log())
    if (entry.value("level", "") == "SEVERE") out.push_back(entry.value("message", ""));
  return out;
}

// Clicks the element `css` matches once it is shown and enabled, as a person would: the live
// page may redraw it meanwhile (a new state, new buttons), so a stale or not yet shown one is
// looked up again, for up to `timeout`.
void click_when_ready(Browser& b, const std::string& css, std::chrono::milliseconds timeout = 10s) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  const std::string ready = "(() => { const e = document.querySelector(" + json(css).dump() +
                            "); return !!e && !e.disabled && e.getClientRects().length > 0; })()";
  for (;;) {
    try {
      if (b.wait_until(ready, 1s)) {
        b.click(b.find(css));
        return;
      }
    } catch (const std::runtime_error&) {
      if (std::chrono::steady_clock::now() >= until) throw;
    }
    if (std::chrono::steady_clock::now() >= until) throw std::runtime_error("never clickable: " + css);
    std::this_thread::sleep_for(50ms);
  }
}

// Logs in through the page's own form with alice's password.
void log_in(Browser& b) {
  click_when_ready(b, "#login-open");
  b.send_keys(*b.wait_for("#login-user", 5s), WebRig::kUser);
  b.send_keys(b.find("#login-password"), WebRig::kPassword);
  b.click(b.find("#login-submit"));
  ASSERT_TRUE(b.wait_until("!document.querySelector('#upload-submit').disabled", 10s)) << "login did not take";
}

// Uploads `image` through the page's file chooser as a `kind` job with `sets` (key=value
// lines); returns the new job's id from the page.
int64_t upload(Browser& b, const std::string& kind, const std::string& image, const std::string& sets) {
  const int64_t before = newest_row(b);
  b.select_option(b.find("#upload-kind"), kind);
  b.clear(b.find("#upload-sets"));
  if (!sets.empty()) b.send_keys(b.find("#upload-sets"), sets);
  b.send_keys(b.find("#upload-file"), test_image(image).string());
  b.click(b.find("#upload-submit"));
  EXPECT_TRUE(b.wait_until("document.querySelector('#jobs-body tr[data-job-id]') && "
                           "Number(document.querySelector('#jobs-body tr[data-job-id]').dataset.jobId) > " +
                               std::to_string(before),
                           20s))
      << b.text(b.find("#upload-message"));
  return newest_row(b);
}

// Polls the row of job `id` on the jobs page until it shows `state`, recording every state
// it showed on the way. The page is never reloaded meanwhile (the marker survives).
std::vector<std::string> watch_row(Browser& b, int64_t id, const std::string& state, std::chrono::seconds timeout) {
  std::vector<std::string> seen;
  const auto until = std::chrono::steady_clock::now() + timeout;
  const std::string get = "const tr = document.querySelector('#jobs-body tr[data-job-id=\"" + std::to_string(id) +
                          "\"]'); return tr ? tr.dataset.state : '';";
  while (std::chrono::steady_clock::now() < until) {
    const std::string now = b.execute(get).get<std::string>();
    if (!now.empty() && (seen.empty() || seen.back() != now)) seen.push_back(now);
    if (now == state) break;
    std::this_thread::sleep_for(30ms);
  }
  return seen;
}

TEST(WebPage, FollowsJobsLiveFromUploadToCancelOnTheKnittingMachine) {
  if (!Browser::available()) GTEST_SKIP() << "chromium and chromium-driver are not installed";
  WebRigOptions options;
  options.knitter = true;
  options.row_ms = 60;  // a 100-stitch piece knits for several seconds: time to cancel it
  WebRig rig(options);
  Browser b(1280, 900);
  const fs::path shots = shots_dir();
  b.go(rig.base_url() + "/#/jobs");
  ASSERT_TRUE(b.wait_until("document.body.dataset.live === '1'", 10s)) << "the event stream did not open";
  // Every job event as this page receives it, with the delay since the daemon made it.
  b.execute("window.__marker = 'no reload'; window.__latency = [];"
            "new EventSource('/api/events').addEventListener('job', e => {"
            "  const ev = JSON.parse(e.data); window.__latency.push(Date.now() - Date.parse(ev.at)); });");
  log_in(b);
  b.screenshot(shots / "jobs-desktop.png");

  // A small knit job dropped through the page: converted, knitted, completed, live.
  const int64_t small = upload(b, "knit", "pic1.png", "width=20");
  ASSERT_GT(small, 0);
  const std::vector<std::string> seen = watch_row(b, small, "completed", 90s);
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back(), "completed") << rig.daemon().log();
  EXPECT_GE(seen.size(), 2u) << "the row never showed the job before it completed";
  EXPECT_EQ(b.execute("return window.__marker;"), "no reload");
  b.screenshot(shots / "jobs-after-upload.png");

  // Its page: the previews load, the outputs are listed for download, the history is there.
  click_when_ready(b, "#jobs-body tr[data-job-id=\"" + std::to_string(small) + "\"] a");
  ASSERT_TRUE(b.wait_for("#job-page[data-job-id=\"" + std::to_string(small) + "\"]", 10s));
  ASSERT_TRUE(b.wait_until("document.querySelectorAll('img.preview').length >= 2 && "
                           "[...document.querySelectorAll('img.preview')].every(i => i.complete && i.naturalWidth > 0)",
                           15s));
  const json sizes = b.execute("return [...document.querySelectorAll('img.preview')].map(i => [i.naturalWidth, i.naturalHeight]);");
  for (const json& s : sizes) EXPECT_GT(s[0].get<int>(), 0);
  EXPECT_TRUE(b.execute("return !!document.querySelector('a[href$=\"files/pattern.k?download=1\"]');").get<bool>());
  b.screenshot(shots / "job-page.png");

  // A big piece, knitting on the emulator, canceled from its page: the machine stops.
  b.go(rig.base_url() + "/#/jobs");
  ASSERT_TRUE(b.wait_for("#upload-file", 10s));
  const int64_t big = upload(b, "knit", "HappyFish.jpg", "width=100");
  b.go(rig.base_url() + "/#/jobs/" + std::to_string(big));
  ASSERT_TRUE(b.wait_until("document.querySelector('#job-page') && document.querySelector('#job-page').dataset.state === 'running'", 90s))
      << rig.daemon().log();
  ASSERT_TRUE(b.wait_until("document.querySelector('#job-page progress, #job-page .bar') !== null", 5s));
  b.screenshot(shots / "job-running.png");
  click_when_ready(b, "button[data-action=\"cancel\"]");
  click_when_ready(b, "#confirm-ok");
  ASSERT_TRUE(b.wait_until("document.querySelector('#job-page').dataset.state === 'canceled'", 30s)) << rig.daemon().log();
  // Once canceled, the page no longer says it is canceling.
  EXPECT_TRUE(b.wait_until("!/cancel/i.test(document.querySelector('#action-message').textContent)", 5s))
      << b.text(b.find("#action-message"));
  b.screenshot(shots / "job-canceled.png");
  const json job = rig.daemon().request("show", {{"id", big}})["result"];
  EXPECT_EQ(job["state"], "canceled");
  const int64_t knitted = job["progress"]["done"], total = job["progress"]["total"];
  EXPECT_LT(knitted, total) << "the whole piece was knitted: the cancel came too late";
  const size_t rows_before = rig.knitter()->recorded().size();
  std::this_thread::sleep_for(500ms);
  EXPECT_EQ(rig.knitter()->recorded().size(), rows_before) << "the machine went on knitting";

  // The machines page: the knitter, its state and what it last did.
  b.go(rig.base_url() + "/#/machines");
  ASSERT_TRUE(b.wait_for(".device[data-device=\"knitter\"]", 10s));
  EXPECT_NE(b.text(b.find(".device[data-device=\"knitter\"]")).find("knitter"), std::string::npos);
  b.screenshot(shots / "machines-desktop.png");

  // A phone: every page fits 360 px.
  b.set_viewport_size(360, 740);
  for (const std::string& page : {std::string("#/jobs"), "#/jobs/" + std::to_string(small), std::string("#/machines")}) {
    b.go(rig.base_url() + "/" + page);
    ASSERT_TRUE(b.wait_until("document.querySelector('#app').children.length > 0", 10s));
    std::this_thread::sleep_for(300ms);  // images and fonts settle
    EXPECT_TRUE(fits_width(b)) << page << " scrolls sideways at 360 px";
    std::string name = page.substr(2);
    std::replace(name.begin(), name.end(), '/', '-');
    b.screenshot(shots / ("phone-" + name + ".png"));
  }

  const std::vector<std::string> errors = page_errors(b);
  EXPECT_TRUE(errors.empty()) << errors.front();
  std::vector<double> latency;
  for (const json& ms : b.execute("return window.__latency || [];")) latency.push_back(ms.get<double>());
  std::sort(latency.begin(), latency.end());
  if (!latency.empty())
    std::cout << "event latency (daemon change -> page), " << latency.size() << " events: median "
              << latency[latency.size() / 2] << " ms, max " << latency.back() << " ms\n";
  std::cout << "screenshots: " << shots.string() << "\n";
}

TEST(WebPage, AThousandJobsArePagedAndLoadQuickly) {
  if (!Browser::available()) GTEST_SKIP() << "chromium and chromium-driver are not installed";
  WebRigOptions options;
  options.preload_jobs = 1000;
  WebRig rig(options);
  Browser b(1280, 900);
  const fs::path shots = shots_dir();
  // From navigation to 50 rows drawn, as the browser's own clock measures it (ms since the
  // navigation began): the page's load event, the list's answer, and the first poll that saw
  // the rows (an upper bound, within the 50 ms of polling).
  b.go(rig.base_url() + "/#/jobs");
  ASSERT_TRUE(b.wait_until("document.querySelectorAll('#jobs-body tr[data-job-id]').length === 50", 15s));
  const json t = b.execute(
      "const nav = performance.getEntriesByType('navigation')[0];"
      "const api = performance.getEntriesByType('resource').find(e => e.name.includes('/api/jobs'));"
      "return {load: nav.loadEventEnd, api: api ? api.responseEnd : -1, seen: performance.now()};");
  std::cout << "jobs page with 1000 jobs in the store: load event " << t["load"] << " ms, /api/jobs answered "
            << t["api"] << " ms, 50 rows drawn by " << t["seen"] << " ms after navigation\n";
  EXPECT_NE(b.text(b.find("#jobs-total")).find("1000"), std::string::npos);
  EXPECT_EQ(newest_row(b), 1000);
  b.screenshot(shots / "jobs-1000.png");
  b.click(b.find("#page-older"));
  ASSERT_TRUE(b.wait_until("Number(document.querySelector('#jobs-body tr[data-job-id]').dataset.jobId) === 950", 10s));
  EXPECT_NE(b.text(b.find("#jobs-total")).find("51"), std::string::npos) << b.text(b.find("#jobs-total"));
  b.select_option(b.find("#filter-kind"), "cut");
  ASSERT_TRUE(b.wait_until("document.querySelector('#jobs-total').textContent.includes('333')", 10s))
      << b.text(b.find("#jobs-total"));
  b.set_viewport_size(360, 740);
  std::this_thread::sleep_for(300ms);
  EXPECT_TRUE(fits_width(b));
  b.screenshot(shots / "phone-jobs-1000.png");
  const std::vector<std::string> errors = page_errors(b);
  EXPECT_TRUE(errors.empty()) << errors.front();
}

}  // namespace
}  // namespace atelier::test

// The web page's server side against the real daemon (docs/web.md):
// - BM_WebJobsPage: GET /api/jobs (the first page of 50, with each job's times) over a store
//   of 1000 jobs: what the jobs page waits for.
// - BM_WebEventLatency: from a job's state change in the daemon (the event's "at") to its
//   server-sent event arriving at a client of GET /api/events: how live the page is.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include <ctime>
#include <optional>

#include "daemon/store.h"
#include "tests/e2e/web_rig.h"

namespace {

// Milliseconds since the epoch of "2026-11-22T11:31:50.123Z" (daemon/job_json.h's format).
std::optional<int64_t> parse_iso8601_utc(const std::string& text) {
  std::tm tm{};
  int ms = 0;
  if (std::sscanf(text.c_str(), "%d-%d-%dT%d:%d:%d.%dZ", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour,
                  &tm.tm_min, &tm.tm_sec, &ms) != 7)
    return std::nullopt;
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return static_cast<int64_t>(timegm(&tm)) * 1000 + ms;
}

using atelier::test::WebRig;
using atelier::test::WebRigOptions;

void BM_WebJobsPage(benchmark::State& state) {
  WebRigOptions options;
  options.preload_jobs = 1000;
  WebRig rig(options);
  auto client = rig.client();
  size_t bytes = 0;
  for (auto _ : state) {
    auto r = client->Get("/api/jobs?limit=50&offset=0");
    if (!r || r->status != 200) {
      state.SkipWithError("GET /api/jobs failed");
      return;
    }
    bytes = r->body.size();
  }
  state.SetLabel("1000 jobs in the store, first page of 50 (" + std::to_string(bytes) + " bytes of JSON)");
}
BENCHMARK(BM_WebJobsPage)->Unit(benchmark::kMillisecond)->Iterations(200);

void BM_WebEventLatency(benchmark::State& state) {
  WebRig rig;
  std::mutex mu;
  std::condition_variable cv;
  std::vector<double> latencies_ms;  // one per job event received
  std::atomic<bool> stop{false};
  std::string buffer;
  std::thread reader([&] {
    auto c = rig.client();
    c->Get("/api/events", [&](const char* data, size_t n) {
      const int64_t received = atelier::now_ms();
      std::lock_guard lock(mu);
      buffer.append(data, n);
      for (size_t end; (end = buffer.find("\n\n")) != std::string::npos; buffer.erase(0, end + 2)) {
        const std::string event = buffer.substr(0, end);
        const auto data_at = event.find("data: ");
        if (event.rfind("event: job", 0) != 0 || data_at == std::string::npos) continue;
        const auto j = nlohmann::json::parse(event.substr(data_at + 6), nullptr, false);
        if (auto at = parse_iso8601_utc(j.value("at", ""))) latencies_ms.push_back(double(received - *at));
      }
      cv.notify_all();
      return !stop.load();
    });
  });
  const std::string not_an_image = "no picture here";
  for (auto _ : state) {
    // A job that is queued, converts and fails at once: three state changes.
    size_t before;
    {
      std::lock_guard lock(mu);
      before = latencies_ms.size();
    }
    rig.submit("knit", "notes.png", not_an_image);
    std::unique_lock lock(mu);
    cv.wait_for(lock, std::chrono::seconds(10), [&] { return latencies_ms.size() >= before + 3; });
  }
  stop = true;
  rig.submit("knit", "last.png", not_an_image);  // an event, so the reader sees `stop`
  reader.join();
  std::sort(latencies_ms.begin(), latencies_ms.end());
  if (latencies_ms.empty()) {
    state.SkipWithError("no event arrived");
    return;
  }
  state.counters["median_ms"] = latencies_ms[latencies_ms.size() / 2];
  state.counters["p95_ms"] = latencies_ms[latencies_ms.size() * 95 / 100];
  state.counters["max_ms"] = latencies_ms.back();
  state.SetLabel(std::to_string(latencies_ms.size()) + " job events, daemon change -> SSE client (ms clock)");
}
BENCHMARK(BM_WebEventLatency)->Unit(benchmark::kMillisecond)->Iterations(20);

}  // namespace

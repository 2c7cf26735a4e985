// AYAB line round trip through the real serial stack: the host's cnfLine goes through
// libserialport and a pseudo-terminal to atelier-knit-emu, whose next reqLine comes back the
// same way. With the emulated carriage taking no time (--row-ms 0), the interval between two
// confirmed passes is one reqLine -> cnfLine round trip. Target: p99 under 5 ms (a real
// carriage waits on it).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <thread>

#include "drivers/ayab/host_session.h"
#include "drivers/ayab/knit_plan.h"
#include "drivers/serial_transport.h"
#include "tests/e2e/daemon_harness.h"

namespace fs = std::filesystem;

static void BM_AyabLineRoundTrip(benchmark::State& state) {
  atelier::test::TempDir dir;
  const fs::path link = dir.path() / "knitter";
  atelier::test::BackgroundProcess emulator(
      {atelier::test::binary("atelier-knit-emu").string(), "--machine", "kh930", "--link",
       link.string(), "--row-ms", "0", "--boot-ms", "0"},
      dir.path() / "emulator.log");
  for (int i = 0; i < 100 && !fs::exists(link); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));

  const int rows = static_cast<int>(state.range(0));
  cv::Mat pattern(rows, 180, CV_8UC1);
  cv::randu(pattern, 0, 2);
  const auto plan = atelier::ayab::plan_knitting(pattern, {});
  std::vector<double> round_trips_ms;
  for (auto _ : state) {
    auto link_port = atelier::SerialTransport::open(link.string());
    atelier::ayab::HostSession session(*link_port);
    session.connect();
    session.init(plan.machine);
    auto last = std::chrono::steady_clock::now();
    std::atomic<bool> cancel{false};
    session.knit(plan, 0, [&](const atelier::ayab::KnitProgress&) {
      auto now = std::chrono::steady_clock::now();
      round_trips_ms.push_back(std::chrono::duration<double, std::milli>(now - last).count());
      last = now;
    }, cancel);
    link_port->close();
  }
  if (round_trips_ms.empty()) return;
  std::sort(round_trips_ms.begin(), round_trips_ms.end());
  auto pct = [&](double p) { return round_trips_ms[static_cast<size_t>(p * (round_trips_ms.size() - 1))]; };
  state.counters["p50_ms"] = pct(0.50);
  state.counters["p99_ms"] = pct(0.99);
  state.counters["max_ms"] = round_trips_ms.back();
  state.SetLabel(std::to_string(round_trips_ms.size()) + " lines, KH-930, pty + libserialport");
}
BENCHMARK(BM_AyabLineRoundTrip)->Arg(1000)->Iterations(1)->Unit(benchmark::kMillisecond);

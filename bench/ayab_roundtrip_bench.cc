// AYAB line round trip through the real serial stack: the host's cnfLine goes through
// libserialport and a pseudo-terminal to atelier-knit-emu, whose next reqLine comes back the
// same way. With the emulated carriage taking no time (--row-ms 0), the interval between two
// confirmed passes is one reqLine -> cnfLine round trip. Target: p99 under 5 ms (a real
// carriage waits on it).
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <random>
#include <thread>

#include "drivers/ayab/host_session.h"
#include "drivers/ayab/knit_plan.h"
#include "drivers/serial_transport.h"

extern char** environ;
namespace fs = std::filesystem;

static void BM_AyabLineRoundTrip(benchmark::State& state) {
  std::string tmpl = (fs::temp_directory_path() / "atelier-bench-XXXXXX").string();
  const fs::path dir = mkdtemp(tmpl.data());
  const fs::path link = dir / "knitter";
  std::vector<std::string> argv = {std::string(ATELIER_BINARY_DIR) + "/bin/atelier-knit-emu",
                                   "--machine", "kh930", "--link", link.string(),
                                   "--row-ms", "0", "--boot-ms", "0"};
  std::vector<char*> args;
  for (auto& a : argv) args.push_back(a.data());
  args.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  pid_t pid;
  if (posix_spawn(&pid, args[0], &fa, nullptr, args.data(), environ) != 0) {
    state.SkipWithError("cannot start atelier-knit-emu");
    return;
  }
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
  kill(pid, SIGTERM);
  waitpid(pid, nullptr, 0);
  fs::remove_all(dir);
  if (round_trips_ms.empty()) return;
  std::sort(round_trips_ms.begin(), round_trips_ms.end());
  auto pct = [&](double p) { return round_trips_ms[static_cast<size_t>(p * (round_trips_ms.size() - 1))]; };
  state.counters["p50_ms"] = pct(0.50);
  state.counters["p99_ms"] = pct(0.99);
  state.counters["max_ms"] = round_trips_ms.back();
  state.SetLabel(std::to_string(round_trips_ms.size()) + " lines, KH-930, pty + libserialport");
}
BENCHMARK(BM_AyabLineRoundTrip)->Arg(1000)->Iterations(1)->Unit(benchmark::kMillisecond);

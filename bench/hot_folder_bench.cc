// Hot-folder pick-up latency: from the moment a dropped file is closed to the moment its
// job row is committed (claimed into work/<id>/, queued). Target: under 50 ms.
#include <benchmark/benchmark.h>
#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "daemon/hot_folder.h"
#include "daemon/job_service.h"
#include "daemon/store.h"
#include "tests/e2e/daemon_harness.h"

namespace fs = std::filesystem;

static void BM_HotFolderPickup(benchmark::State& state) {
  atelier::test::TempDir tmp;
  const fs::path root = tmp.path();
  atelier::SpoolLayout layout{root / "spool"};
  atelier::Store store(root / "jobs.sqlite");
  atelier::JobService jobs(store, layout, nullptr);
  jobs.ensure_layout();
  atelier::HotFolder folder(layout, atelier::WatchMode::inotify, 500);
  std::string bytes(100 * 1024, 'x');  // a 100 kB drop
  int n = 0;
  for (auto _ : state) {
    fs::path file = layout.incoming("knit") / ("drop" + std::to_string(n++) + ".png");
    {
      std::ofstream out(file, std::ios::binary);
      out << bytes;
    }
    auto closed = std::chrono::steady_clock::now();
    bool claimed = false;
    while (!claimed) {
      struct pollfd p = {folder.fd(), POLLIN, 0};
      ::poll(&p, 1, 1000);
      for (const auto& entry : folder.collect()) claimed = jobs.claim(entry).has_value() || claimed;
    }
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - closed).count());
  }
  state.SetLabel("100 kB file, inotify, claim + SQLite commit");
}
BENCHMARK(BM_HotFolderPickup)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(50);

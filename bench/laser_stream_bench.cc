// GRBL streaming throughput through the real serial stack: the driver streams a dense engrave
// job (short G1 moves, the power changing on every one, as a raster does) through
// libserialport and a pseudo-terminal to atelier-laser-emu, which takes bytes at the real
// 115200-baud rate into its 128-byte receive buffer and moves almost instantly
// (--time-scale 0.0001), so the serial line is the bottleneck. The figure is the share of the
// line rate (11520 bytes/s) the job's bytes used: character counting against send-response.
// Target: 90 % or more with character counting.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "drivers/grbl/session.h"
#include "drivers/serial_transport.h"
#include "tests/e2e/daemon_harness.h"

namespace fs = std::filesystem;
namespace grbl = atelier::grbl;

namespace {

constexpr double kLineBytesPerSecond = 115200.0 / 10;  // 8N1: 10 bits a byte

// A dense engrave: a serpentine raster of 0.1 mm steps whose power follows a pattern.
std::string dense_engrave(int moves) {
  std::string g = "; s_max=1000\nG21 G90\nG0 X10 Y10\nM4\nG1 F3000\n";
  char line[64];
  for (int i = 0; i < moves; ++i) {
    const int row = i / 400, col = i % 400;
    const double x = 10 + (row % 2 ? 400 - col : col) * 0.1;
    const double y = 10 + row * 0.1;
    std::snprintf(line, sizeof line, "G1X%.1fY%.1fS%d\n", x, y, (i * 37) % 1000);
    g += line;
  }
  return g + "M5\n";
}

void stream_job(benchmark::State& state, grbl::StreamMode mode) {
  atelier::test::TempDir dir;
  const fs::path link = dir.path() / "laser";
  atelier::test::BackgroundProcess emulator(
      {atelier::test::binary("atelier-laser-emu").string(), "--link", link.string(), "--time-scale", "0.0001"},
      dir.path() / "emulator.log");
  for (int i = 0; i < 100 && !fs::exists(link); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));

  const grbl::Program program = grbl::parse_program(dense_engrave(static_cast<int>(state.range(0))), 6000);
  size_t bytes = 0;
  for (const auto& l : program.lines) bytes += l.size() + 1;
  double seconds = 0;
  for (auto _ : state) {
    auto port = atelier::SerialTransport::open(link.string());
    grbl::Session session(*port);
    session.connect();
    grbl::Controls controls;
    const auto t0 = std::chrono::steady_clock::now();
    session.stream(program, mode, controls, [](const grbl::Progress&) {});
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    port->close();
    state.SetIterationTime(seconds);
  }
  state.counters["line_rate_pct"] = 100.0 * bytes / seconds / kLineBytesPerSecond;
  state.counters["bytes_per_s"] = bytes / seconds;
  state.SetLabel(std::to_string(program.lines.size()) + " lines, " + std::to_string(bytes) + " bytes");
}

void BM_GrblStreamCharacterCounting(benchmark::State& state) {
  stream_job(state, grbl::StreamMode::character_counting);
}
void BM_GrblStreamSendResponse(benchmark::State& state) { stream_job(state, grbl::StreamMode::send_response); }

}  // namespace

BENCHMARK(BM_GrblStreamCharacterCounting)->Arg(3000)->Arg(4986)->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GrblStreamSendResponse)->Arg(3000)->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);

// The time estimate (grbl::parse_program over GRBL's planner model) against the emulator's
// motion: a job streamed with the planner kept full takes what the estimate says. The
// emulator's motion is slowed by its time scale so the 115200 baud link never starves it.
#include <gtest/gtest.h>

#include <cstdio>
#include <deque>
#include <string>

#include "drivers/grbl/program.h"
#include "tests/support/laser_emu_rig.h"

namespace atelier::laser_emu {
namespace {

using testing::Rig;

constexpr double kTimeScale = 20;

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

// A greyscale raster: 30 lines of 0.1 mm, back and forth over 20 mm, S changing every 0.5 mm.
std::string dense_raster() {
  std::string g = "G21 G90\nM4 S0\nG0 X0 Y0\n";
  for (int row = 0; row < 30; ++row) {
    const double y = row * 0.1;
    const bool forward = row % 2 == 0;
    g += "G0 X" + num(forward ? 0 : 20) + " Y" + num(y) + "\n";
    for (int k = 1; k <= 40; ++k) {
      const double x = forward ? k * 0.5 : 20 - k * 0.5;
      g += "G1 X" + num(x) + " S" + std::to_string((k * 37 + row * 11) % 1000) + " F3000\n";
    }
  }
  return g + "M5\n";
}

// A cut outline: straight edges, a G2 arc, a G3 arc and a polyline of shallow corners.
std::string curved_cut() {
  std::string g = "G21 G90\nG0 X10 Y10\nM4 S800\nG1 X60 F1200\nG2 X70 Y20 I0 J10\nG1 Y50\n";
  g += "G3 X40 Y50 I-15 J0\n";
  for (int k = 1; k <= 30; ++k) g += "G1 X" + num(40 - k) + " Y" + num(50 - k * 1.3 + (k % 2) * 0.2) + "\n";
  return g + "G1 X10 Y10\nM5\n";
}

// Streams `gcode` by character counting (127 bytes in flight at most) and returns the
// seconds the head took, unscaled: from the first piece of motion to the last.
double emulated_seconds(const std::string& gcode) {
  ControllerOptions o;
  o.time_scale = kTimeScale;
  Rig rig(o);
  rig.boot();
  for (const char* s : {"$120=500", "$121=500", "$11=0.010", "$110=6000", "$111=6000"})
    EXPECT_EQ(rig.exchange(s), "ok\r\n") << s;
  const grbl::Program p = grbl::parse_program(gcode, 6000);
  std::deque<size_t> in_flight;
  size_t next = 0, acked = 0, bytes = 0;
  while (acked < p.lines.size()) {
    while (next < p.lines.size() && bytes + p.lines[next].size() + 1 <= 127) {
      rig.send(p.lines[next] + "\n");
      bytes += p.lines[next].size() + 1;
      in_flight.push_back(p.lines[next].size() + 1);
      ++next;
    }
    rig.run(1000);
    for (size_t pos; (pos = rig.out.find("ok\r\n")) != std::string::npos;) {
      rig.out.erase(0, pos + 4);
      bytes -= in_flight.front();
      in_flight.pop_front();
      ++acked;
    }
    EXPECT_EQ(rig.out.find("error"), std::string::npos) << rig.out;
    if (rig.t > 4'000'000'000) break;  // over an hour of virtual time: something is stuck
  }
  rig.run(1'000'000);
  for (int i = 0; i < 100000 && rig.ctl.state() != MachineState::idle; ++i) rig.run(10'000);
  const Record r = rig.ctl.snapshot();
  EXPECT_FALSE(r.segments.empty());
  if (r.segments.empty()) return 0;
  return (r.segments.back().t1 - r.segments.front().t0) / kTimeScale;
}

double estimated_seconds(const std::string& gcode) {
  laser::MotionSettings s;
  s.accel_mm_s2 = {500, 500, 10};
  s.max_rate_mm_min = {6000, 6000, 500};
  s.steps_per_mm = {80, 80, 250};
  s.junction_deviation_mm = 0.010;
  return grbl::parse_program(gcode, s).total_seconds();
}

TEST(LaserEmuPlannerTiming, ADenseRasterTakesWhatTheEstimateSays) {
  const std::string g = dense_raster();
  const double estimate = estimated_seconds(g);
  const double emulated = emulated_seconds(g);
  EXPECT_NEAR(emulated, estimate, 0.02 * estimate) << "estimate " << estimate << " s, emulator " << emulated << " s";
  // Acceleration counts: each line starts and ends at rest (+0.05 s per ramp at 500 mm/s^2),
  // so the raster takes over 1.2 times its 12 s at the feed alone.
  EXPECT_GT(estimate, 1.2 * 30 * 20 / 50.0);
}

TEST(LaserEmuPlannerTiming, ACurvedCutTakesWhatTheEstimateSays) {
  const std::string g = curved_cut();
  const double estimate = estimated_seconds(g);
  const double emulated = emulated_seconds(g);
  EXPECT_NEAR(emulated, estimate, 0.02 * estimate) << "estimate " << estimate << " s, emulator " << emulated << " s";
}

}  // namespace
}  // namespace atelier::laser_emu

// What the laser emulator did, for tests and people: the toolpath with beam power, notable
// events, and receive-buffer statistics (atelier-laser-emu --record FILE / --render PNG).
//
// Times are unix epoch seconds (system_clock, double) so tests compare them with their own
// clock; positions are machine mm (X right, Y away from the operator, origin front-left).
// JSON: {"segments":[{"t0","t1","x0","y0","x1","y1","s","power","mode","feed"}],
//        "events":[{"t","event","code"?,"line"?}], "rx_overflows", "max_rx_bytes",
//        "lines_received", "errors", "work_area_mm":[W,H]}.
// A segment is a stretch of constant programmed speed and laser output: a block (or the part of
// it run before a hold/reset/alarm), the deceleration of a feed hold, or a stationary burn
// (x0==x1, y0==y1: M3 with power while stopped). power is 0..1 of $30 (0 when the beam is off;
// M4 power is already scaled by actual/programmed speed, the deceleration's average is used),
// mode "M3"|"M4"|"off", s the programmed S of the block, feed its speed in mm/min.
// Events: hold, resume, reset, alarm(code), beam_off, overflow(line), error(code,line),
// hangup (the host closed the port or died: DTR dropped, the board restarted),
// drop, replug.
// Plain value types; not thread-safe. Rendering is pure (no file I/O).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace atelier::laser_emu {

struct Segment {
  double t0 = 0, t1 = 0;
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  double s = 0;
  double power = 0;
  std::string mode = "off";
  double feed = 0;
};

struct Event {
  double t = 0;
  std::string event;
  std::optional<int> code;
  std::optional<long> line;
};

struct Record {
  std::vector<Segment> segments;
  std::vector<Event> events;
  long rx_overflows = 0;  // bytes dropped because the 128-byte receive buffer was full
  int max_rx_bytes = 0;   // highest receive-buffer fill seen
  long lines_received = 0;
  long errors = 0;        // error:N responses
  double work_w_mm = 400, work_h_mm = 400;
  uint64_t version = 0;   // bumped on every change, so a writer knows when to save again

  void add_event(double t, std::string name, std::optional<int> code = {}, std::optional<long> line = {});
  void add_segment(const Segment& s);
};

nlohmann::json to_json(const Record& record);

// A white 8-bit grey image of the work area at `px_per_mm`, every segment with power > 0 drawn
// dark (darker for more power, line width max(1, round(0.2 mm * px_per_mm))). Machine (X, Y)
// maps to pixel (X * px_per_mm, (H - Y) * px_per_mm): Y up, the origin at the bottom-left.
cv::Mat render_burn(const Record& record, double px_per_mm);

}  // namespace atelier::laser_emu

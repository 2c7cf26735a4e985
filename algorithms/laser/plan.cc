#include "algorithms/laser/plan.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "algorithms/laser/kerf.h"
#include "algorithms/laser/motion_planner.h"
#include "algorithms/laser/order.h"

namespace atelier::laser {
namespace {

constexpr size_t kMaxLine = 70;
constexpr double kEpsilon = 1e-6;  // mm; absorbs rounding at the edges of the work area

// Design (x right, y down) -> bed coordinates (Y from the front edge); see plan.h.
Point to_machine(Point p, const Machine& m) { return Point{p.x, m.height_mm - p.y}; }

// Bed (0, 0), where the head is assumed to start, in design coordinates.
Point machine_zero_in_design(const Machine& m) { return Point{0, m.height_mm}; }

// GRBL's planner (motion_planner.h) with the job's machine: both axes at the travel rate
// and acceleration of the [laser] settings, its junction deviation; the rest GRBL's.
MotionSettings motion_settings_for(const Machine& m) {
  MotionSettings ms;
  ms.max_rate_mm_min[0] = ms.max_rate_mm_min[1] = m.travel_mm_min;
  ms.accel_mm_s2[0] = ms.accel_mm_s2[1] = m.accel_mm_s2;
  ms.junction_deviation_mm = m.junction_deviation_mm;
  return ms;
}

// Writes G-code lines and remembers the modal state, so that unchanged axes and feeds are
// not repeated (every byte costs streaming time).
class GcodeWriter {
 public:
  void line(std::string text) {
    if (text.size() > kMaxLine) text.resize(kMaxLine);
    out_ += text;
    out_ += '\n';
  }

  void move(bool burn, Point p, double feed) {
    std::string x = format_number(p.x), y = format_number(p.y);
    if (x == x_ && y == y_) return;  // no motion after rounding
    std::string text = burn ? "G1" : "G0";
    if (x != x_) text += " X" + x;
    if (y != y_) text += " Y" + y;
    if (burn) {
      std::string f = format_number(feed);
      if (f != f_) text += " F" + f;
      f_ = f;
    }
    x_ = x;
    y_ = y;
    line(text);
  }

  std::string take() { return std::move(out_); }

 private:
  std::string out_;
  std::string x_, y_, f_;  // as last written; empty = unknown
};

std::string printable(const std::string& s) {
  std::string out;
  for (char c : s) out += (c >= 0x20 && c < 0x7f) ? c : '?';
  return out;
}

std::string layer_comment(const LayerSettings& s) {
  std::string tail = std::string(" ") + mode_name(s.mode) + " " +
                     format_number(s.speed_mm_min) + "mm/min " + format_number(s.power_pct) +
                     "% x" + std::to_string(s.passes);
  std::string head = "; layer ";
  std::string name = printable(s.name);
  size_t room = kMaxLine > head.size() + tail.size() ? kMaxLine - head.size() - tail.size() : 0;
  if (name.size() > room) name.resize(room);
  return head + name + tail;
}

void check_settings(const LayerSettings& s, const Machine& m) {
  auto bad = [&](const std::string& what) {
    throw PlanError("layer '" + s.name + "': " + what);
  };
  if (!(s.speed_mm_min > 0)) bad("speed_mm_min must be above 0");
  if (!(s.power_pct >= 0 && s.power_pct <= 100)) bad("power_pct must be within 0..100");
  if (s.passes < 1) bad("passes must be at least 1");
  if (!(s.kerf_mm >= 0)) bad("kerf_mm must not be negative");
  if (!(m.width_mm > 0 && m.height_mm > 0)) throw PlanError("the work area must not be empty");
  if (!(m.s_max > 0)) throw PlanError("s_max must be above 0");
  if (!(m.travel_mm_min > 0)) throw PlanError("travel_mm_min must be above 0");
}

void check_work_area(const Bounds& design, const Machine& m) {
  if (design.min_x >= -kEpsilon && design.min_y >= -kEpsilon &&
      design.max_x <= m.width_mm + kEpsilon && design.max_y <= m.height_mm + kEpsilon) {
    return;
  }
  Bounds mb;
  mb.add(to_machine(Point{design.min_x, design.min_y}, m));
  mb.add(to_machine(Point{design.max_x, design.max_y}, m));
  Bounds area;
  area.add(to_machine(Point{0, 0}, m));
  area.add(to_machine(Point{m.width_mm, m.height_mm}, m));
  auto range = [](double a, double b) { return format_number(a) + ".." + format_number(b); };
  throw PlanError("the job spans X " + range(mb.min_x, mb.max_x) + " mm x Y " +
                  range(mb.min_y, mb.max_y) + " mm, outside the " + format_number(m.width_mm) +
                  " x " + format_number(m.height_mm) + " mm work area (X " +
                  range(area.min_x, area.max_x) + ", Y " + range(area.min_y, area.max_y) +
                  " in bed coordinates)");
}

// The program's header: the comments the driver reads (s_max, bounds), then units and mode.
void write_header(GcodeWriter& g, const Machine& machine, const Bounds& bounds) {
  g.line("; atelier laser job");
  g.line("; s_max=" + format_number(machine.s_max));
  g.line("; bounds=" + format_number(bounds.min_x) + "," + format_number(bounds.min_y) + "," +
         format_number(bounds.max_x) + "," + format_number(bounds.max_y));
  g.line("G21 G90");
}

}  // namespace

const char* mode_name(Mode mode) { return mode == Mode::cut ? "cut" : "engrave"; }

std::string format_number(double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f", value);
  std::string s(buf);
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  return s;
}

Job plan_job(const std::vector<Layer>& layers, const Machine& machine) {
  // A NaN would pass every comparison below unnoticed (and stall the ordering): refuse it first.
  for (const auto& l : layers)
    for (const auto& path : l.paths)
      for (const auto& q : path.points)
        if (!std::isfinite(q.x) || !std::isfinite(q.y))
          throw PlanError("layer '" + l.settings.name + "': a point is not a finite number");
  // Nesting over every cut layer at once, so that a hole drawn in another colour than its
  // outline still counts as a hole (kerf inwards, cut before the outline).
  std::vector<Path> all_cut;
  for (const auto& l : layers)
    if (l.settings.mode == Mode::cut) all_cut.insert(all_cut.end(), l.paths.begin(), l.paths.end());
  const std::vector<size_t> all_depths = nesting_depths(all_cut);
  std::map<const Layer*, std::vector<size_t>> depths;
  std::map<const Layer*, size_t> deepest;
  for (size_t at = 0; const auto& l : layers) {
    if (l.settings.mode != Mode::cut) continue;
    auto& d = depths[&l];
    d.assign(all_depths.begin() + static_cast<long>(at), all_depths.begin() + static_cast<long>(at + l.paths.size()));
    deepest[&l] = d.empty() ? 0 : *std::max_element(d.begin(), d.end());
    at += l.paths.size();
  }

  // Engrave first: engraving after cutting would hit pieces that may have shifted. Then the
  // cut layers, those holding the deepest (innermost) contours first: a piece must not drop
  // out before its holes are cut.
  std::vector<const Layer*> order;
  for (const auto& l : layers)
    if (l.settings.mode == Mode::engrave) order.push_back(&l);
  std::vector<const Layer*> cuts;
  for (const auto& l : layers)
    if (l.settings.mode == Mode::cut) cuts.push_back(&l);
  std::stable_sort(cuts.begin(), cuts.end(), [&](const Layer* a, const Layer* b) { return deepest[a] > deepest[b]; });
  order.insert(order.end(), cuts.begin(), cuts.end());

  Job job;
  Point head = machine_zero_in_design(machine);
  Bounds design;
  for (const Layer* layer : order) {
    const LayerSettings& s = layer->settings;
    check_settings(s, machine);
    KerfResult kerf;
    if (s.mode == Mode::cut) kerf = apply_kerf(layer->paths, s.kerf_mm, depths[layer]);
    else kerf.paths = layer->paths;
    std::vector<Path> paths = order_paths(kerf.paths, head);
    if (paths.empty()) continue;
    for (const auto& p : paths) design.add(bounds_of(p));
    PlannedLayer planned;
    planned.settings = s;
    planned.paths = std::move(paths);
    LayerStats stats;
    stats.name = s.name;
    stats.mode = s.mode;
    stats.paths = planned.paths.size();
    stats.passes = s.passes;
    stats.vanished_holes = kerf.vanished_holes;
    job.toolpaths.push_back(std::move(planned));
    job.layers.push_back(stats);
  }
  if (job.toolpaths.empty()) throw PlanError("nothing to burn: no layer has a path");
  check_work_area(design, machine);

  for (auto& layer : job.toolpaths)
    for (auto& path : layer.paths)
      for (auto& p : path.points) {
        p = to_machine(p, machine);
        job.bounds.add(p);
      }

  GcodeWriter g;
  write_header(g, machine, job.bounds);
  Point at{0, 0};
  // Every move as GRBL's planner sees it, and the layer it belongs to, for the estimate.
  std::vector<PlannedMove> moves;
  std::vector<size_t> move_layer;
  for (size_t li = 0; li < job.toolpaths.size(); ++li) {
    const PlannedLayer& layer = job.toolpaths[li];
    const LayerSettings& s = layer.settings;
    LayerStats& stats = job.layers[li];
    const double feed = s.speed_mm_min;
    g.line(layer_comment(s));
    g.line("M4 S" + std::to_string(std::lround(s.power_pct / 100.0 * machine.s_max)));
    bool synced = true;  // the M4 line above: the planner empties before the next move
    auto plan = [&](bool burn, Point p) {
      PlannedMove m;
      m.target = {p.x, p.y, 0};
      m.feed_mm_min = feed;
      m.rapid = !burn;
      m.from_rest = synced;
      synced = false;
      moves.push_back(m);
      move_layer.push_back(li);
    };
    double burn_mm = 0, travel_mm = 0;
    for (const Path& path : layer.paths) {
      travel_mm += distance(at, path.points.front());
      g.move(false, path.points.front(), feed);
      plan(false, path.points.front());
      at = path.points.front();
      stats.length_mm += path_length(path);
      for (int pass = 0; pass < s.passes; ++pass) {
        // Open paths run back and forth so that a repeat needs no travel.
        bool backwards = !path.closed && pass % 2 == 1;
        const auto& pts = path.points;
        for (size_t k = 1; k < pts.size(); ++k) {
          Point p = backwards ? pts[pts.size() - 1 - k] : pts[k];
          g.move(true, p, feed);
          plan(true, p);
          burn_mm += distance(at, p);
          at = p;
        }
        if (path.closed && pts.size() > 1) {
          g.move(true, pts.front(), feed);
          plan(true, pts.front());
          burn_mm += distance(at, pts.front());
          at = pts.front();
        }
      }
    }
    (s.mode == Mode::cut ? job.cut_length_mm : job.engrave_length_mm) += burn_mm;
    job.travel_length_mm += travel_mm;
  }
  // Acceleration and junctions as GRBL plans them: short moves and corners take longer than
  // their length at the feed (issue 20: a dense engrave 3.9x longer than length / feed).
  const std::vector<double> seconds = move_seconds(moves, motion_settings_for(machine));
  for (size_t i = 0; i < seconds.size(); ++i) {
    job.layers[move_layer[i]].time_s += seconds[i];
    job.estimated_s += seconds[i];
  }
  g.line("M5");
  job.gcode = g.take();
  return job;
}

}  // namespace atelier::laser

namespace atelier::laser {

Job join_jobs(const std::vector<Job>& jobs, const std::vector<std::vector<std::string>>& notes,
              const Machine& machine) {
  if (jobs.empty()) throw PlanError("join_jobs: no jobs");
  if (notes.size() != jobs.size()) throw PlanError("join_jobs: one list of notes per job");
  Job out;
  for (const Job& j : jobs) {
    out.bounds.add(j.bounds);
    out.layers.insert(out.layers.end(), j.layers.begin(), j.layers.end());
    out.toolpaths.insert(out.toolpaths.end(), j.toolpaths.begin(), j.toolpaths.end());
    out.cut_length_mm += j.cut_length_mm;
    out.engrave_length_mm += j.engrave_length_mm;
    out.travel_length_mm += j.travel_length_mm;
    out.estimated_s += j.estimated_s;
  }
  GcodeWriter g;
  write_header(g, machine, out.bounds);
  std::string text = g.take();
  for (size_t i = 0; i < jobs.size(); ++i) {
    // Notes are comments, which GRBL never sees: kept whole, however long the sheet's name.
    for (const std::string& note : notes[i]) text += "; " + printable(note) + "\n";
    if (i > 0) text += "M0\n";
    // The job's body: what plan_job wrote after its own header (the four lines above). Each
    // body starts with its layer comment and a full G0 X Y, and ends with M5.
    const std::string& gc = jobs[i].gcode;
    size_t at = gc.find("\nG21 G90\n");
    if (at == std::string::npos) throw PlanError("join_jobs: job " + std::to_string(i) + " was not made by plan_job");
    text += gc.substr(at + 9);
  }
  out.gcode = std::move(text);
  return out;
}

}  // namespace atelier::laser

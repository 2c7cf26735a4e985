#include "algorithms/laser/raster.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace atelier::laser {
namespace {

constexpr double kEpsilon = 1e-6;  // mm; rounding at the edges of the work area

// The 8x8 Bayer index matrix (recursive construction of Bayer 1973): every threshold level
// 0..63 once, neighbouring levels far apart, so flat greys become even dot patterns.
constexpr std::array<std::array<int, 8>, 8> kBayer8{{{0, 32, 8, 40, 2, 34, 10, 42},
                                                    {48, 16, 56, 24, 50, 18, 58, 26},
                                                    {12, 44, 4, 36, 14, 46, 6, 38},
                                                    {60, 28, 52, 20, 62, 30, 54, 22},
                                                    {3, 35, 11, 43, 1, 33, 9, 41},
                                                    {51, 19, 59, 27, 49, 17, 57, 25},
                                                    {15, 47, 7, 39, 13, 45, 5, 37},
                                                    {63, 31, 55, 23, 61, 29, 53, 21}}};

int s_of(double pct, double s_max) { return static_cast<int>(std::lround(pct / 100.0 * s_max)); }

void check_power(const PowerSettings& s) {
  if (!(s.s_max > 0)) throw PlanError("s_max must be above 0");
  if (!(s.gamma > 0)) throw PlanError("gamma must be above 0");
  if (!(s.min_power_pct >= 0 && s.min_power_pct <= 100) || !(s.max_power_pct >= 0 && s.max_power_pct <= 100))
    throw PlanError("power must be within 0..100 %");
  if (s.min_power_pct > s.max_power_pct) throw PlanError("min power is above max power");
  if (!(s.threshold >= 0 && s.threshold <= 1)) throw PlanError("threshold must be within 0..1");
}

// Writes G-code lines, repeating no unchanged word (every byte costs streaming time).
class RasterWriter {
 public:
  explicit RasterWriter(double feed) : feed_(format_number(feed)) {}
  void line(const std::string& text) {
    out_ += text;
    out_ += '\n';
  }
  void rapid(double x, double y) {
    std::string xs = format_number(x), ys = format_number(y);
    if (xs == x_ && ys == y_) return;
    std::string t = "G0";
    if (xs != x_) t += " X" + xs;
    if (ys != y_) t += " Y" + ys;
    x_ = xs;
    y_ = ys;
    line(t);
  }
  // Returns false when the move rounds to no motion (nothing written).
  bool scan(double x, int s) {
    std::string xs = format_number(x);
    if (xs == x_) return false;
    std::string t = "G1 X" + xs;
    if (s != s_) t += " S" + std::to_string(s);
    if (!f_written_) t += " F" + feed_;
    f_written_ = true;
    s_ = s;
    x_ = xs;
    line(t);
    return true;
  }
  std::string take() { return std::move(out_); }

 private:
  std::string out_, x_, y_, feed_;
  int s_ = 0;  // after "M4 S0"
  bool f_written_ = false;
};

}  // namespace

const char* dither_name(Dither d) {
  switch (d) {
    case Dither::threshold: return "threshold";
    case Dither::ordered: return "ordered";
    case Dither::floyd_steinberg: return "floyd-steinberg";
    case Dither::jarvis: return "jarvis";
    case Dither::stucki: return "stucki";
    case Dither::greyscale: return "greyscale";
  }
  return "?";
}

std::vector<KernelTap> diffusion_kernel(Dither d) {
  switch (d) {
    case Dither::floyd_steinberg:  // Floyd & Steinberg 1976
      return {{1, 0, 7 / 16.0}, {-1, 1, 3 / 16.0}, {0, 1, 5 / 16.0}, {1, 1, 1 / 16.0}};
    case Dither::jarvis: {  // Jarvis, Judice & Ninke 1976
      std::vector<KernelTap> k{{1, 0, 7}, {2, 0, 5}};
      const int r1[5] = {3, 5, 7, 5, 3}, r2[5] = {1, 3, 5, 3, 1};
      for (int i = 0; i < 5; ++i) k.push_back({i - 2, 1, double(r1[i])});
      for (int i = 0; i < 5; ++i) k.push_back({i - 2, 2, double(r2[i])});
      for (auto& t : k) t.w /= 48;
      return k;
    }
    case Dither::stucki: {  // Stucki 1981
      std::vector<KernelTap> k{{1, 0, 8}, {2, 0, 4}};
      const int r1[5] = {2, 4, 8, 4, 2}, r2[5] = {1, 2, 4, 2, 1};
      for (int i = 0; i < 5; ++i) k.push_back({i - 2, 1, double(r1[i])});
      for (int i = 0; i < 5; ++i) k.push_back({i - 2, 2, double(r2[i])});
      for (auto& t : k) t.w /= 42;
      return k;
    }
    default: return {};
  }
}

Grid<float> darkness(const Grid<uint8_t>& grey, const PowerSettings& s) {
  check_power(s);
  Grid<float> out(grey.cols, grey.rows);
  std::array<float, 256> lut{};
  for (int g = 0; g < 256; ++g) {
    double d = s.negative ? g / 255.0 : 1.0 - g / 255.0;
    lut[static_cast<size_t>(g)] = static_cast<float>(std::pow(d, s.gamma));
  }
  for (size_t i = 0; i < grey.v.size(); ++i) out.v[i] = lut[grey.v[i]];
  return out;
}

Grid<uint8_t> dither(const Grid<float>& dark, Dither d, double threshold) {
  Grid<uint8_t> dots(dark.cols, dark.rows);
  if (d == Dither::threshold || d == Dither::greyscale) {
    for (size_t i = 0; i < dark.v.size(); ++i) dots.v[i] = dark.v[i] > threshold ? 1 : 0;
    return dots;
  }
  if (d == Dither::ordered) {
    for (int r = 0; r < dark.rows; ++r)
      for (int c = 0; c < dark.cols; ++c) {
        const double t = (kBayer8[static_cast<size_t>(r % 8)][static_cast<size_t>(c % 8)] + 0.5) / 64.0;
        dots.at(r, c) = dark.at(r, c) > t ? 1 : 0;
      }
    return dots;
  }
  // Error diffusion: each pixel's quantisation error goes to its unvisited neighbours.
  const std::vector<KernelTap> kernel = diffusion_kernel(d);
  Grid<float> work = dark;
  for (int r = 0; r < work.rows; ++r)
    for (int c = 0; c < work.cols; ++c) {
      const float v = work.at(r, c);
      const uint8_t on = v > 0.5f ? 1 : 0;
      dots.at(r, c) = on;
      const float err = v - static_cast<float>(on);
      for (const KernelTap& t : kernel) {
        const int rr = r + t.dy, cc = c + t.dx;
        if (rr < work.rows && cc >= 0 && cc < work.cols) work.at(rr, cc) += err * static_cast<float>(t.w);
      }
    }
  return dots;
}

Grid<int> power_grid(const Grid<uint8_t>& grey, const PowerSettings& s) {
  const Grid<float> dark = darkness(grey, s);
  Grid<int> power(grey.cols, grey.rows);
  if (s.dither == Dither::greyscale) {
    constexpr float kBlank = 0.5f / 255.0f;  // lighter than half a grey level: not burned
    for (size_t i = 0; i < dark.v.size(); ++i) {
      if (dark.v[i] <= kBlank) continue;
      power.v[i] = s_of(s.min_power_pct + (s.max_power_pct - s.min_power_pct) * dark.v[i], s.s_max);
    }
    return power;
  }
  const Grid<uint8_t> dots = dither(dark, s.dither, s.threshold);
  const int on = s_of(s.max_power_pct, s.s_max);
  for (size_t i = 0; i < dots.v.size(); ++i) power.v[i] = dots.v[i] ? on : 0;
  return power;
}

std::vector<ScanLine> scan_lines(const Grid<int>& power, bool bidirectional) {
  std::vector<ScanLine> lines;
  bool forward = true;
  for (int r = 0; r < power.rows; ++r) {
    int first = -1, last = -1;
    for (int c = 0; c < power.cols; ++c)
      if (power.at(r, c) > 0) {
        if (first < 0) first = c;
        last = c;
      }
    if (first < 0) continue;  // a blank line is not scanned
    ScanLine line;
    line.row = r;
    line.forward = forward;
    for (int c = first; c <= last;) {
      int e = c + 1;
      while (e <= last && power.at(r, e) == power.at(r, c)) ++e;
      line.runs.push_back(Run{c, e, power.at(r, c)});
      c = e;
    }
    if (!forward) std::reverse(line.runs.begin(), line.runs.end());
    lines.push_back(std::move(line));
    if (bidirectional) forward = !forward;
  }
  return lines;
}

double overscan_for(double speed_mm_min, double accel_mm_s2) {
  if (!(accel_mm_s2 > 0)) throw PlanError("acceleration must be above 0");
  const double v = speed_mm_min / 60.0;
  return 1.1 * v * v / (2.0 * accel_mm_s2);
}

RasterJob raster_gcode(const Grid<int>& power, const std::vector<ScanLine>& lines,
                       const RasterPlacement& place, const RasterMotion& motion,
                       const Machine& m, const std::string& comment) {
  if (!(motion.speed_mm_min > 0)) throw PlanError("speed_mm_min must be above 0");
  if (!(motion.overscan_mm >= 0)) throw PlanError("overscan must not be negative");
  if (!(place.dot_mm > 0 && place.line_mm > 0)) throw PlanError("dot and line pitch must be above 0");
  if (!(m.width_mm > 0 && m.height_mm > 0)) throw PlanError("the work area must not be empty");
  if (lines.empty()) throw PlanError("nothing to burn: the image has no pixel dark enough");

  RasterJob job;
  auto x_of = [&](int col) { return place.x_mm + col * place.dot_mm; };
  auto y_of = [&](int row) { return place.y_mm + (power.rows - row - 0.5) * place.line_mm; };
  for (const ScanLine& l : lines) {
    // Runs start and end with a burned pixel (scan_lines keeps no S0 run at either end).
    const int lo = std::min(l.runs.front().col0, l.runs.back().col0);
    const int hi = std::max(l.runs.front().col1, l.runs.back().col1);
    job.bounds.add(Point{x_of(lo), y_of(l.row)});
    job.bounds.add(Point{x_of(hi), y_of(l.row)});
  }
  if (job.bounds.min_x < -kEpsilon || job.bounds.min_y < -kEpsilon ||
      job.bounds.max_x > m.width_mm + kEpsilon || job.bounds.max_y > m.height_mm + kEpsilon) {
    auto range = [](double a, double b) { return format_number(a) + ".." + format_number(b); };
    throw PlanError("the engraving spans X " + range(job.bounds.min_x, job.bounds.max_x) + " mm x Y " +
                    range(job.bounds.min_y, job.bounds.max_y) + " mm, outside the " +
                    format_number(m.width_mm) + " x " + format_number(m.height_mm) +
                    " mm work area (bed coordinates: X from the left edge, Y from the front)");
  }

  RasterWriter g(motion.speed_mm_min);
  g.line("; atelier laser job");
  g.line("; s_max=" + format_number(m.s_max));
  g.line("; bounds=" + format_number(job.bounds.min_x) + "," + format_number(job.bounds.min_y) + "," +
         format_number(job.bounds.max_x) + "," + format_number(job.bounds.max_y));
  g.line("G21 G90");
  if (!comment.empty()) g.line("; " + comment.substr(0, 68));
  g.line("M4 S0");  // dynamic power: the beam follows the actual speed, off while stopped

  Point at{0, 0};
  auto rapid = [&](double x, double y) {
    g.rapid(x, y);
    job.travel_length_mm += std::hypot(x - at.x, y - at.y);
    job.moves.push_back(RasterMove{x, y, 0, true});
    at = Point{x, y};
  };
  auto scan = [&](double x, int s) {
    if (!g.scan(x, s)) return;
    const double len = std::abs(x - at.x);
    job.scan_length_mm += len;
    if (s > 0) {
      job.burn_length_mm += len;
      ++job.burn_moves;
    }
    job.moves.push_back(RasterMove{x, at.y, motion.speed_mm_min, false});
    at.x = x;
  };
  for (const ScanLine& l : lines) {
    const double y = y_of(l.row);
    const double dir = l.forward ? 1 : -1;
    const double first = l.forward ? x_of(l.runs.front().col0) : x_of(l.runs.front().col1);
    const double last = l.forward ? x_of(l.runs.back().col1) : x_of(l.runs.back().col0);
    double lead = first - dir * motion.overscan_mm, tail = last + dir * motion.overscan_mm;
    const double lead_c = std::clamp(lead, 0.0, m.width_mm), tail_c = std::clamp(tail, 0.0, m.width_mm);
    if (lead_c != lead || tail_c != tail) job.overscan_clipped = true;
    rapid(lead_c, y);
    scan(first, 0);
    for (const Run& r : l.runs) scan(l.forward ? x_of(r.col1) : x_of(r.col0), r.s);
    scan(tail_c, 0);
    ++job.scanned_rows;
  }
  g.line("M5");
  job.gcode = g.take();
  return job;
}

}  // namespace atelier::laser

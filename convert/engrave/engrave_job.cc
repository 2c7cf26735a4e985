#include "convert/engrave/engrave_job.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "algorithms/laser/motion_planner.h"
#include "algorithms/laser/raster.h"
#include "convert/common/display_text.h"
#include "convert/common/image_input.h"
#include "convert/common/output_files.h"
#include "convert/engrave/engrave_params.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;

constexpr int kMaxGridPx = 20000;       // per side: 5000 mm at 0.25 mm, or 500 mm at 1000 dpi
constexpr double kLinkBytesPerS = 11520;  // 115200 baud, 8N1: GRBL's serial link
constexpr double kFinePxPerMm = 40;    // preview drawing resolution before averaging down
constexpr double kMaxFinePx = 1.5e8;   // bytes of the fine drawing, at most

double round3(double v) { return std::round(v * 1000) / 1000; }

// 8-bit grey; transparent parts count as white (unburned), as LightBurn shows them.
cv::Mat grey_of(const cv::Mat& loaded, const std::string& name) {
  if (loaded.channels() == 2 || loaded.channels() > 4)
    throw ConvertError(name + ": expected a grey, colour or colour+alpha image");
  cv::Mat img = to_8bit(loaded);
  cv::Mat grey;
  if (img.channels() == 4) {
    cv::Mat bgr, alpha;
    cv::cvtColor(img, bgr, cv::COLOR_BGRA2BGR);
    cv::extractChannel(img, alpha, 3);
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    cv::Mat a, g;
    alpha.convertTo(a, CV_32F, 1 / 255.0);
    grey.convertTo(g, CV_32F);
    g = g.mul(a) + 255.0f * (1.0f - a);
    g.convertTo(grey, CV_8U);
  } else if (img.channels() == 3) {
    cv::cvtColor(img, grey, cv::COLOR_BGR2GRAY);
  } else {
    grey = img;
  }
  return grey;
}

laser::Grid<uint8_t> grid_of(const cv::Mat& grey) {
  laser::Grid<uint8_t> g(grey.cols, grey.rows);
  for (int r = 0; r < grey.rows; ++r) std::copy_n(grey.ptr<uint8_t>(r), grey.cols, &g.at(r, 0));
  return g;
}

// See engrave_job.h. Drawn at kFinePxPerMm (a 0.2 mm spot is 8 px there), then
// averaged down to the output dpi, so the dot gain of the round spot shows as it will burn.
cv::Mat render_preview(const std::vector<laser::ScanLine>& lines,
                       const laser::RasterPlacement& place, double s_max, double spot_mm, double width_mm,
                       double height_mm, double dpi) {
  const double ppm = dpi / 25.4;
  const int cols = std::max(1, static_cast<int>(std::lround(width_mm * ppm)));
  const int rows = std::max(1, static_cast<int>(std::lround(height_mm * ppm)));
  int k = std::max(1, static_cast<int>(std::lround(kFinePxPerMm / ppm)));
  while (k > 1 && static_cast<double>(cols) * rows * k * k > kMaxFinePx) --k;
  const double fine = ppm * k;
  cv::Mat big(rows * k, cols * k, CV_8U, cv::Scalar(255));
  struct Stroke {
    int s;
    cv::Point a, b;
  };
  constexpr int kShift = 4;  // sub-pixel endpoints
  auto px = [&](double mm) { return static_cast<int>(std::lround(mm * fine * (1 << kShift))); };
  std::vector<Stroke> strokes;
  for (const laser::ScanLine& l : lines) {
    const int y = px((l.row + 0.5) * place.line_mm);
    for (const laser::Run& r : l.runs)
      if (r.s > 0) strokes.push_back({r.s, {px(r.col0 * place.dot_mm), y}, {px(r.col1 * place.dot_mm), y}});
  }
  // Weakest first: where spots overlap, the strongest burn shows.
  std::stable_sort(strokes.begin(), strokes.end(), [](const Stroke& a, const Stroke& b) { return a.s < b.s; });
  const int thickness = std::max(1, static_cast<int>(std::lround(spot_mm * fine)));
  for (const Stroke& st : strokes) {
    const double grey = 200.0 * (1.0 - std::min(1.0, st.s / s_max));
    cv::line(big, st.a, st.b, cv::Scalar(grey), thickness, cv::LINE_8, kShift);
  }
  cv::Mat out;
  cv::resize(big, out, cv::Size(cols, rows), 0, 0, cv::INTER_AREA);
  return out;
}

// GRBL's planner model (contract D) with the [laser] motion settings: both axes at the
// travel rate and acceleration, the junction deviation as given.
double estimate_seconds(const std::vector<laser::RasterMove>& moves, const laser::Machine& m) {
  laser::MotionSettings ms;
  ms.max_rate_mm_min[0] = ms.max_rate_mm_min[1] = m.travel_mm_min;
  ms.accel_mm_s2[0] = ms.accel_mm_s2[1] = m.accel_mm_s2;
  ms.junction_deviation_mm = m.junction_deviation_mm;
  std::vector<laser::PlannedMove> planned;
  planned.reserve(moves.size());
  for (const laser::RasterMove& mv : moves) {
    laser::PlannedMove p;
    p.target = {mv.x, mv.y, 0};
    p.feed_mm_min = mv.feed_mm_min;
    p.rapid = mv.rapid;
    planned.push_back(p);
  }
  double total = 0;
  for (double s : laser::move_seconds(planned, ms)) total += s;
  return total;
}

}  // namespace

ConvertResult convert_engrave(const ConvertRequest& req) {
  const EngraveParams p = read_engrave_params(req.params, req.params_source);
  const laser::Machine& m = p.laser.machine;
  const std::string name = safe_text(req.input.filename().string());  // names are data
  report_progress(req, 0.0);

  const cv::Mat grey = grey_of(load_image(req.input, req.limits), name);
  const double dot_mm = 25.4 / p.dpi;
  const double height_mm = p.width_mm * grey.rows / grey.cols;
  const int cols = std::max(1, static_cast<int>(std::lround(p.width_mm / dot_mm)));
  const int rows = std::max(1, static_cast<int>(std::lround(height_mm / p.line_interval_mm)));
  if (cols > kMaxGridPx || rows > kMaxGridPx)
    throw ConvertError(name + ": " + std::to_string(cols) + " x " + std::to_string(rows) +
                       " dots is more than " + std::to_string(kMaxGridPx) +
                       " per side; lower dpi or width_mm, or raise line_interval_mm");
  cv::Mat sized;
  // Area averaging when shrinking (no aliasing of fine texture), cubic when enlarging.
  const bool shrink = cols < grey.cols || rows < grey.rows;
  cv::resize(grey, sized, cv::Size(cols, rows), 0, 0, shrink ? cv::INTER_AREA : cv::INTER_CUBIC);
  report_progress(req, 0.2);

  laser::PowerSettings ps;
  ps.dither = p.dither;
  ps.min_power_pct = p.min_power_pct;
  ps.max_power_pct = p.max_power_pct;
  ps.gamma = p.gamma;
  ps.negative = p.negative;
  ps.threshold = p.threshold;
  ps.s_max = m.s_max;
  laser::RasterPlacement place;
  place.x_mm = p.position_x_mm;
  place.y_mm = p.position_y_mm;
  place.dot_mm = dot_mm;
  place.line_mm = p.line_interval_mm;
  laser::RasterMotion motion;
  motion.speed_mm_min = p.speed_mm_min;
  motion.overscan_mm = p.overscan_mm > 0 ? p.overscan_mm : laser::overscan_for(p.speed_mm_min, m.accel_mm_s2);

  laser::Grid<int> power;
  std::vector<laser::ScanLine> lines;
  laser::RasterJob job;
  double estimated_s = 0;
  try {
    power = laser::power_grid(grid_of(sized), ps);
    lines = laser::scan_lines(power, p.bidirectional);
    report_progress(req, 0.5);
    const std::string comment = std::string("engrave ") + laser::dither_name(p.dither) + " " +
                                laser::format_number(p.dpi) + "dpi " + laser::format_number(p.speed_mm_min) +
                                "mm/min " + laser::format_number(p.min_power_pct) + "-" +
                                laser::format_number(p.max_power_pct) + "%";
    job = laser::raster_gcode(power, lines, place, motion, m, comment);
    estimated_s = estimate_seconds(job.moves, m);
  } catch (const laser::PlanError& e) {
    throw ConvertError(name + ": " + e.what());
  }
  report_progress(req, 0.7);

  std::error_code ec;
  fs::create_directories(req.output_dir, ec);
  if (ec) throw ConvertError(req.output_dir.string() + ": cannot create output folder: " + ec.message());
  const fs::path& out = req.output_dir;
  write_output(out / kEngraveGcodeFile, job.gcode);
  const cv::Mat preview =
      render_preview(lines, place, m.s_max, p.spot_mm, p.width_mm, rows * p.line_interval_mm, p.dpi);
  write_output_png(out / "preview.png", preview);
  report_progress(req, 0.9);

  ConvertResult result;
  result.outputs = {kEngraveGcodeFile, "preview.png", "report.json"};
  const auto gcode_lines = std::count(job.gcode.begin(), job.gcode.end(), '\n');
  const double burn_s = job.scan_length_mm / p.speed_mm_min * 60;  // at the feed, every G1
  nlohmann::ordered_json r;
  r["kind"] = "engrave";
  r["input"] = {{"file", name}, {"width_px", grey.cols}, {"height_px", grey.rows}};
  r["dither"] = laser::dither_name(p.dither);
  r["dpi"] = p.dpi;
  r["line_interval_mm"] = p.line_interval_mm;
  r["spot_mm"] = p.spot_mm;
  r["size_mm"] = {round3(p.width_mm), round3(rows * p.line_interval_mm)};
  r["position_mm"] = {p.position_x_mm, p.position_y_mm};
  r["grid"] = {{"cols", cols}, {"rows", rows}};
  r["power_pct"] = {{"min", p.min_power_pct}, {"max", p.max_power_pct}};
  r["gamma"] = p.gamma;
  r["negative"] = p.negative;
  r["bidirectional"] = p.bidirectional;
  r["speed_mm_min"] = p.speed_mm_min;
  r["overscan_mm"] = round3(motion.overscan_mm);
  r["overscan_clipped"] = job.overscan_clipped;
  r["scanned_rows"] = job.scanned_rows;
  r["burn_moves"] = job.burn_moves;
  r["burn_length_mm"] = round3(job.burn_length_mm);
  r["scan_length_mm"] = round3(job.scan_length_mm);
  r["travel_length_mm"] = round3(job.travel_length_mm);
  r["estimated_time_s"] = round3(estimated_s);
  r["bounds_mm"] = {{"min_x", round3(job.bounds.min_x)},
                    {"min_y", round3(job.bounds.min_y)},
                    {"max_x", round3(job.bounds.max_x)},
                    {"max_y", round3(job.bounds.max_y)}};
  r["coordinates"] = "bed";  // X from the bed's left edge, Y from its front edge
  r["work_area_mm"] = {m.width_mm, m.height_mm};
  r["s_max"] = m.s_max;
  r["gcode_lines"] = gcode_lines;
  r["gcode_bytes"] = job.gcode.size();
  // What streaming must carry while the head scans at the feed: GRBL's 115200 baud link moves
  // 11520 bytes/s; above that (or above GRBL's planner rate) the head would starve and slow.
  r["stream"] = {{"lines_per_s", round3(burn_s > 0 ? gcode_lines / burn_s : 0)},
                 {"bytes_per_s", round3(burn_s > 0 ? job.gcode.size() / burn_s : 0)},
                 {"link_bytes_per_s", kLinkBytesPerS}};
  r["preview_px_per_mm"] = round3(p.dpi / 25.4);
  r["outputs"] = result.outputs;
  return finish_report(req, out, r, std::move(result));
}

}  // namespace atelier

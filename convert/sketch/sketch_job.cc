#include "convert/sketch/sketch_job.h"

#include "convert/common/display_text.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "algorithms/laser/plan.h"
#include "algorithms/pencil/hatching.h"
#include "algorithms/pencil/sketch.h"
#include "algorithms/pencil/strokes.h"
#include "convert/common/output_files.h"
#include "convert/sketch/pencil_profile_file.h"
#include "convert/sketch/sketch_params.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr int kMaxDrawingPx = 4096;          // longer side of the preview
constexpr const char* kGraphite = "#3c3c3c";  // lines.svg stroke and the engrave layer's colour
constexpr double kSvgTolerancePx = 0.25;      // drawing px: simplification of lines.svg paths

double round3(double v) { return std::round(v * 1000) / 1000; }
double ms_since(Clock::time_point t) {
  return round3(std::chrono::duration<double, std::milli>(Clock::now() - t).count());
}

// An 8-bit grey, BGR or BGRA image, as the stroke finder takes it. Decoders give 16-bit PNGs and
// TIFFs as 0..65535 and float TIFFs as 0..1 (a float drawing read as 0/1 grey levels was all
// black: no edges, and hatched all over).
cv::Mat eight_bit(const cv::Mat& image, const std::string& name) {
  if (image.channels() == 2 || image.channels() > 4)
    throw ConvertError(name + ": expected a grey, colour or colour+alpha image");
  const int depth = image.depth();
  if (depth != CV_8U && depth != CV_16U && depth != CV_32F && depth != CV_64F)
    throw ConvertError(name + ": expected 8- or 16-bit or floating-point pixels");
  return to_8bit(image);
}

// Douglas-Peucker (cv::approxPolyDP takes float points; drawing px and mm fit them well).
std::vector<cv::Point2d> simplified(const std::vector<cv::Point2d>& path, double tolerance) {
  if (path.size() <= 2) return path;
  std::vector<cv::Point2f> in(path.begin(), path.end()), out;
  cv::approxPolyDP(in, out, tolerance, false);
  return {out.begin(), out.end()};
}

double path_length(const std::vector<cv::Point2d>& path) {
  double len = 0;
  for (size_t i = 1; i < path.size(); ++i) len += cv::norm(path[i] - path[i - 1]);
  return len;
}

// Mean grey level of the pencil's line pixels, 0..255.
double mean_grey(const pencil::PencilProfile& p) {
  double sum = 0, weight = 0;
  for (size_t i = 0; i < p.hist.size(); ++i) {
    sum += static_cast<double>(i) * p.hist[i];
    weight += p.hist[i];
  }
  return weight > 0 ? sum / weight : 255.0;
}

std::string svg_path_data(const std::vector<cv::Point2d>& path) {
  std::ostringstream d;
  for (size_t i = 0; i < path.size(); ++i)
    d << (i ? " L" : "M") << laser::format_number(path[i].x) << ' ' << laser::format_number(path[i].y);
  return d.str();
}

// A name inside an XML comment: valid UTF-8, no "--" (which would end or break the comment).
std::string comment_safe(const std::string& s) {
  std::string out = safe_text(s);
  for (size_t at; (at = out.find("--")) != std::string::npos;) out.replace(at, 2, "- -");
  return out;
}

std::string lines_svg(const pencil::SketchDrawing& drawing, double width_mm, double stroke_px,
                      const std::string& pencil) {
  const int w = drawing.canvas.cols, h = drawing.canvas.rows;
  std::ostringstream s;
  s << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << laser::format_number(width_mm)
    << "mm\" height=\"" << laser::format_number(width_mm * h / w) << "mm\" viewBox=\"0 0 " << w << ' '
    << h << "\">\n"
    << "<!-- atelier sketch: hand-drawn pencil lines (" << comment_safe(pencil) << "), drawing px -->\n";
  for (bool hatch : {false, true}) {
    s << "<g id=\"" << (hatch ? "hatching" : "strokes") << "\" fill=\"none\" stroke=\"" << kGraphite
      << "\" stroke-width=\"" << laser::format_number(stroke_px)
      << "\" stroke-linecap=\"round\" stroke-linejoin=\"round\">\n";
    for (const auto& line : drawing.lines)
      if (line.hatch == hatch && line.path.size() >= 2)
        s << "<path d=\"" << svg_path_data(simplified(line.path, kSvgTolerancePx)) << "\"/>\n";
    s << "</g>\n";
  }
  s << "</svg>\n";
  return s.str();
}

// The parts of `path` (drawing px) inside [0, cols] x [0, rows]: a hand-drawn line near the
// drawing's edge may wander past it, which the preview clips and the engraving must too (else a
// drawing placed at the bed's edge leaves the work area). cv::clipLine takes integer points:
// 1/1024 px is far finer than the laser's tolerance.
std::vector<std::vector<cv::Point2d>> clipped_to(const std::vector<cv::Point2d>& path, int cols, int rows) {
  constexpr double kFixed = 1024;
  const cv::Size2l box(static_cast<int64_t>(cols * kFixed) + 1, static_cast<int64_t>(rows * kFixed) + 1);
  auto fixed = [](cv::Point2d q) {
    return cv::Point2l(std::llround(q.x * kFixed), std::llround(q.y * kFixed));
  };
  std::vector<std::vector<cv::Point2d>> parts;
  bool open = false;  // the last part ends at the previous point
  for (size_t i = 1; i < path.size(); ++i) {
    cv::Point2l a = fixed(path[i - 1]), b = fixed(path[i]);
    const cv::Point2l b0 = b;
    if (!cv::clipLine(box, a, b)) {
      open = false;
      continue;
    }
    if (!open) parts.push_back({cv::Point2d(a.x / kFixed, a.y / kFixed)});
    parts.back().emplace_back(b.x / kFixed, b.y / kFixed);
    open = b == b0;  // the segment ended inside, so the next one continues this part
  }
  return parts;
}

// The drawing's paths in design mm (x right, y down from the bed's rear-left corner), clipped
// to the drawing (width_mm wide at position_mm).
laser::Layer engrave_layer(const pencil::SketchDrawing& drawing, const SketchParams& p,
                           const std::string& pencil, double power_pct) {
  laser::Layer layer;
  layer.settings.name = "pencil " + pencil;
  layer.settings.color = kGraphite;
  layer.settings.mode = laser::Mode::engrave;
  layer.settings.speed_mm_min = p.speed_mm_min;
  layer.settings.power_pct = power_pct;
  layer.settings.passes = 1;
  const double mm_per_px = p.width_mm / drawing.canvas.cols;
  for (const auto& line : drawing.lines) {
    for (const auto& part : clipped_to(line.path, drawing.canvas.cols, drawing.canvas.rows)) {
      std::vector<cv::Point2d> mm;
      mm.reserve(part.size());
      for (const auto& q : part)
        mm.emplace_back(p.position_x_mm + q.x * mm_per_px, p.position_y_mm + q.y * mm_per_px);
      laser::Path path;
      for (const auto& q : simplified(mm, p.laser.tolerance_mm)) path.points.push_back({q.x, q.y});
      if (path.points.size() >= 2) layer.paths.push_back(std::move(path));
    }
  }
  return layer;
}

}  // namespace

ConvertResult convert_sketch(const ConvertRequest& req) {
  const Clock::time_point start = Clock::now();
  const SketchParams p = read_sketch_params(req.params, req.params_source);
  const std::string name = safe_text(req.input.filename().string());  // names are data
  report_progress(req, 0.0);

  const pencil::PencilProfile profile = open_pencil(
      p.pencil, req.paths.access("pencil"),
      req.paths.from_job("pencil") ? req.paths.source_of("pencil") : req.params_source);
  const cv::Mat image = eight_bit(load_image(req.input, req.limits), name);

  Clock::time_point t = Clock::now();
  pencil::StrokeParams sp;
  sp.smoothing_px = p.smoothing_px;
  sp.canny_low = p.canny_low;
  sp.canny_high = p.canny_high;
  sp.simplify_px = p.simplify_px;
  sp.min_stroke_px = p.min_stroke_px;
  std::vector<pencil::Segment> strokes = pencil::edge_strokes(image, sp);
  std::vector<pencil::Segment> hatching;
  if (p.hatching) {
    pencil::HatchParams hp;
    hp.dark_level = p.hatch_level;
    hp.cross_level = std::min(p.cross_level, p.hatch_level);
    hp.spacing_px = p.hatch_spacing_px;
    hp.angle_deg = p.hatch_angle_deg;
    hatching = pencil::hatch_lines(image, hp);
  }
  const size_t found_strokes = strokes.size(), found_hatching = hatching.size();
  pencil::keep_longest(&strokes, &hatching, static_cast<size_t>(p.max_lines));
  if (strokes.empty() && hatching.empty()) {
    throw ConvertError(name + ": nothing to draw: no edge stroke of at least " +
                       laser::format_number(p.min_stroke_px) + " px was found" +
                       (p.hatching ? " and nothing is dark enough to hatch" : "") +
                       " (a blank image? try a lower min_stroke_px or canny thresholds)");
  }
  const double edges_ms = ms_since(t);
  report_progress(req, 0.1);

  const double scale =
      std::min(p.scale, static_cast<double>(kMaxDrawingPx) / std::max(image.cols, image.rows));
  t = Clock::now();
  pencil::PathParams path_params;
  path_params.squiggle = p.squiggle;
  const pencil::SketchDrawing drawing = pencil::draw_sketch(
      image.size(), scale, strokes, hatching, path_params, profile, p.seed,
      [&req](double f) { report_progress(req, 0.1 + 0.7 * f); });
  const double draw_ms = ms_since(t);

  const double power = p.power_pct > 0 ? p.power_pct
                                       : std::clamp(std::round(100 * (1 - mean_grey(profile) / 255)), 1.0, 100.0);
  laser::Job job;
  try {
    job = laser::plan_job({engrave_layer(drawing, p, profile.name, power)}, p.laser.machine);
  } catch (const laser::PlanError& e) {
    throw ConvertError(name + ": engraving " + laser::format_number(p.width_mm) + " mm wide at (" +
                       laser::format_number(p.position_x_mm) + ", " +
                       laser::format_number(p.position_y_mm) + ") mm: " + e.what());
  }
  report_progress(req, 0.9);

  std::error_code ec;
  fs::create_directories(req.output_dir, ec);
  if (ec) throw ConvertError(req.output_dir.string() + ": cannot create output folder: " + ec.message());
  const fs::path& out = req.output_dir;
  write_output_png(out / "preview.png", drawing.canvas);
  write_output(out / "lines.svg", lines_svg(drawing, p.width_mm, profile.width_px, profile.name));
  write_output(out / kSketchGcodeFile, job.gcode);

  ConvertResult result;
  result.outputs = {"preview.png", "lines.svg", kSketchGcodeFile, "report.json"};
  double drawn_px = 0;
  size_t points = 0;
  for (const auto& line : drawing.lines) {
    drawn_px += path_length(line.path);
    points += line.path.size();
  }
  nlohmann::ordered_json r;
  r["kind"] = "sketch";
  r["input"] = {{"file", name}, {"width_px", image.cols}, {"height_px", image.rows}};
  r["pencil"] = {{"name", safe_text(profile.name)},
                 {"source", p.pencil},
                 {"width_px", round3(profile.width_px)},
                 {"mean_grey", round3(mean_grey(profile))}};
  r["parameters"] = {{"squiggle", p.squiggle},         {"seed", p.seed},
                     {"min_stroke_px", p.min_stroke_px}, {"smoothing_px", p.smoothing_px},
                     {"canny_low", p.canny_low},         {"canny_high", p.canny_high},
                     {"simplify_px", p.simplify_px},     {"max_lines", p.max_lines},
                     {"hatching", p.hatching}};
  r["scale"] = round3(scale);
  r["strokes"] = strokes.size();
  r["hatch_lines"] = hatching.size();
  r["dropped_lines"] = (found_strokes - strokes.size()) + (found_hatching - hatching.size());
  r["lines"] = drawing.lines.size();
  r["path_points"] = points;
  r["drawn_length_px"] = round3(drawn_px);
  r["drawing_px"] = {drawing.canvas.cols, drawing.canvas.rows};
  r["engrave"] = {{"width_mm", p.width_mm},
                  {"height_mm", round3(p.width_mm * drawing.canvas.rows / drawing.canvas.cols)},
                  {"position_mm", {p.position_x_mm, p.position_y_mm}},
                  {"power_pct", power},
                  {"power_from", p.power_pct > 0 ? "power_pct" : "pencil"},
                  {"speed_mm_min", p.speed_mm_min},
                  {"paths", job.layers.empty() ? 0 : job.layers[0].paths},
                  {"length_mm", round3(job.engrave_length_mm)},
                  {"travel_mm", round3(job.travel_length_mm)},
                  {"estimated_time_s", round3(job.estimated_s)},
                  {"gcode_lines", std::count(job.gcode.begin(), job.gcode.end(), '\n')},
                  {"bounds_mm",
                   {round3(job.bounds.min_x), round3(job.bounds.min_y), round3(job.bounds.max_x),
                    round3(job.bounds.max_y)}}};
  r["work_area_mm"] = {p.laser.machine.width_mm, p.laser.machine.height_mm};
  r["timings_ms"] = {{"edges", edges_ms}, {"drawing", draw_ms}, {"total", ms_since(start)}};
  r["outputs"] = result.outputs;
  return finish_report(req, out, r, std::move(result));
}

}  // namespace atelier

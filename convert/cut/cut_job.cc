#include "convert/cut/cut_job.h"

#include "convert/common/display_text.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/laser/plan.h"
#include "convert/common/output_files.h"
#include "convert/common/param_table.h"
#include "convert/common/svg_paths.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;

constexpr double kPreviewPxPerMm = 10;
constexpr double kPreviewMarginMm = 5;
constexpr int kPreviewMaxPx = 8000;  // keeps a full-bed preview of a big machine in memory

double round3(double v) { return std::round(v * 1000) / 1000; }

cv::Scalar bgr(const std::string& hex) {
  unsigned rgb = static_cast<unsigned>(std::stoul(hex.substr(1), nullptr, 16));
  return cv::Scalar(rgb & 0xff, (rgb >> 8) & 0xff, (rgb >> 16) & 0xff);
}

struct Preview {
  cv::Mat image;
  double px_per_mm = kPreviewPxPerMm;
};

// Bed coordinates have X right and Y towards the rear, so the image
// shows the bed as seen from above with the front at the bottom.
Preview render_preview(const laser::Job& job, const laser::Machine& m) {
  laser::Bounds view = job.bounds;
  view.min_x -= kPreviewMarginMm;
  view.min_y -= kPreviewMarginMm;
  view.max_x += kPreviewMarginMm;
  view.max_y += kPreviewMarginMm;
  Preview p;
  double w_mm = view.max_x - view.min_x, h_mm = view.max_y - view.min_y;
  p.px_per_mm = std::min(kPreviewPxPerMm, kPreviewMaxPx / std::max(w_mm, h_mm));
  const double s = p.px_per_mm;
  const int cols = std::max(1, static_cast<int>(std::ceil(w_mm * s)));
  const int rows = std::max(1, static_cast<int>(std::ceil(h_mm * s)));
  p.image = cv::Mat(rows, cols, CV_8UC3, cv::Scalar(200, 200, 200));

  constexpr int kShift = 4;  // sub-pixel precision for the drawing calls
  auto px = [&](laser::Point q) {
    return cv::Point(static_cast<int>(std::lround((q.x - view.min_x) * s * (1 << kShift))),
                     static_cast<int>(std::lround((view.max_y - q.y) * s * (1 << kShift))));
  };
  // The work area in bed coordinates: [0, width] x [0, height].
  laser::Point area_lo{0, 0};
  laser::Point area_hi{area_lo.x + m.width_mm, area_lo.y + m.height_mm};
  cv::rectangle(p.image, px({area_lo.x, area_hi.y}), px({area_hi.x, area_lo.y}),
                cv::Scalar(255, 255, 255), cv::FILLED, cv::LINE_8, kShift);

  const int thickness = std::max(1, static_cast<int>(std::lround(0.2 * s)));
  for (const auto& layer : job.toolpaths) {
    cv::Scalar colour = bgr(layer.settings.color);
    for (const auto& path : layer.paths) {
      std::vector<cv::Point> pts;
      pts.reserve(path.points.size());
      for (auto q : path.points) pts.push_back(px(q));
      cv::polylines(p.image, pts, path.closed, colour, thickness, cv::LINE_AA, kShift);
    }
  }
  return p;
}

std::string shape_count(size_t n) {
  return std::to_string(n) + (n == 1 ? " shape" : " shapes");
}

std::string configured_colours(const LaserParams& p) {
  std::string list;
  for (const auto& l : p.layers)
    list += (list.empty() ? "" : ", ") + l.color + " (" + l.name + ")";
  return list;
}


}  // namespace

CutParams read_cut_params(const toml::table& params, const std::string& source) {
  TableReader r(params, source, "");
  CutParams p;
  if (const toml::table* laser = r.get_table("laser")) {
    p.laser = read_laser_params(*laser, source);
  } else {
    p.laser = read_laser_params(toml::table{}, source);
  }
  r.finish();
  return p;
}

ConvertResult convert_cut(const ConvertRequest& req) {
  const CutParams p = read_cut_params(req.params, req.params_source);
  const LaserParams& lp = p.laser;
  const std::string input_name = safe_text(req.input.filename().string());  // names are data
  report_progress(req, 0.0);

  SvgDrawing drawing = read_svg(req.input, lp.tolerance_mm, req.limits.max_file_bytes);
  report_progress(req, 0.3);

  // Stroke colour -> layer, in the configured order.
  std::vector<laser::Layer> layers;
  for (const auto& s : lp.layers) layers.push_back(laser::Layer{s, {}});
  size_t unstroked = 0;
  std::map<std::string, size_t> unmapped;  // colour -> shapes
  for (auto& shape : drawing.shapes) {
    if (shape.stroke.empty()) {
      ++unstroked;
      continue;
    }
    auto it = std::find_if(layers.begin(), layers.end(), [&](const laser::Layer& l) {
      return l.settings.color == shape.stroke;
    });
    if (it == layers.end()) {
      ++unmapped[shape.stroke];
      continue;
    }
    for (auto& path : shape.paths) it->paths.push_back(std::move(path));
  }
  if (!unmapped.empty()) {
    std::string what;
    for (const auto& [colour, n] : unmapped)
      what += (what.empty() ? "" : ", ") + colour + " (" + shape_count(n) + ")";
    throw ConvertError(input_name + ": no laser layer for the stroke colour " + what +
                       "; configured layers: " + configured_colours(lp) +
                       ". Add a [[laser.layer]] with that color or recolour the shapes.");
  }
  std::erase_if(layers, [](const laser::Layer& l) { return l.paths.empty(); });
  if (layers.empty()) {
    throw ConvertError(input_name + ": nothing to burn: no shape has a stroke" +
                       (unstroked ? " (" + shape_count(unstroked) +
                                        " only filled or invisible; the laser follows strokes)"
                                  : std::string(" (the drawing has no shapes)")));
  }

  laser::Job job;
  try {
    job = laser::plan_job(layers, lp.machine);
  } catch (const laser::PlanError& e) {
    throw ConvertError(input_name + ": " + e.what());
  }
  report_progress(req, 0.6);

  std::error_code ec;
  fs::create_directories(req.output_dir, ec);
  if (ec) {
    throw ConvertError(req.output_dir.string() + ": cannot create output folder: " + ec.message());
  }
  const fs::path& out = req.output_dir;
  write_output(out / kCutGcodeFile, job.gcode);

  Preview preview = render_preview(job, lp.machine);
  write_output_png(out / "preview.png", preview.image);
  report_progress(req, 0.9);

  ConvertResult result;
  result.outputs = {kCutGcodeFile, "preview.png", "report.json"};
  nlohmann::ordered_json r;
  r["kind"] = "cut";
  r["input"] = {{"file", input_name}};
  nlohmann::ordered_json layer_list = nlohmann::ordered_json::array();
  for (size_t i = 0; i < job.layers.size(); ++i) {
    const laser::LayerStats& st = job.layers[i];
    const laser::LayerSettings& s = job.toolpaths[i].settings;
    layer_list.push_back({{"name", st.name},
                          {"color", s.color},
                          {"mode", laser::mode_name(st.mode)},
                          {"paths", st.paths},
                          {"length_mm", round3(st.length_mm)},
                          {"passes", st.passes},
                          {"speed_mm_min", s.speed_mm_min},
                          {"power_pct", s.power_pct},
                          {"kerf_mm", s.kerf_mm},
                          {"time_s", round3(st.time_s)},
                          {"vanished_holes", st.vanished_holes}});
  }
  r["layers"] = layer_list;
  r["cut_length_mm"] = round3(job.cut_length_mm);
  r["engrave_length_mm"] = round3(job.engrave_length_mm);
  r["travel_length_mm"] = round3(job.travel_length_mm);
  r["estimated_time_s"] = round3(job.estimated_s);
  r["bounds_mm"] = {{"min_x", round3(job.bounds.min_x)},
                    {"min_y", round3(job.bounds.min_y)},
                    {"max_x", round3(job.bounds.max_x)},
                    {"max_y", round3(job.bounds.max_y)}};
  r["work_area_mm"] = {lp.machine.width_mm, lp.machine.height_mm};
  r["coordinates"] = "bed";  // X from the bed's left edge, Y from its front edge
  r["s_max"] = lp.machine.s_max;
  r["ignored_unstroked"] = unstroked;
  // e.g. {"text": 2}: convert text to paths (Inkscape: Path > Object to Path) to burn it.
  r["ignored_elements"] = drawing.unburned;
  r["source"] = {{"width_mm", round3(drawing.width_mm)}, {"height_mm", round3(drawing.height_mm)}};
  r["gcode_lines"] = std::count(job.gcode.begin(), job.gcode.end(), '\n');
  r["preview_px_per_mm"] = round3(preview.px_per_mm);
  r["outputs"] = result.outputs;
  return finish_report(req, out, r, std::move(result));
}

}  // namespace atelier

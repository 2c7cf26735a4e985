#include "convert/sketch/line_job.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "algorithms/pencil/path.h"
#include "algorithms/pencil/texture.h"
#include "convert/common/output_files.h"
#include "convert/common/display_text.h"
#include "convert/common/param_table.h"
#include "convert/sketch/pencil_profile_file.h"

namespace atelier {

namespace {

// "X,Y" or [X, Y]; finite and within kLineMaxCoordinate.
cv::Point2d read_point(TableReader& r, const toml::table& t, const std::string& key) {
  const toml::node* n = t.get(key);
  if (!n) {
    r.get_string(key, "");  // marks the key as read for finish()
    r.fail(key, "missing: give the end point as \"X,Y\" (px)");
  }
  double xy[2];
  if (n->is_array()) {
    const toml::array* a = r.get_array(key);
    if (a->size() != 2) r.fail(key, "expected [X, Y]");
    for (int i = 0; i < 2; ++i) {
      const toml::node& e = *a->get(static_cast<size_t>(i));
      if (auto d = e.value_exact<double>()) xy[i] = *d;
      else if (auto v = e.value_exact<int64_t>()) xy[i] = static_cast<double>(*v);
      else r.fail(key, "expected [X, Y] numbers");
    }
  } else if (n->is_string()) {
    const std::string s = r.get_string(key, "");
    std::istringstream in(s);
    char comma = 0;
    std::string rest;
    if (!(in >> xy[0]) || !(in >> comma) || comma != ',' || !(in >> xy[1]) || (in >> rest))
      r.fail(key, "'" + display_value(s) + "' is not \"X,Y\" (two numbers, px)");
  } else {
    r.fail(key, "expected \"X,Y\" or [X, Y] (px)");
  }
  for (double v : xy) {
    if (!std::isfinite(v) || std::abs(v) > kLineMaxCoordinate) {
      std::ostringstream msg;
      msg << "coordinate " << v << " is outside [-" << kLineMaxCoordinate << ", " << kLineMaxCoordinate << "]";
      r.fail(key, msg.str());
    }
  }
  return {xy[0], xy[1]};
}

double r3(double v) { return std::round(v * 1000.0) / 1000.0; }

nlohmann::json points_json(const std::vector<cv::Point2d>& pts) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& p : pts) a.push_back({r3(p.x), r3(p.y)});
  return a;
}

}  // namespace

LineParams read_line_params(const toml::table& params, const std::string& source) {
  TableReader r(params, source, "");
  LineParams p;
  p.from = read_point(r, params, "from");
  p.to = read_point(r, params, "to");
  p.pencil = r.get_string("pencil", p.pencil);
  if (p.pencil.empty()) r.fail("pencil", "must name a pencil (2H .. 8B) or a .toml profile");
  p.squiggle = r.get_double("squiggle", p.squiggle, 0.0, 100.0);
  p.seed = static_cast<std::uint64_t>(r.get_int("seed", 1, 0, std::numeric_limits<int64_t>::max()));
  p.margin_px = static_cast<int>(r.get_int("margin", p.margin_px, 0, 1000));
  r.finish();
  return p;
}

ConvertResult convert_line(const toml::table& params, const std::string& source, const std::filesystem::path& out,
                           const ImageLimits& limits) {
  const auto start = std::chrono::steady_clock::now();
  const LineParams p = read_line_params(params, source);
  const toml::node* pencil_node = params.get("pencil");
  const pencil::PencilProfile profile =
      resolve_pencil(p.pencil, pencil_node ? param_base_dir(*pencil_node) : std::filesystem::path{}, source);

  pencil::PathParams pp;
  pp.squiggle = p.squiggle;
  const pencil::HumanPath line = pencil::human_path(p.from, p.to, pp, p.seed);

  // The canvas: the path's bounding box, its half width and the margin, on whole pixels.
  double x0 = line.path.front().x, x1 = x0, y0 = line.path.front().y, y1 = y0;
  for (const auto& q : line.path) {
    x0 = std::min(x0, q.x), x1 = std::max(x1, q.x);
    y0 = std::min(y0, q.y), y1 = std::max(y1, q.y);
  }
  const double grow = std::ceil(profile.width_px / 2.0) + p.margin_px;
  const cv::Point origin(static_cast<int>(std::floor(x0 - grow)), static_cast<int>(std::floor(y0 - grow)));
  const long long cols = static_cast<long long>(std::ceil(x1 + grow)) - origin.x + 1;
  const long long rows = static_cast<long long>(std::ceil(y1 + grow)) - origin.y + 1;
  if (static_cast<unsigned long long>(cols * rows) > limits.max_pixels)
    throw ConvertError("line: the canvas would be " + std::to_string(cols) + " x " + std::to_string(rows) +
                       " px, more than the limit of " + std::to_string(limits.max_pixels) + " pixels");
  cv::Mat canvas(static_cast<int>(rows), static_cast<int>(cols), CV_8UC1, cv::Scalar(255));
  std::vector<cv::Point2d> shifted;
  shifted.reserve(line.path.size());
  for (const auto& q : line.path) shifted.emplace_back(q.x - origin.x, q.y - origin.y);
  pencil::draw_pencil_line(canvas, shifted, profile, p.seed);

  double length = 0.0;
  for (size_t i = 1; i < line.path.size(); ++i) length += cv::norm(line.path[i] - line.path[i - 1]);

  std::filesystem::create_directories(out);
  write_output_png(out / "line.png", canvas);
  nlohmann::json lj = {{"from", {p.from.x, p.from.y}},
                       {"to", {p.to.x, p.to.y}},
                       {"pencil", p.pencil},
                       {"squiggle", p.squiggle},
                       {"seed", p.seed},
                       {"origin", {origin.x, origin.y}},
                       {"control", points_json(line.control)},
                       {"path", points_json(line.path)}};
  write_output(out / "line.json", lj.dump() + "\n");

  ConvertResult result;
  result.report = {{"kind", "line"},
                   {"from", {p.from.x, p.from.y}},
                   {"to", {p.to.x, p.to.y}},
                   {"pencil", {{"name", profile.name}, {"source", p.pencil}, {"width_px", profile.width_px}}},
                   {"squiggle", p.squiggle},
                   {"seed", p.seed},
                   {"margin", p.margin_px},
                   {"origin", {origin.x, origin.y}},
                   {"canvas", {{"width", cols}, {"height", rows}}},
                   {"length_px", r3(length)},
                   {"points", line.path.size()},
                   {"control_points", line.control.size()}};
  result.report["milliseconds"] =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  write_output(out / "report.json", result.report.dump(2) + "\n");
  result.outputs = {"line.png", "line.json", "report.json"};
  return result;
}

}  // namespace atelier

#include "convert/parquetry/parquetry_svg.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "algorithms/laser/hershey_text.h"
#include "algorithms/laser/plan.h"
#include "convert/common/hershey_fonts.h"

namespace atelier {
namespace {

using laser::format_number;

constexpr double kLabelPxPerMm = 10;   // raster for finding a piece's inscribed circle
constexpr double kLabelShare = 0.4;    // the ID's longer side / the inscribed diameter
constexpr double kMinTextMm = 1.5;     // smaller IDs do not survive the beam's width
constexpr double kStrokeMm = 0.1;      // drawn line width (the laser ignores it)

std::string pt(cv::Point2d p) { return format_number(p.x) + " " + format_number(p.y); }

std::string outline_d(const parquetry::Outline& outline) {
  if (outline.empty()) return "";
  std::string d = "M " + pt(outline.front().p0);
  for (const auto& c : outline) d += " C " + pt(c.c1) + " " + pt(c.c2) + " " + pt(c.p3);
  return d + " Z";
}

std::string strokes_d(const std::vector<laser::Path>& paths, cv::Matx23d m = {1, 0, 0, 0, 1, 0}) {
  std::string d;
  for (const auto& path : paths) {
    for (size_t i = 0; i < path.points.size(); ++i) {
      const cv::Point2d p = parquetry::transformed(cv::Point2d(path.points[i].x, path.points[i].y), m);
      d += (d.empty() ? "" : " ") + std::string(i == 0 ? "M " : "L ") + pt(p);
    }
  }
  return d;
}

// Centre and diameter (mm) of the largest circle inside `polygon`.
std::pair<cv::Point2d, double> inscribed_circle(const std::vector<cv::Point2d>& polygon) {
  cv::Rect2d box;  // cv::boundingRect takes float or int points only
  if (!polygon.empty()) {
    double x0 = polygon[0].x, y0 = polygon[0].y, x1 = x0, y1 = y0;
    for (const auto& p : polygon) {
      x0 = std::min(x0, p.x), y0 = std::min(y0, p.y), x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
    }
    box = cv::Rect2d(x0, y0, x1 - x0, y1 - y0);
  }
  const double s = kLabelPxPerMm;
  const cv::Point2d origin(box.x - 2 / s, box.y - 2 / s);
  const cv::Size size(static_cast<int>(std::ceil(box.width * s)) + 4,
                      static_cast<int>(std::ceil(box.height * s)) + 4);
  cv::Mat inside(size, CV_8UC1, cv::Scalar(0));
  std::vector<cv::Point> px;
  for (const auto& p : polygon) {
    px.emplace_back(static_cast<int>(std::lround((p.x - origin.x) * s * 16)),
                    static_cast<int>(std::lround((p.y - origin.y) * s * 16)));
  }
  cv::fillPoly(inside, std::vector<std::vector<cv::Point>>{px}, cv::Scalar(255), cv::LINE_8, 4);
  cv::Mat dist;
  cv::distanceTransform(inside, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  double max_d = 0;
  cv::Point at;
  cv::minMaxLoc(dist, nullptr, &max_d, nullptr, &at);
  return {{origin.x + (at.x + 0.5) / s, origin.y + (at.y + 0.5) / s}, 2 * max_d / s};
}

// Cap height that makes `text` about kLabelShare of `diameter` on its longer side.
double text_height(const std::string& text, double diameter) {
  const laser::Bounds unit = laser::hershey_text_bounds(hershey_font(), text, {0, 0}, 1.0);
  const double longer = std::max(unit.max_x - unit.min_x, unit.max_y - unit.min_y);
  if (!(longer > 0)) return kMinTextMm;
  return std::max(kMinTextMm, kLabelShare * diameter / longer);
}

std::vector<laser::Path> id_strokes(int id, cv::Point2d centre, double height) {
  return laser::hershey_text_centred(hershey_font(), std::to_string(id), {centre.x, centre.y}, height);
}

void svg_open(std::ostringstream& o, double w, double h) {
  o << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << format_number(w) << "mm\" height=\""
    << format_number(h) << "mm\" viewBox=\"0 0 " << format_number(w) << " " << format_number(h)
    << "\">\n";
}

}  // namespace

cv::Size2d sheet_size_mm(const parquetry::Sheet& sheet) {
  return {sheet.image.cols * 25.4 / sheet.dpi, sheet.image.rows * 25.4 / sheet.dpi};
}

SheetCuts sheet_cuts(const parquetry::Plan& plan, const parquetry::Sheet& sheet) {
  SheetCuts out;
  out.sheet_id = sheet.id;
  const cv::Size2d size = sheet_size_mm(sheet);
  out.width_mm = size.width;
  out.height_mm = size.height;
  const cv::Matx23d mirror(-1, 0, size.width, 0, 1, 0);  // face down: x' = width - x
  for (const auto& piece : plan.pieces) {
    if (piece.sheet_id != sheet.id) continue;
    PieceCut cut;
    cut.id = piece.id;
    cut.outline = parquetry::transformed(piece.source, mirror);
    std::vector<cv::Point2d> polygon;
    for (const auto& p : piece.source_mm) polygon.push_back(parquetry::transformed(p, mirror));
    auto [centre, diameter] = inscribed_circle(polygon);
    cut.inscribed_mm = diameter;
    cut.text_height_mm = text_height(std::to_string(piece.id), diameter);
    cut.id_text = id_strokes(piece.id, centre, cut.text_height_mm);
    out.pieces.push_back(std::move(cut));
  }
  std::sort(out.pieces.begin(), out.pieces.end(), [](const PieceCut& a, const PieceCut& b) { return a.id < b.id; });
  return out;
}

std::string cuts_svg(const SheetCuts& cuts) {
  std::ostringstream o;
  svg_open(o, cuts.width_mm, cuts.height_mm);
  o << "<!-- Veneer sheet '" << cuts.sheet_id << "' seen from the BACK: it is cut face down, so this\n"
    << "     drawing is the scan mirrored left-right (x' = " << format_number(cuts.width_mm)
    << " - x). Red #ff0000 = cut, blue #0000ff = engraved piece IDs\n"
    << "     (they read normally in this view). Units: mm. -->\n"
    << "<title>cuts for sheet " << cuts.sheet_id << " (face down, mirrored)</title>\n";
  for (const auto& p : cuts.pieces) {
    o << "<g id=\"piece-" << p.id << "\" data-piece=\"" << p.id << "\" data-sheet=\"" << cuts.sheet_id
      << "\">\n"
      << "  <path d=\"" << outline_d(p.outline) << "\" fill=\"none\" stroke=\"" << kParquetryCutColor
      << "\" stroke-width=\"" << kStrokeMm << "\"/>\n"
      << "  <path d=\"" << strokes_d(p.id_text) << "\" fill=\"none\" stroke=\"" << kParquetryEngraveColor
      << "\" stroke-width=\"" << kStrokeMm << "\" stroke-linecap=\"round\"/>\n"
      << "</g>\n";
  }
  o << "</svg>\n";
  return o.str();
}

std::string assembly_svg(const parquetry::Plan& plan) {
  std::ostringstream o;
  svg_open(o, plan.width_mm, plan.height_mm);
  o << "<!-- Assembly seen from the FACE: every piece at its place in the result (mm), its ID as\n"
    << "     engraved on its back, its wood and rotation in its title. -->\n"
    << "<title>parquetry assembly, " << plan.pieces.size() << " pieces</title>\n";
  for (const auto& piece : plan.pieces) {
    auto [centre, diameter] = inscribed_circle(piece.target_mm);
    const double h = text_height(std::to_string(piece.id), diameter);
    o << "<g id=\"piece-" << piece.id << "\" data-piece=\"" << piece.id << "\" data-sheet=\""
      << piece.sheet_id << "\">\n"
      << "  <title>piece " << piece.id << ": " << piece.sheet_id << ", wood turned "
      << format_number(piece.rotation_deg) << " deg</title>\n"
      << "  <path d=\"" << outline_d(piece.target) << "\" fill=\"none\" stroke=\"#000000\" stroke-width=\""
      << kStrokeMm << "\"/>\n"
      << "  <path d=\"" << strokes_d(id_strokes(piece.id, centre, h)) << "\" fill=\"none\" stroke=\"#404040\""
      << " stroke-width=\"" << kStrokeMm << "\" stroke-linecap=\"round\"/>\n"
      << "</g>\n";
  }
  o << "</svg>\n";
  return o.str();
}

}  // namespace atelier

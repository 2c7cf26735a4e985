#include "algorithms/laser/hershey_text.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace atelier::laser {
namespace {

// Strokes of `text` laid out along the baseline, in mm, x right and y UP (local frame).
std::vector<std::vector<Point>> layout(const HersheyFont& font, const std::string& text,
                                       double cap_height_mm, double* advance_mm) {
  if (!(cap_height_mm > 0) || !std::isfinite(cap_height_mm))
    throw std::invalid_argument("hershey_text: cap height must be a positive number of mm, got " +
                                std::to_string(cap_height_mm));
  const double scale = cap_height_mm / font.cap_units;
  std::vector<std::vector<Point>> out;
  double pen = 0;  // font units
  for (size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c >= 128 || !font.glyphs[c].present)
      throw std::invalid_argument("hershey_text: font '" + font.name + "' has no glyph for " +
                                  (c >= 32 && c < 127 ? "'" + std::string(1, char(c)) + "'"
                                                      : "byte " + std::to_string(int(c))) +
                                  " at position " + std::to_string(i) + " of \"" + text + "\"");
    const HersheyGlyph& g = font.glyphs[c];
    for (const auto& s : g.strokes) {
      std::vector<Point> placed;
      placed.reserve(s.size());
      for (Point p : s) placed.push_back({(pen + p.x) * scale, p.y * scale});
      out.push_back(std::move(placed));
    }
    pen += g.advance;
  }
  if (advance_mm) *advance_mm = pen * scale;
  return out;
}

// Local (x right, y up, mm) -> design (x right, y down): turn counter-clockwise as seen on the
// sheet by `angle_deg`, then move the local origin to `origin`.
std::vector<Path> place(const std::vector<std::vector<Point>>& strokes, Point shift, Point origin,
                        double angle_deg) {
  const double a = angle_deg * std::numbers::pi / 180.0, c = std::cos(a), s = std::sin(a);
  std::vector<Path> out;
  out.reserve(strokes.size());
  for (const auto& stroke : strokes) {
    Path path;
    path.points.reserve(stroke.size());
    for (Point p : stroke) {
      const double u = p.x + shift.x, v = p.y + shift.y;
      path.points.push_back({origin.x + u * c - v * s, origin.y - (u * s + v * c)});
    }
    out.push_back(std::move(path));
  }
  return out;
}

}  // namespace

std::vector<Path> hershey_text(const HersheyFont& font, const std::string& text, Point baseline_left,
                               double cap_height_mm, double angle_deg) {
  return place(layout(font, text, cap_height_mm, nullptr), {0, 0}, baseline_left, angle_deg);
}

Bounds hershey_text_bounds(const HersheyFont& font, const std::string& text, Point baseline_left,
                           double cap_height_mm, double angle_deg) {
  Bounds b;
  for (const Path& p : hershey_text(font, text, baseline_left, cap_height_mm, angle_deg))
    b.add(bounds_of(p));
  return b;
}

double hershey_text_advance(const HersheyFont& font, const std::string& text, double cap_height_mm) {
  double advance = 0;
  layout(font, text, cap_height_mm, &advance);
  return advance;
}

std::vector<Path> hershey_text_centred(const HersheyFont& font, const std::string& text, Point centre,
                                       double cap_height_mm, double angle_deg) {
  const auto strokes = layout(font, text, cap_height_mm, nullptr);
  Bounds ink;
  for (const auto& s : strokes)
    for (Point p : s) ink.add(p);
  const Point mid = ink.empty() ? Point{} : Point{(ink.min_x + ink.max_x) / 2, (ink.min_y + ink.max_y) / 2};
  return place(strokes, {-mid.x, -mid.y}, centre, angle_deg);
}

}  // namespace atelier::laser

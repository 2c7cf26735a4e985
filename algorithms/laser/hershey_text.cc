#include "algorithms/laser/hershey_text.h"

extern "C" {  // a C header without its own linkage guard
#include <hersheyfont.h>
}

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <stdexcept>

namespace atelier::laser {
namespace {

// Font units: x right from the glyph's left bearing, y up from the baseline (libhersheyfont's
// frame). Only the 7-bit ASCII glyphs are kept.
struct Glyph {
  bool present = false;
  int advance = 0;
  std::vector<std::vector<Point>> strokes;
};

struct Font {
  std::array<Glyph, 128> glyphs;
  double cap_units = 21;  // height of 'H'; 21 in every Roman Hershey font
};

std::filesystem::path font_path(const std::string& name) {
  // Names only, so a caller's string can never reach outside the font directory.
  if (name.empty() || name.find_first_not_of("abcdefghijklmnopqrstuvwxyz"
                                             "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") !=
                          std::string::npos)
    throw std::invalid_argument("hershey_text: bad font name '" + name +
                                "' (expected a .jhf name such as 'rowmans')");
  const char* dir = std::getenv("HERSHEY_FONTS_DIR");  // libhersheyfont's own override
  return std::filesystem::path(dir && *dir ? dir : "/usr/share/hershey-fonts") / (name + ".jhf");
}

std::shared_ptr<const Font> read_font(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw std::runtime_error("hershey_text: font file " + path.string() +
                             " not found (install hershey-fonts-data, or set HERSHEY_FONTS_DIR)");
  errno = 0;
  hershey_font* hf = hershey_jhf_font_load(path.c_str());
  if (!hf)
    throw std::runtime_error("hershey_text: cannot read font file " + path.string() +
                             (errno ? std::string(": ") + std::strerror(errno) : std::string()));
  std::unique_ptr<hershey_font, void (*)(hershey_font*)> guard(hf, hershey_font_free);

  auto font = std::make_shared<Font>();
  for (int c = 32; c < 127; ++c) {
    const hershey_glyph* hg = hershey_font_glyph(hf, static_cast<unsigned char>(c));
    if (!hg || hg->width == 0) continue;  // the font has no glyph for c
    Glyph& g = font->glyphs[c];
    g.present = true;
    g.advance = hg->width;
    for (const hershey_path* hp = hg->paths; hp; hp = hp->next) {
      std::vector<Point> stroke;
      for (unsigned i = 0; i < hp->nverts; ++i) {
        Point p{double(hp->verts[i].x), double(hp->verts[i].y)};
        if (stroke.empty() || stroke.back().x != p.x || stroke.back().y != p.y)
          stroke.push_back(p);
      }
      if (stroke.size() >= 2) g.strokes.push_back(std::move(stroke));  // a lone point burns nothing
    }
  }
  if (font->glyphs['H'].present) {
    double top = 0;
    for (const auto& s : font->glyphs['H'].strokes)
      for (Point p : s) top = std::max(top, p.y);
    if (top > 0) font->cap_units = top;
  }
  return font;
}

const Font& font_named(const std::string& name) {
  static std::mutex mutex;
  static std::map<std::string, std::shared_ptr<const Font>> cache;  // by path; never erased
  const std::filesystem::path path = font_path(name);
  std::lock_guard lock(mutex);
  auto it = cache.find(path.string());
  if (it == cache.end()) it = cache.emplace(path.string(), read_font(path)).first;
  return *it->second;
}

// Strokes of `text` laid out along the baseline, in mm, x right and y UP (local frame).
std::vector<std::vector<Point>> layout(const std::string& text, double cap_height_mm,
                                       const std::string& font_name, double* advance_mm) {
  if (!(cap_height_mm > 0) || !std::isfinite(cap_height_mm))
    throw std::invalid_argument("hershey_text: cap height must be a positive number of mm, got " +
                                std::to_string(cap_height_mm));
  const Font& font = font_named(font_name);
  const double scale = cap_height_mm / font.cap_units;
  std::vector<std::vector<Point>> out;
  double pen = 0;  // font units
  for (size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c >= 128 || !font.glyphs[c].present)
      throw std::invalid_argument("hershey_text: font '" + font_name + "' has no glyph for " +
                                  (c >= 32 && c < 127 ? "'" + std::string(1, char(c)) + "'"
                                                      : "byte " + std::to_string(int(c))) +
                                  " at position " + std::to_string(i) + " of \"" + text + "\"");
    const Glyph& g = font.glyphs[c];
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

std::vector<Path> hershey_text(const std::string& text, Point baseline_left, double cap_height_mm,
                               double angle_deg, const std::string& font) {
  return place(layout(text, cap_height_mm, font, nullptr), {0, 0}, baseline_left, angle_deg);
}

Bounds hershey_text_bounds(const std::string& text, Point baseline_left, double cap_height_mm,
                           double angle_deg, const std::string& font) {
  Bounds b;
  for (const Path& p : hershey_text(text, baseline_left, cap_height_mm, angle_deg, font))
    b.add(bounds_of(p));
  return b;
}

double hershey_text_advance(const std::string& text, double cap_height_mm,
                            const std::string& font) {
  double advance = 0;
  layout(text, cap_height_mm, font, &advance);
  return advance;
}

std::vector<Path> hershey_text_centred(const std::string& text, Point centre, double cap_height_mm,
                                       double angle_deg, const std::string& font) {
  const auto strokes = layout(text, cap_height_mm, font, nullptr);
  Bounds ink;
  for (const auto& s : strokes)
    for (Point p : s) ink.add(p);
  const Point mid = ink.empty() ? Point{} : Point{(ink.min_x + ink.max_x) / 2, (ink.min_y + ink.max_y) / 2};
  return place(strokes, {-mid.x, -mid.y}, centre, angle_deg);
}

}  // namespace atelier::laser

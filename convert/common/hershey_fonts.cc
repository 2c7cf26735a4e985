#include "convert/common/hershey_fonts.h"

extern "C" {  // a C header without its own linkage guard
#include <hersheyfont.h>
}

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>

#include "base/error.h"

namespace atelier {
namespace {

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

std::unique_ptr<const laser::HersheyFont> read_font(const std::string& name,
                                                    const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InternalError("hershey_text: font file " + path.string() +
                        " not found (install hershey-fonts-data, or set HERSHEY_FONTS_DIR)");
  errno = 0;
  ::hershey_font* hf = hershey_jhf_font_load(path.c_str());
  if (!hf)
    throw InternalError("hershey_text: cannot read font file " + path.string() +
                        (errno ? std::string(": ") + std::strerror(errno) : std::string()));
  std::unique_ptr<::hershey_font, void (*)(::hershey_font*)> guard(hf, hershey_font_free);

  auto font = std::make_unique<laser::HersheyFont>();
  font->name = name;
  for (int c = 32; c < 127; ++c) {
    const hershey_glyph* hg = hershey_font_glyph(hf, static_cast<unsigned char>(c));
    if (!hg || hg->width == 0) continue;  // the font has no glyph for c
    laser::HersheyGlyph& g = font->glyphs[c];
    g.present = true;
    g.advance = hg->width;
    for (const hershey_path* hp = hg->paths; hp; hp = hp->next) {
      std::vector<laser::Point> stroke;
      for (unsigned i = 0; i < hp->nverts; ++i) {
        laser::Point p{double(hp->verts[i].x), double(hp->verts[i].y)};
        if (stroke.empty() || stroke.back().x != p.x || stroke.back().y != p.y)
          stroke.push_back(p);
      }
      if (stroke.size() >= 2) g.strokes.push_back(std::move(stroke));  // a lone point burns nothing
    }
  }
  if (font->glyphs['H'].present) {
    double top = 0;
    for (const auto& s : font->glyphs['H'].strokes)
      for (laser::Point p : s) top = std::max(top, p.y);
    if (top > 0) font->cap_units = top;
  }
  return font;
}

}  // namespace

const laser::HersheyFont& hershey_font(const std::string& name) {
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<const laser::HersheyFont>> cache;  // by path; never erased
  const std::filesystem::path path = font_path(name);
  std::lock_guard lock(mutex);
  auto it = cache.find(path.string());
  if (it == cache.end()) it = cache.emplace(path.string(), read_font(name, path)).first;
  return *it->second;
}

}  // namespace atelier

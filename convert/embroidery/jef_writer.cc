#include "convert/embroidery/jef_writer.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <stdexcept>

#include "convert/embroidery/thread_palettes.h"

namespace atelier::embroidery {
namespace {

constexpr long kMaxMove = 127;  // -128 (0x80) is the control escape
constexpr int kTrimJumps = 3;

void u32(std::string& out, long v) {
  const auto u = static_cast<std::uint32_t>(static_cast<std::int32_t>(v));
  for (int i = 0; i < 4; ++i) out += static_cast<char>((u >> (8 * i)) & 0xff);
}
char byte_of(long v) { return static_cast<char>(static_cast<signed char>(v)); }

// The design's extents from the start point (0.1 mm, all >= 0: the start point counts).
struct Extents {
  long left = 0, top = 0, right = 0, bottom = 0;
};

bool fits(const Extents& e, const JefHoop& h) {
  return 2 * std::max(e.left, e.right) <= h.width && 2 * std::max(e.top, e.bottom) <= h.height;
}

void edges(std::string& out, const Extents& e, long width, long height) {
  const long l = width / 2 - e.left, t = height / 2 - e.top, r = width / 2 - e.right, b = height / 2 - e.bottom;
  const bool in = std::min({l, t, r, b}) >= 0;
  for (long v : {l, t, r, b}) u32(out, in ? v : -1);
}

}  // namespace

const std::vector<JefHoop>& jef_hoops() {
  static const std::vector<JefHoop> h{{1, 500, 500}, {0, 1100, 1100}, {3, 1260, 1100}, {2, 1400, 2000}, {4, 2000, 2000}};
  return h;
}

std::string write_jef(const StitchPlan& plan, const std::string& date) {
  validate_plan(plan);
  if (date.size() != 14 || !std::all_of(date.begin(), date.end(), [](unsigned char c) { return std::isdigit(c); }))
    throw std::invalid_argument("JEF: the date must be 14 digits YYYYMMDDhhmmss, not '" + date + "'");

  std::string body;
  FileUnits at;
  Extents ext;
  auto move_to = [&](FileUnits target, bool jump) {
    for (const FileUnits& s : split_move(target.x - at.x, target.y - at.y, kMaxMove)) {
      if (jump) body += "\x80\x02";
      body += byte_of(s.x);
      body += byte_of(s.y);
    }
    at = target;
    ext.left = std::max(ext.left, -at.x), ext.right = std::max(ext.right, at.x);
    ext.top = std::max(ext.top, at.y), ext.bottom = std::max(ext.bottom, -at.y);  // +y up
  };
  for (const StitchPoint& p : plan.points) {
    switch (p.kind) {
      case StitchKind::stitch: move_to(to_file_units(p), false); break;
      case StitchKind::jump: move_to(to_file_units(p), true); break;
      case StitchKind::trim:
        for (int i = 0; i < kTrimJumps; ++i) body.append("\x80\x02\x00\x00", 4);
        break;
      case StitchKind::color_change: body.append("\x80\x01\x00\x00", 4); break;
      case StitchKind::end: break;  // the one end code is written below
    }
  }
  body += "\x80\x10";

  const std::vector<int> threads = assign_threads(jef_threads(), block_colors(plan));
  const JefHoop* hoop = &jef_hoops().back();
  for (const JefHoop& h : jef_hoops())
    if (fits(ext, h)) {
      hoop = &h;
      break;
    }
  std::string out;
  u32(out, 0x74 + 8 * static_cast<long>(threads.size()));
  u32(out, 0x14);
  out += date;
  out.append(2, '\0');
  u32(out, static_cast<long>(threads.size()));
  u32(out, static_cast<long>(body.size() / 2));
  u32(out, hoop->code);
  for (long v : {ext.left, ext.top, ext.right, ext.bottom}) u32(out, v);
  edges(out, ext, 1100, 1100);
  edges(out, ext, 500, 500);
  edges(out, ext, 1400, 2000);
  edges(out, ext, hoop->width, hoop->height);
  for (int t : threads) u32(out, t);
  for (size_t i = 0; i < threads.size(); ++i) u32(out, 0x0D);
  return out + body;
}

}  // namespace atelier::embroidery

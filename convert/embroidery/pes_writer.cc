#include "convert/embroidery/pes_writer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <vector>

#include "convert/embroidery/stitch_label.h"
#include "convert/embroidery/thread_palettes.h"

namespace atelier::embroidery {
namespace {

constexpr std::uint8_t kJumpFlag = 0x10, kTrimFlag = 0x20;
// CSewSeg's point count is 16-bit: a longer run of stitches continues in a new segment.
constexpr size_t kMaxSegmentPoints = 32000;

void u8(std::string& out, unsigned v) { out += static_cast<char>(v & 0xff); }
void u16(std::string& out, unsigned v) { u8(out, v), u8(out, v >> 8); }
void s16(std::string& out, long v) { u16(out, static_cast<unsigned>(static_cast<std::uint16_t>(v))); }
void u24(std::string& out, unsigned long v) { u16(out, v & 0xffff), u8(out, v >> 16); }
void u32(std::string& out, unsigned long v) { u16(out, v & 0xffff), u16(out, v >> 16); }
void f32(std::string& out, float v) {
  std::uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  u32(out, bits);
}
void put_u32_at(std::string& out, size_t at, unsigned long v) {
  std::string b;
  u32(b, v);
  out.replace(at, 4, b);
}

// PEC units: 0.1 mm, image frame (+y down).
FileUnits pec_units(const StitchPoint& p) { return {std::lround(p.x_mm * 10.0), std::lround(p.y_mm * 10.0)}; }

struct Extent {
  long min_x = 0, max_x = 0, min_y = 0, max_y = 0;
  bool any = false;
  void add(FileUnits u) {
    if (!any) min_x = max_x = u.x, min_y = max_y = u.y, any = true;
    min_x = std::min(min_x, u.x), max_x = std::max(max_x, u.x);
    min_y = std::min(min_y, u.y), max_y = std::max(max_y, u.y);
  }
  long width() const { return max_x - min_x; }
  long height() const { return max_y - min_y; }
};

Extent extent_of(const StitchPlan& plan) {
  Extent e;
  for (const StitchPoint& p : plan.points)
    if (is_positioned(p.kind)) e.add(pec_units(p));
  return e;
}

// ---- PEC stitches ------------------------------------------------------------------------
class PecMoves {
 public:
  std::string bytes;

  void stitch_to(FileUnits t) {
    flush_trim();
    for (const FileUnits& s : split_move(t.x - x_, t.y - y_, kPecMaxLong)) {
      value(s.x, 0, false);
      value(s.y, 0, false);
    }
    x_ = t.x, y_ = t.y;
  }
  void jump_to(FileUnits t) {
    for (const FileUnits& s : split_move(t.x - x_, t.y - y_, kPecMaxLong)) {
      const std::uint8_t flag = trim_pending_ ? kTrimFlag : kJumpFlag;
      trim_pending_ = false;
      value(s.x, flag, true);
      value(s.y, flag, true);
    }
    x_ = t.x, y_ = t.y;
  }
  void trim() {
    flush_trim();
    trim_pending_ = true;
  }
  void color_change() {
    flush_trim();
    bytes += "\xFE\xB0";
    u8(bytes, color_two_ ? 0x02 : 0x01);  // alternates 2, 1, 2, ... as Brother's software writes
    color_two_ = !color_two_;
  }
  void end() {
    flush_trim();
    u8(bytes, 0xFF);
  }

 private:
  // A trim with no jump after it: a trim-flagged move of zero.
  void flush_trim() {
    if (!trim_pending_) return;
    trim_pending_ = false;
    value(0, kTrimFlag, true);
    value(0, kTrimFlag, true);
  }
  void value(long v, std::uint8_t flag, bool force_long) {
    if (!force_long && v >= kPecMinShort && v <= kPecMaxShort) {
      u8(bytes, static_cast<unsigned>(v) & 0x7f);
      return;
    }
    const unsigned twelve = static_cast<unsigned>(v) & 0x0fff;
    u8(bytes, 0x80 | flag | (twelve >> 8));
    u8(bytes, twelve & 0xff);
  }
  long x_ = 0, y_ = 0;
  bool trim_pending_ = false, color_two_ = true;
};

// ---- Thumbnails ----------------------------------------------------------------------------
using Thumb = std::array<std::uint8_t, kPecThumbBytes>;

void set_bit(Thumb& t, int x, int y) {
  if (x < 0 || y < 0 || x >= kPecThumbWidth || y >= kPecThumbHeight) return;
  t[static_cast<size_t>(y * (kPecThumbWidth / 8) + x / 8)] |= static_cast<std::uint8_t>(1u << (x % 8));
}

void line(Thumb& t, int x0, int y0, int x1, int y1) {
  // Bresenham; at most 48 + 38 steps, so bounded whatever the design.
  const int dx = std::abs(x1 - x0), dy = -std::abs(y1 - y0);
  const int sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1;
  int err = dx + dy;
  for (int step = 0; step <= kPecThumbWidth + kPecThumbHeight; ++step) {
    set_bit(t, x0, y0);
    if (x0 == x1 && y0 == y1) break;
    const int e2 = 2 * err;
    if (e2 >= dy) err += dy, x0 += sx;
    if (e2 <= dx) err += dx, y0 += sy;
  }
}

// The rounded frame Brother's machines and software draw around a thumbnail.
Thumb framed() {
  Thumb t{};
  line(t, 4, 1, 43, 1);
  line(t, 4, 36, 43, 36);
  line(t, 1, 4, 1, 33);
  line(t, 46, 4, 46, 33);
  line(t, 1, 4, 3, 2), line(t, 44, 2, 46, 4), line(t, 1, 33, 3, 35), line(t, 44, 35, 46, 33);
  return t;
}

// Draws the stitches (lines between consecutive needle points) of colour block `only`
// (every block for -1), the design's extent scaled into the frame's inside (x 4..43, y 4..33).
Thumb thumbnail(const StitchPlan& plan, const Extent& e, int only) {
  Thumb t = framed();
  const double scale = std::min(39.0 / std::max(1L, e.width()), 29.0 / std::max(1L, e.height()));
  const double ox = 4 + (39.0 - e.width() * scale) / 2, oy = 4 + (29.0 - e.height() * scale) / 2;
  auto px = [&](FileUnits u, int& x, int& y) {
    x = static_cast<int>(std::lround(ox + (u.x - e.min_x) * scale));
    y = static_cast<int>(std::lround(oy + (u.y - e.min_y) * scale));
  };
  int block = 0;
  bool have_last = false;  // the thread runs from the last needle point
  int lx = 0, ly = 0;
  for (const StitchPoint& p : plan.points) {
    if (p.kind == StitchKind::color_change) ++block, have_last = false;
    if (p.kind == StitchKind::trim || p.kind == StitchKind::jump) have_last = false;
    if (p.kind != StitchKind::stitch || (only >= 0 && block != only)) continue;
    int x, y;
    px(pec_units(p), x, y);
    if (have_last) line(t, lx, ly, x, y);
    else set_bit(t, x, y);
    lx = x, ly = y, have_last = true;
  }
  return t;
}

// ---- PES part ------------------------------------------------------------------------------
struct Segment {
  int flag = 0;  // 0 stitches, 1 jump
  int color = 0;
  std::vector<FileUnits> points;
};

std::vector<Segment> segments(const StitchPlan& plan, const std::vector<int>& threads) {
  std::vector<Segment> out;
  size_t block = 0;
  FileUnits last_stitch{};
  int open = -1;  // kind of the segment being extended (-1: none)
  for (const StitchPoint& p : plan.points) {
    if (p.kind == StitchKind::color_change) ++block, open = -1;
    if (p.kind == StitchKind::trim) open = -1;
    if (!is_positioned(p.kind)) continue;
    const int color = threads[std::min(block, threads.size() - 1)];
    const FileUnits u = pec_units(p);
    if (p.kind == StitchKind::stitch) {
      if (open != 0 || out.back().points.size() >= kMaxSegmentPoints) {
        out.push_back({0, color, {}});
        if (open == 0) out.back().points.push_back(last_stitch);  // continues the run
      }
      out.back().points.push_back(u);
      last_stitch = u;
      open = 0;
    } else {
      if (open != 1) out.push_back({1, color, {last_stitch, u}});
      out.back().points.back() = u;
      open = 1;
    }
  }
  return out;
}

void pes_part(std::string& out, const StitchPlan& plan, const Extent& e, const std::vector<int>& threads) {
  out += "#PES0001";
  u32(out, 0);  // the PEC offset, set once known
  const bool small = e.width() <= 1000 && e.height() <= 1000;
  const double hoop_w = small ? 1000 : 1300, hoop_h = small ? 1000 : 1800;
  u16(out, 1);              // scale to fit
  u16(out, small ? 0 : 1);  // hoop: 0 = 100 x 100 mm, 1 = 130 x 180 mm
  const std::vector<Segment> segs = segments(plan, threads);
  if (segs.size() > 0xFFFF)
    throw std::invalid_argument("PES: " + std::to_string(segs.size()) + " runs of stitches and jumps; CSewSeg counts at most 65535");
  if (segs.empty()) {
    u16(out, 0);  // no block
    u16(out, 0), u16(out, 0);
    return;
  }
  u16(out, 1);  // one block
  u16(out, 0xFFFF), u16(out, 0);
  u16(out, 7);
  out += "CEmbOne";
  for (int i = 0; i < 8; ++i) u16(out, 0);  // two bounding boxes, left unset as PE-Design reads
  // Affine (a, b, c, d, tx, ty): the identity, translated so the design sits at the hoop's
  // centre on PE-Design's page (its hoop is 350 x 100 units from the page corner).
  const double w = static_cast<double>(e.width()), h = static_cast<double>(e.height());
  for (float v : {1.0f, 0.0f, 0.0f, 1.0f}) f32(out, v);
  f32(out, static_cast<float>(350 + hoop_w / 2 - w / 2));
  f32(out, static_cast<float>(100 + h + hoop_h / 2 - h / 2));
  u16(out, 1), u16(out, 0), u16(out, 0);
  s16(out, e.width()), s16(out, e.height());
  out.append(8, '\0');
  u16(out, static_cast<unsigned>(segs.size()));
  u16(out, 0xFFFF), u16(out, 0);
  u16(out, 7);
  out += "CSewSeg";
  std::vector<std::pair<size_t, int>> color_log;
  for (size_t i = 0; i < segs.size(); ++i) {
    const Segment& s = segs[i];
    if (i) u16(out, 0x8003);  // segment separator
    if (color_log.empty() || color_log.back().second != s.color) color_log.push_back({i, s.color});
    u16(out, static_cast<unsigned>(s.flag));
    u16(out, static_cast<unsigned>(s.color));
    u16(out, static_cast<unsigned>(s.points.size()));
    for (const FileUnits& u : s.points) s16(out, u.x - e.min_x), s16(out, u.y - e.max_y);
  }
  u16(out, static_cast<unsigned>(color_log.size()));
  for (const auto& [section, color] : color_log) u16(out, static_cast<unsigned>(section)), u16(out, static_cast<unsigned>(color));
  u16(out, 0), u16(out, 0);  // no more blocks
}

// ---- PEC section ---------------------------------------------------------------------------
void pec_section(std::string& out, const StitchPlan& plan, const Extent& e, const std::vector<int>& threads) {
  const size_t start = out.size();
  out += "LA:" + label16(plan.name) + "\r";
  out.append(12, ' ');
  out += "\xFF";
  out += '\0';
  u8(out, kPecThumbWidth / 8);
  u8(out, kPecThumbHeight);
  out.append(12, ' ');
  u8(out, static_cast<unsigned>(threads.size() - 1));
  for (int t : threads) u8(out, static_cast<unsigned>(t));
  out.append(start + kPecHeaderBytes - out.size(), ' ');

  const size_t block = out.size();
  out += std::string("\0\0", 2);
  u24(out, 0);  // the block's length, set below
  out += "\x31\xFF\xF0";
  u16(out, static_cast<unsigned>(e.width()));
  u16(out, static_cast<unsigned>(e.height()));
  u16(out, 0x1E0), u16(out, 0x1B0);
  PecMoves moves;
  for (const StitchPoint& p : plan.points) {
    switch (p.kind) {
      case StitchKind::stitch: moves.stitch_to(pec_units(p)); break;
      case StitchKind::jump: moves.jump_to(pec_units(p)); break;
      case StitchKind::trim: moves.trim(); break;
      case StitchKind::color_change: moves.color_change(); break;
      case StitchKind::end: break;  // the one end code is written below
    }
  }
  moves.end();
  out += moves.bytes;
  const size_t length = out.size() - block;
  if (length > 0xFFFFFF) throw std::invalid_argument("PES: the stitches do not fit PEC's 24-bit length");
  std::string len;
  u24(len, length);
  out.replace(block + 2, 3, len);

  const Thumb all = thumbnail(plan, e, -1);
  out.append(reinterpret_cast<const char*>(all.data()), all.size());
  for (size_t b = 0; b < threads.size(); ++b) {
    const Thumb t = thumbnail(plan, e, static_cast<int>(b));
    out.append(reinterpret_cast<const char*>(t.data()), t.size());
  }
}

}  // namespace

std::string write_pes(const StitchPlan& plan) {
  validate_plan(plan);
  const std::vector<std::uint32_t> colors = block_colors(plan);
  if (colors.size() > static_cast<size_t>(kPecMaxColors))
    throw std::invalid_argument("PES: " + std::to_string(colors.size()) + " colour blocks; PEC holds at most " +
                                std::to_string(kPecMaxColors));
  const Extent e = extent_of(plan);
  if (e.width() > 0x7FFF || e.height() > 0x7FFF)
    throw std::invalid_argument("PES: the design is larger than the 16-bit size fields");
  const std::vector<int> threads = assign_threads(pec_threads(), colors);
  std::string out;
  pes_part(out, plan, e, threads);
  put_u32_at(out, 8, out.size());
  pec_section(out, plan, e, threads);
  return out;
}

}  // namespace atelier::embroidery

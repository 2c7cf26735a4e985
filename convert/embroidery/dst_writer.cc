#include "convert/embroidery/dst_writer.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "convert/embroidery/stitch_label.h"

namespace atelier::embroidery {
namespace {

constexpr long kMaxMove = 121;  // 1 + 3 + 9 + 27 + 81

// One balanced-ternary digit: its weight, the record byte holding it, and its four bits.
struct Digit {
  int weight;
  int byte;
  std::uint8_t x_plus, x_minus, y_plus, y_minus;
};
constexpr std::array<Digit, 5> kDigits{{
    {81, 2, 0x04, 0x08, 0x20, 0x10},
    {27, 1, 0x04, 0x08, 0x20, 0x10},
    {9, 0, 0x04, 0x08, 0x20, 0x10},
    {3, 1, 0x01, 0x02, 0x80, 0x40},
    {1, 0, 0x01, 0x02, 0x80, 0x40},
}};

void put_axis(long v, bool is_x, std::array<std::uint8_t, 3>& rec) {
  for (const Digit& d : kDigits) {
    const long half = d.weight / 2;  // weights are odd: v > half means this digit is +1
    if (v > half) {
      rec[d.byte] |= is_x ? d.x_plus : d.y_plus;
      v -= d.weight;
    } else if (v < -half) {
      rec[d.byte] |= is_x ? d.x_minus : d.y_minus;
      v += d.weight;
    }
  }
}

class Body {
 public:
  void move(long dx, long dy, bool jump) {
    std::array<std::uint8_t, 3> rec{0, 0, static_cast<std::uint8_t>(jump ? 0x83 : 0x03)};
    put_axis(dx, true, rec);
    put_axis(dy, false, rec);
    append(rec);
    x_ += dx;
    y_ += dy;
    min_x_ = std::min(min_x_, x_);
    max_x_ = std::max(max_x_, x_);
    min_y_ = std::min(min_y_, y_);
    max_y_ = std::max(max_y_, y_);
  }
  void move_to(FileUnits target, bool jump) {
    for (const FileUnits& s : split_move(target.x - x_, target.y - y_, kMaxMove)) move(s.x, s.y, jump);
  }
  void color_change() {
    append({0x00, 0x00, 0xC3});
    ++colors_;
  }
  void end() { append({0x00, 0x00, 0xF3}); }

  std::string bytes;
  long records = 0, colors_ = 0;
  long x_ = 0, y_ = 0, min_x_ = 0, max_x_ = 0, min_y_ = 0, max_y_ = 0;

 private:
  void append(const std::array<std::uint8_t, 3>& rec) {
    bytes.append(reinterpret_cast<const char*>(rec.data()), rec.size());
    ++records;
  }
};

void field(std::string& h, const char* fmt, long v, long max) {
  if (std::labs(v) > max)
    throw std::invalid_argument(std::string("DST header field ") + std::string(fmt, 3) +
                                " cannot hold " + std::to_string(v));
  char buf[32];
  std::snprintf(buf, sizeof buf, fmt, std::labs(v));
  h += buf;
}

void signed_field(std::string& h, const char* name, long v) {
  if (std::labs(v) > 99999)
    throw std::invalid_argument(std::string("DST header field ") + name + " cannot hold " +
                                std::to_string(v));
  char buf[32];
  std::snprintf(buf, sizeof buf, "%s%c%5ld\r", name, v < 0 ? '-' : '+', std::labs(v));
  h += buf;
}

}  // namespace

std::string write_dst(const StitchPlan& plan) {
  validate_plan(plan);
  Body body;
  for (const StitchPoint& p : plan.points) {
    switch (p.kind) {
      case StitchKind::stitch: body.move_to(to_file_units(p), false); break;
      case StitchKind::jump: body.move_to(to_file_units(p), true); break;
      case StitchKind::trim:
        body.move(2, 2, true);
        body.move(-4, -4, true);
        body.move(2, 2, true);
        break;
      case StitchKind::color_change: body.color_change(); break;
      case StitchKind::end: break;  // the one end record is written below
    }
  }
  body.end();

  std::string h = "LA:" + label16(plan.name) + "\r";
  field(h, "ST:%7ld\r", body.records, 9999999);
  field(h, "CO:%3ld\r", body.colors_, 999);
  field(h, "+X:%5ld\r", body.max_x_, 99999);
  field(h, "-X:%5ld\r", body.min_x_, 99999);
  field(h, "+Y:%5ld\r", body.max_y_, 99999);
  field(h, "-Y:%5ld\r", body.min_y_, 99999);
  signed_field(h, "AX:", body.x_);
  signed_field(h, "AY:", body.y_);
  signed_field(h, "MX:", 0);
  signed_field(h, "MY:", 0);
  h += "PD:******\r";
  h += '\x1A';
  h.resize(512, ' ');
  return h + body.bytes;
}

}  // namespace atelier::embroidery

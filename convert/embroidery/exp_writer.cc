#include "convert/embroidery/exp_writer.h"

namespace atelier::embroidery {
namespace {

constexpr long kMaxMove = 127;  // -128 (0x80) would read as the control escape

char byte_of(long v) { return static_cast<char>(static_cast<signed char>(v)); }

}  // namespace

std::string write_exp(const StitchPlan& plan) {
  validate_plan(plan);
  std::string out;
  FileUnits at;
  auto move_to = [&](FileUnits target, bool jump) {
    for (const FileUnits& s : split_move(target.x - at.x, target.y - at.y, kMaxMove)) {
      if (jump) out += "\x80\x04";
      out += byte_of(s.x);
      out += byte_of(s.y);
    }
    at = target;
  };
  for (const StitchPoint& p : plan.points) {
    switch (p.kind) {
      case StitchKind::stitch: move_to(to_file_units(p), false); break;
      case StitchKind::jump: move_to(to_file_units(p), true); break;
      case StitchKind::trim: out.append("\x80\x80\x07\x00", 4); break;
      case StitchKind::color_change: out.append("\x80\x01\x00\x00", 4); break;
      case StitchKind::end: break;  // EXP has no end code (see exp_writer.h)
    }
  }
  return out;
}

}  // namespace atelier::embroidery

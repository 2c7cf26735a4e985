// Embroidery stitch files (DST, EXP) checked by readers written here from the formats file
// (shared/protocols/embroidery-formats.md), independently of the writers: record ranges, the
// DST header against the decoded body, end code, positions after accumulating, splitting of
// long moves, trims, colour changes, and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "convert/embroidery/dst_writer.h"
#include "convert/embroidery/exp_writer.h"
#include "algorithms/embroidery/stitch_plan.h"
#include "tests/unit/stitch_file_readers.h"

namespace atelier::embroidery {
namespace {

using namespace atelier::embroidery::test;

// ---- Checks shared by both formats --------------------------------------------------------
// Walks the plan against the decoded records (trims folded): every stitch and jump of the plan
// is reached by one or more records of its kind, each within +-max_units, of near-equal size
// (pieces of one move differ by at most 1 unit), ending within 0.05 mm of the plan's absolute
// position (image y = -file y); trims and colour changes appear in order. Returns the index of
// the first record not consumed.
size_t expect_round_trip(const StitchPlan& plan, const std::vector<Rec>& recs, int max_units) {
  size_t k = 0;
  long x = 0, y = 0;  // accumulated file units
  int moves_checked = 0;
  for (size_t p = 0; p < plan.points.size(); ++p) {
    const StitchPoint& pt = plan.points[p];
    if (pt.kind == StitchKind::end) continue;
    if (pt.kind == StitchKind::trim || pt.kind == StitchKind::color_change) {
      const Ev want = pt.kind == StitchKind::trim ? Ev::trim : Ev::color;
      EXPECT_LT(k, recs.size()) << "point " << p;
      if (k >= recs.size()) return k;
      EXPECT_EQ(static_cast<int>(recs[k].type), static_cast<int>(want)) << "point " << p;
      ++k;
      continue;
    }
    const Ev want = pt.kind == StitchKind::stitch ? Ev::stitch : Ev::jump;
    int min_dx = 1 << 20, max_dx = -(1 << 20), min_dy = 1 << 20, max_dy = -(1 << 20);
    bool reached = false;
    while (!reached) {
      EXPECT_LT(k, recs.size()) << "point " << p << " never reached";
      if (k >= recs.size()) return k;
      const Rec& r = recs[k++];
      EXPECT_EQ(static_cast<int>(r.type), static_cast<int>(want)) << "point " << p;
      EXPECT_LE(std::abs(r.dx), max_units);
      EXPECT_LE(std::abs(r.dy), max_units);
      min_dx = std::min(min_dx, r.dx), max_dx = std::max(max_dx, r.dx);
      min_dy = std::min(min_dy, r.dy), max_dy = std::max(max_dy, r.dy);
      x += r.dx;
      y += r.dy;
      reached = std::abs(x / 10.0 - pt.x_mm) <= 0.05 + 1e-9 &&
                std::abs(-y / 10.0 - pt.y_mm) <= 0.05 + 1e-9;
    }
    EXPECT_LE(max_dx - min_dx, 1) << "unequal pieces for point " << p;
    EXPECT_LE(max_dy - min_dy, 1) << "unequal pieces for point " << p;
    ++moves_checked;
  }
  EXPECT_GT(moves_checked, 0);
  return k;
}

// A design with everything: a start run, a 30 mm stitch, 100 tiny stitches whose moves round
// badly (0.26 mm each), a trim, a 40 mm jump, two colour changes, negative coordinates.
StitchPlan mixed_plan() {
  StitchPlan plan;
  plan.name = "test design";
  plan.colors_rgb = {0xff0000, 0x00ff00, 0x0000ff};
  auto add = [&](double x, double y, StitchKind k = StitchKind::stitch) {
    plan.points.push_back({x, y, k});
  };
  add(1, 1);
  add(2.5, 1);
  add(32.5, 1);  // 30 mm: 300 units, split in DST and EXP
  for (int i = 1; i <= 100; ++i) add(32.5 + 0.26 * i, 1 + 0.13 * i);  // ends at 58.5, 14
  add(0, 0, StitchKind::trim);
  add(58.5, 54, StitchKind::jump);  // 40 mm jump straight down
  add(0, 0, StitchKind::color_change);
  add(57, 55);
  add(-10.04, 60.06);
  add(0, 0, StitchKind::trim);
  add(-20, -5, StitchKind::jump);
  add(0, 0, StitchKind::color_change);
  add(-21.5, -5);
  add(-21.5, -6.5);
  add(0, 0, StitchKind::end);
  return plan;
}

TEST(EmbroideryDst, KnownRecordBytes) {
  StitchPlan plan;
  plan.points = {{0.1, 0}, {0.1, -0.1}, {0.1, 12.0, StitchKind::jump}};
  const std::string f = write_dst(plan);
  ASSERT_EQ(f.size(), 512u + 4 * 3);
  const auto b = [&](size_t i) { return static_cast<std::uint8_t>(f[512 + i]); };
  // x+1 stitch.
  EXPECT_EQ(b(0), 0x01);
  EXPECT_EQ(b(1), 0x00);
  EXPECT_EQ(b(2), 0x03);
  // y is up in the file: image y -0.1 mm is y+1.
  EXPECT_EQ(b(3), 0x80);
  EXPECT_EQ(b(4), 0x00);
  EXPECT_EQ(b(5), 0x03);
  // jump of image +12.1 mm down = file y -121 = -81 -27 -9 -3 -1.
  EXPECT_EQ(b(6), 0x50);
  EXPECT_EQ(b(7), 0x50);
  EXPECT_EQ(b(8), 0x93);
  // End of design.
  EXPECT_EQ(b(9), 0x00);
  EXPECT_EQ(b(10), 0x00);
  EXPECT_EQ(b(11), 0xF3);
}

TEST(EmbroideryDst, RecordsDecodeInRangeAndHeaderMatchesBody) {
  const StitchPlan plan = mixed_plan();
  const std::string bytes = write_dst(plan);
  const DstFile f = read_dst(bytes);
  EXPECT_TRUE(f.errors.empty()) << f.errors.front();
  ASSERT_FALSE(f.records.empty());
  EXPECT_EQ(static_cast<int>(f.records.back().type), static_cast<int>(Ev::end));
  long x = 0, y = 0, min_x = 0, max_x = 0, min_y = 0, max_y = 0;
  int colors = 0, ends = 0;
  for (const Rec& r : f.records) {
    EXPECT_LE(std::abs(r.dx), 121);
    EXPECT_LE(std::abs(r.dy), 121);
    x += r.dx, y += r.dy;
    min_x = std::min(min_x, x), max_x = std::max(max_x, x);
    min_y = std::min(min_y, y), max_y = std::max(max_y, y);
    colors += r.type == Ev::color;
    ends += r.type == Ev::end;
  }
  EXPECT_EQ(ends, 1);
  EXPECT_EQ(colors, 2);
  // The 512-byte header: fields, then 0x1A and spaces.
  EXPECT_EQ(f.header.at("LA"), "test design     ");
  EXPECT_EQ(f.header.at("ST"), std::string(7 - std::to_string(f.records.size()).size(), ' ') +
                                   std::to_string(f.records.size()));
  EXPECT_EQ(num(f.header.at("ST")), static_cast<long>(f.records.size()));
  EXPECT_EQ(f.header.at("CO"), "  2");
  EXPECT_EQ(f.header.at("+X").size(), 5u);
  EXPECT_EQ(num(f.header.at("+X")), max_x);
  EXPECT_EQ(num(f.header.at("-X")), -min_x);
  EXPECT_EQ(num(f.header.at("+Y")), max_y);
  EXPECT_EQ(num(f.header.at("-Y")), -min_y);
  EXPECT_GT(max_x, 580);  // the design really reaches x = 58.5 mm
  EXPECT_GE(-min_y, 600);  // and image y = 60 mm (file y down)
  EXPECT_EQ(f.header.at("AX").size(), 6u);
  EXPECT_EQ(num(f.header.at("AX")), x);
  EXPECT_EQ(num(f.header.at("AY")), y);
  EXPECT_EQ(x, -215);
  EXPECT_EQ(y, 65);
  EXPECT_EQ(f.header.at("MX"), "+    0");
  EXPECT_EQ(f.header.at("PD"), "******");
  ASSERT_FALSE(f.header_tail.empty());
  EXPECT_EQ(f.header_tail[0], '\x1A');
  EXPECT_EQ(f.header_tail.substr(1), std::string(f.header_tail.size() - 1, ' '));
}

TEST(EmbroideryDst, RoundTripGivesBackEveryPositionSplitsLongMovesAndTrims) {
  const StitchPlan plan = mixed_plan();
  const DstFile f = read_dst(write_dst(plan));
  ASSERT_TRUE(f.errors.empty()) << f.errors.front();
  const std::vector<Rec> recs = fold_dst_trims(f.records);
  const size_t used = expect_round_trip(plan, recs, 121);
  ASSERT_EQ(used + 1, recs.size());  // only the end record is left
  EXPECT_EQ(static_cast<int>(recs.back().type), static_cast<int>(Ev::end));

  // The 30 mm stitch is three stitches of 10 mm; the 40 mm jump four jumps of 10 mm.
  EXPECT_EQ(recs[2].dx, 100);
  EXPECT_EQ(recs[3].dx, 100);
  EXPECT_EQ(recs[4].dx, 100);
  EXPECT_EQ(static_cast<int>(recs[4].type), static_cast<int>(Ev::stitch));
  size_t trim = 0;
  while (recs[trim].type != Ev::trim) ++trim;
  EXPECT_EQ(trim, 105u);
  for (size_t k = trim + 1; k < trim + 5; ++k) {
    EXPECT_EQ(static_cast<int>(recs[k].type), static_cast<int>(Ev::jump));
    EXPECT_EQ(recs[k].dx, 0);
    EXPECT_EQ(recs[k].dy, -100);
  }
  EXPECT_EQ(static_cast<int>(recs[trim + 5].type), static_cast<int>(Ev::color));
  // The raw trim: jumps (+2,+2), (-4,-4), (+2,+2).
  const Rec* raw = &f.records[trim];
  EXPECT_EQ(static_cast<int>(raw[0].type), static_cast<int>(Ev::jump));
  EXPECT_EQ(raw[0].dx, 2);
  EXPECT_EQ(raw[0].dy, 2);
  EXPECT_EQ(raw[1].dx, -4);
  EXPECT_EQ(raw[1].dy, -4);
  EXPECT_EQ(raw[2].dx, 2);
  EXPECT_EQ(raw[2].dy, 2);
}

TEST(EmbroideryDst, LabelIsAsciiPaddedAndCut) {
  StitchPlan plan;
  plan.name = "Ros\xC3\xA9 garden with a long name";
  plan.points = {{1, 1}};
  EXPECT_EQ(read_dst(write_dst(plan)).header.at("LA"), "Ros_ garden with");
  plan.name = "";
  const DstFile f = read_dst(write_dst(plan));
  EXPECT_EQ(f.header.at("LA"), std::string(16, ' '));
  EXPECT_EQ(f.header.at("CO"), "  0");
  EXPECT_EQ(f.records.size(), 2u);  // the stitch and the end record
}

TEST(EmbroideryExp, RoundTripGivesBackEveryPositionSplitsLongMovesAndHasNoEndCode) {
  const StitchPlan plan = mixed_plan();
  const std::string bytes = write_exp(plan);
  const ExpFile f = read_exp(bytes);
  ASSERT_TRUE(f.errors.empty()) << f.errors.front();
  for (const Rec& r : f.records) {
    EXPECT_LE(std::abs(r.dx), 127);
    EXPECT_LE(std::abs(r.dy), 127);
  }
  const size_t used = expect_round_trip(plan, f.records, 127);
  EXPECT_EQ(used, f.records.size());  // nothing after the last stitch: EXP has no end code
  // The 30 mm stitch is three stitches of 10 mm (300 > 2 * 127).
  EXPECT_EQ(f.records[2].dx, 100);
  EXPECT_EQ(f.records[4].dx, 100);
  EXPECT_EQ(static_cast<int>(f.records[4].type), static_cast<int>(Ev::stitch));
  // The last stitch, -1.5 mm in image y, is +15 in the file (y up, like DST).
  EXPECT_EQ(bytes.substr(bytes.size() - 2), std::string("\x00\x0F", 2));
  // The trim is the native 80 80 07 00; the 40 mm jump four 80 04 records of 10 mm down.
  size_t trim = 0;
  while (f.records[trim].type != Ev::trim) ++trim;
  for (size_t k = trim + 1; k < trim + 5; ++k) {
    EXPECT_EQ(static_cast<int>(f.records[k].type), static_cast<int>(Ev::jump));
    EXPECT_EQ(f.records[k].dy, -100);
  }
  EXPECT_NE(bytes.find(std::string("\x80\x04\x00\x9C", 4)), std::string::npos);  // dy = -100
}

TEST(EmbroideryFiles, ColoursAndFortyMillimetreJump) {
  StitchPlan plan;
  plan.name = "three colours";
  plan.colors_rgb = {0x112233, 0x445566, 0x778899};
  plan.points = {{0, 0},
                 {2, 0},
                 {2, 2},
                 {0, 0, StitchKind::color_change},
                 {2, 4},
                 {0, 0, StitchKind::trim},
                 {42, 4, StitchKind::jump},
                 {0, 0, StitchKind::color_change},
                 {42, 6},
                 {44, 6}};
  const StitchStats s = stitch_stats(plan);
  EXPECT_EQ(s.stitches, 6);
  EXPECT_EQ(s.jumps, 1);
  EXPECT_EQ(s.trims, 1);
  EXPECT_EQ(s.color_changes, 2);
  EXPECT_DOUBLE_EQ(s.min_x_mm, 0);
  EXPECT_DOUBLE_EQ(s.max_x_mm, 44);
  EXPECT_DOUBLE_EQ(s.max_y_mm, 6);

  const DstFile d = read_dst(write_dst(plan));
  ASSERT_TRUE(d.errors.empty()) << d.errors.front();
  EXPECT_EQ(d.header.at("CO"), "  2");
  const std::vector<Rec> drecs = fold_dst_trims(d.records);
  expect_round_trip(plan, drecs, 121);
  int djumps = 0;
  for (const Rec& r : drecs) djumps += r.type == Ev::jump;
  EXPECT_EQ(djumps, 4);  // 400 units need ceil(400 / 121) = 4 jumps
  EXPECT_EQ(num(d.header.at("+X")), 440);
  EXPECT_EQ(num(d.header.at("-Y")), 60);
  EXPECT_EQ(num(d.header.at("+Y")), 0);  // the design lies below its start point

  const ExpFile e = read_exp(write_exp(plan));
  ASSERT_TRUE(e.errors.empty()) << e.errors.front();
  expect_round_trip(plan, e.records, 127);
  int ejumps = 0, ecolors = 0;
  for (const Rec& r : e.records) ejumps += r.type == Ev::jump, ecolors += r.type == Ev::color;
  EXPECT_EQ(ejumps, 4);  // ceil(400 / 127) = 4
  EXPECT_EQ(ecolors, 2);
}

TEST(EmbroideryFiles, BadInputIsRejected) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  StitchPlan plan;
  plan.points = {{1, 1}, {nan, 2}};
  EXPECT_THROW(write_dst(plan), std::invalid_argument);
  EXPECT_THROW(write_exp(plan), std::invalid_argument);
  plan.points = {{1, 1}, {2, std::numeric_limits<double>::infinity(), StitchKind::jump}};
  EXPECT_THROW(write_dst(plan), std::invalid_argument);
  EXPECT_THROW(write_exp(plan), std::invalid_argument);
  plan.points = {{1, 1}, {0, 0, StitchKind::end}, {2, 2}};
  EXPECT_THROW(write_dst(plan), std::invalid_argument);
  EXPECT_THROW(write_exp(plan), std::invalid_argument);
  // A NaN position on a colour change is ignored, as documented.
  plan.points = {{1, 1}, {nan, nan, StitchKind::color_change}, {2, 2}};
  EXPECT_NO_THROW(write_dst(plan));
}

}  // namespace
}  // namespace atelier::embroidery

// DST files (convert/embroidery/dst_writer.h) read by a reader written from the formats file, not
// the writer: record bytes and ranges, header against body, end code, split moves, trims, label.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "algorithms/embroidery/stitch_plan.h"
#include "convert/embroidery/dst_writer.h"
#include "tests/unit/convert/embroidery/stitch_file_fixture.h"
#include "tests/support/stitch_file_readers.h"

namespace atelier::embroidery {
namespace {

using namespace atelier::embroidery::test;

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

}  // namespace
}  // namespace atelier::embroidery

// JEF files (convert/embroidery/jef_writer.h) read by a reader written from the format
// descriptions (tests/support/pes_jef_readers.h), not the writer: header fields against the
// body, hoop codes from the extent, records, trims, colour changes, positions equal to DST's,
// long moves split, Janome thread indices nearest and distinct.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "algorithms/embroidery/stitch_plan.h"
#include "convert/embroidery/dst_writer.h"
#include "convert/embroidery/jef_writer.h"
#include "convert/embroidery/thread_palettes.h"
#include "tests/support/pes_jef_readers.h"
#include "tests/support/stitch_file_readers.h"
#include "tests/unit/convert/embroidery/stitch_file_fixture.h"

namespace atelier::embroidery {
namespace {

using namespace atelier::embroidery::test;

constexpr const char* kDate = "20261203054000";

int count(const std::vector<Rec>& recs, Ev e) {
  int n = 0;
  for (const Rec& r : recs) n += r.type == e;
  return n;
}

// A rectangle of stitches from (x0, y0) to (x1, y1) mm around the start point.
StitchPlan rectangle(double x0, double y0, double x1, double y1) {
  StitchPlan plan;
  plan.colors_rgb = {0x000000};
  plan.points = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}, {x0, y0}};
  return plan;
}

TEST(EmbroideryJef, KnownBytes) {
  StitchPlan plan;
  plan.colors_rgb = {0xffffff, 0x000000};
  plan.points = {{0.1, 0},  {0.1, -0.2},  {0, 0, StitchKind::trim}, {-12.6, -0.2, StitchKind::jump},
                 {0, 0, StitchKind::color_change}, {-12.7, -0.2}, {0, 0, StitchKind::end}};
  const std::string f = write_jef(plan, kDate);
  const size_t body = 0x74 + 8 * 2;
  ASSERT_EQ(f.size(), body + 2 + 2 + 12 + 4 + 4 + 2 + 2);
  auto u32 = [&](size_t at) {
    return static_cast<std::uint32_t>(static_cast<std::uint8_t>(f[at]) | static_cast<std::uint8_t>(f[at + 1]) << 8 |
                                      static_cast<std::uint8_t>(f[at + 2]) << 16 | static_cast<std::uint8_t>(f[at + 3]) << 24);
  };
  EXPECT_EQ(u32(0), body);
  EXPECT_EQ(u32(4), 0x14u);
  EXPECT_EQ(f.substr(8, 14), kDate);
  EXPECT_EQ(u32(24), 2u);                 // threads
  EXPECT_EQ(u32(28), (f.size() - body) / 2);  // stitch count in 2-byte words
  EXPECT_EQ(u32(0x74), 2u);               // Janome "White"
  EXPECT_EQ(u32(0x78), 1u);               // "Black"
  EXPECT_EQ(u32(0x7C), 0x0Du);
  EXPECT_EQ(u32(0x80), 0x0Du);
  const std::string want{
      "\x01\x00"                                      // x+1
      "\x00\x02"                                      // image y -0.2 mm is up: +2
      "\x80\x02\x00\x00\x80\x02\x00\x00\x80\x02\x00\x00"  // trim: three zero jumps
      "\x80\x02\x81\x00"                              // jump x -127
      "\x80\x01\x00\x00"                              // colour change
      "\xFF\x00"                                      // x -1
      "\x80\x10",                                     // end
      2 + 2 + 12 + 4 + 4 + 2 + 2};
  EXPECT_EQ(f.substr(body), want);
}

TEST(EmbroideryJef, HeaderMatchesTheBodyAndRecordsGiveBackTheDstPositions) {
  const StitchPlan plan = mixed_plan();
  const std::string bytes = write_jef(plan, kDate);
  const JefFile f = read_jef(bytes);
  ASSERT_TRUE(f.errors.empty()) << f.errors.front();
  EXPECT_EQ(f.flags, 0x14);
  EXPECT_EQ(f.date, kDate);
  EXPECT_EQ(f.threads_count, 3);
  EXPECT_EQ(f.stitch_count, f.body_words);
  EXPECT_EQ(f.thread_types, (std::vector<long>{13, 13, 13}));
  // Extents from the start point: x -21.5 .. 58.5 mm, image y -6.5 .. 60.06 mm (y up: top 6.5).
  EXPECT_EQ(f.extents[0], 215);
  EXPECT_EQ(f.extents[1], 65);
  EXPECT_EQ(f.extents[2], 585);
  EXPECT_EQ(f.extents[3], 601);
  // 117 x 120.2 mm centred on the start point: only the 140 x 200 hoop takes it.
  EXPECT_EQ(f.hoop, 2);
  for (long v : f.edges[0]) EXPECT_EQ(v, -1);  // 110 x 110
  for (long v : f.edges[1]) EXPECT_EQ(v, -1);  // 50 x 50
  EXPECT_EQ(f.edges[2][0], 700 - 215);
  EXPECT_EQ(f.edges[2][1], 1000 - 65);
  EXPECT_EQ(f.edges[2][2], 700 - 585);
  EXPECT_EQ(f.edges[2][3], 1000 - 601);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(f.edges[3][k], f.edges[2][k]);  // the chosen hoop

  const size_t used = expect_round_trip(plan, f.records, 127);
  EXPECT_EQ(used + 1, f.records.size());
  const StitchStats st = stitch_stats(plan);
  EXPECT_EQ(count(f.records, Ev::trim), st.trims);
  EXPECT_EQ(count(f.records, Ev::color), st.color_changes);
  EXPECT_EQ(count(f.records, Ev::end), 1);
  // Absolute positions equal DST's: both end where the plan does, and every record is a DST
  // record of the same moves (121 vs 127 split the 30 mm stitch alike: 3 x 10 mm).
  const DstFile dst = read_dst(write_dst(plan));
  long jx = 0, jy = 0, dx = 0, dy = 0;
  for (const Rec& r : f.records) jx += r.dx, jy += r.dy;
  for (const Rec& r : fold_dst_trims(dst.records)) dx += r.dx, dy += r.dy;
  EXPECT_EQ(jx, dx);
  EXPECT_EQ(jy, dy);
  EXPECT_EQ(count(f.records, Ev::stitch), count(fold_dst_trims(dst.records), Ev::stitch));
}

TEST(EmbroideryJef, TheHoopCodeIsTheSmallestJanomeHoopTheDesignFits) {
  struct Case {
    double half_w, half_h;
    long code;
  } cases[] = {{24, 24, 1}, {54, 54, 0}, {62, 54, 3}, {69, 99, 2}, {99, 99, 4}, {150, 150, 4}};
  for (const Case& c : cases) {
    const JefFile f = read_jef(write_jef(rectangle(-c.half_w, -c.half_h, c.half_w, c.half_h), kDate));
    ASSERT_TRUE(f.errors.empty()) << f.errors.front();
    EXPECT_EQ(f.hoop, c.code) << c.half_w << " x " << c.half_h;
  }
  // Off-centre: 40 mm wide but reaching 30 mm right of the start point does not fit 50 x 50.
  EXPECT_EQ(read_jef(write_jef(rectangle(-10, -10, 30, 10), kDate)).hoop, 0);
}

TEST(EmbroideryJef, LongMovesAreSplitWithinAByte) {
  StitchPlan plan;
  plan.colors_rgb = {0x0000ff};
  plan.points = {{1, 1}, {0, 0, StitchKind::trim}, {1, 41, StitchKind::jump}, {1, 42}, {31, 42}};
  const JefFile f = read_jef(write_jef(plan, kDate));
  ASSERT_TRUE(f.errors.empty()) << f.errors.front();
  expect_round_trip(plan, f.records, 127);
  // 40 mm of jump: four of 10 mm; 30 mm of stitch: three of 10 mm.
  EXPECT_EQ(count(f.records, Ev::jump), 4);
  EXPECT_EQ(count(f.records, Ev::stitch), 1 + 1 + 3);
  EXPECT_EQ(count(f.records, Ev::trim), 1);
}

TEST(EmbroideryJef, ThreadsAreJanomesNearestAndDistinctColoursStayDistinct) {
  StitchPlan plan;
  plan.colors_rgb = {0x789878, 0xD89878, 0x78B8B8, 0x7878A8, 0xff0000};
  for (int b = 0; b < 5; ++b) {
    if (b) plan.points.push_back({0, 0, StitchKind::color_change});
    plan.points.push_back({1.0 * b, 0});
  }
  const JefFile f = read_jef(write_jef(plan, kDate));
  ASSERT_TRUE(f.errors.empty()) << f.errors.front();
  ASSERT_EQ(f.threads.size(), 5u);
  for (long t : f.threads) {
    EXPECT_GE(t, 1);
    EXPECT_LE(t, 78);
  }
  for (size_t a = 0; a < 5; ++a)
    for (size_t b = a + 1; b < 5; ++b) EXPECT_NE(f.threads[a], f.threads[b]);
  EXPECT_EQ(f.threads[4], 10);  // Janome "Red" for pure red
  const std::uint32_t c = plan.colors_rgb[0];
  const double d = color_difference(c, jef_threads()[static_cast<size_t>(f.threads[0] - 1)].rgb);
  for (const Thread& t : jef_threads()) EXPECT_LE(d, color_difference(c, t.rgb) + 1e-9) << t.name;
}

TEST(EmbroideryJef, AMalformedDateIsRefused) {
  EXPECT_THROW(write_jef(rectangle(0, 0, 1, 1), "2026-12-03"), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::embroidery

// PES files (convert/embroidery/pes_writer.h) read by a reader written from the format
// descriptions (tests/support/pes_jef_readers.h), not the writer: the PES part points at the
// PEC section, PEC's header, moves, trims, colour changes and thumbnails, positions equal to
// DST's, long moves split, thread indices nearest and distinct.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "algorithms/embroidery/stitch_plan.h"
#include "convert/embroidery/dst_writer.h"
#include "convert/embroidery/pes_writer.h"
#include "convert/embroidery/thread_palettes.h"
#include "tests/support/pes_jef_readers.h"
#include "tests/support/stitch_file_readers.h"
#include "tests/unit/convert/embroidery/stitch_file_fixture.h"

namespace atelier::embroidery {
namespace {

using namespace atelier::embroidery::test;

std::string bytes_of(std::initializer_list<int> v) {
  std::string out;
  for (int b : v) out += static_cast<char>(b);
  return out;
}

int count(const std::vector<Rec>& recs, Ev e) {
  int n = 0;
  for (const Rec& r : recs) n += r.type == e;
  return n;
}

// Absolute positions (file units, y up) after each plan stitch or jump, walking the records as
// expect_round_trip does: the position where the plan point is reached.
std::vector<std::pair<long, long>> plan_positions(const StitchPlan& plan, const std::vector<Rec>& recs) {
  std::vector<std::pair<long, long>> out;
  size_t k = 0;
  long x = 0, y = 0;
  for (const StitchPoint& p : plan.points) {
    if (p.kind == StitchKind::trim || p.kind == StitchKind::color_change) {
      ++k;
      continue;
    }
    if (!is_positioned(p.kind)) continue;
    while (k < recs.size()) {
      x += recs[k].dx, y += recs[k].dy;
      ++k;
      if (std::abs(x / 10.0 - p.x_mm) <= 0.05 + 1e-9 && std::abs(-y / 10.0 - p.y_mm) <= 0.05 + 1e-9) break;
    }
    out.push_back({x, y});
  }
  return out;
}

TEST(EmbroideryPes, KnownBytesOfThePecMoves) {
  StitchPlan plan;
  plan.colors_rgb = {0xED171F, 0x000000};  // Brother's own red and black
  plan.points = {{0.1, 0},  {0.1, 10.1},  {0, 0, StitchKind::trim}, {-20.0, 10.1, StitchKind::jump},
                 {0, 0, StitchKind::color_change}, {-26.4, 10.1}, {0, 0, StitchKind::end}};
  const std::string bytes = write_pes(plan);
  const PesFile f = read_pes(bytes);
  ASSERT_TRUE(f.errors.empty()) << f.errors.front();
  const std::string moves = bytes.substr(f.stitch_block + 16, f.end_code + 1 - (f.stitch_block + 16));
  const std::string want = bytes_of({
      0x01, 0x00,              // x+1: 7-bit; y 0
      0x00, 0x80, 0x65,        // x 0; y+101 (down): 12-bit, no flag
      0xAF, 0x37, 0xA0, 0x00,  // the first move after the trim: trim flag, x -201, y 0
      0xFE, 0xB0, 0x02,        // colour change
      0x40, 0x00,              // x -64 is still 7-bit; y 0
      0xFF});                  // end
  EXPECT_EQ(moves, want);
  EXPECT_EQ(f.threads, (std::vector<int>{nearest_thread(pec_threads(), 0xED171F), nearest_thread(pec_threads(), 0)}));
  EXPECT_EQ(f.threads[0], 5);   // Brother's "Red"
  EXPECT_EQ(f.threads[1], 20);  // "Black"
}

TEST(EmbroideryPes, HeaderPointsAtThePecSectionWhoseFieldsMatchTheDesign) {
  const StitchPlan plan = mixed_plan();
  const std::string bytes = write_pes(plan);
  const PesFile f = read_pes(bytes);
  ASSERT_TRUE(f.errors.empty()) << f.errors.front();
  EXPECT_EQ(f.signature, "#PES0001");
  EXPECT_EQ(bytes.substr(f.pec_offset, 3), "LA:");
  EXPECT_EQ(f.label, "test design     ");
  EXPECT_EQ(f.scale_to_fit, 1);
  EXPECT_EQ(f.blocks, 1);
  EXPECT_EQ(f.thumb_stride, 6);
  EXPECT_EQ(f.thumb_height, 38);
  EXPECT_EQ(f.threads.size(), 3u);  // three colour blocks
  // The extent: x -21.5 .. 58.5 mm, y -6.5 .. 60.06 mm.
  EXPECT_EQ(f.width, 800);
  EXPECT_EQ(f.height, 666);
  EXPECT_EQ(f.block_width, 800);
  EXPECT_EQ(f.block_height, 666);
  EXPECT_EQ(f.hoop, 0);  // fits 100 x 100 mm
  // Identity affine; the design centred in PE-Design's hoop (350, 100 from the page corner).
  EXPECT_EQ(f.affine[0], 1.0f);
  EXPECT_EQ(f.affine[1], 0.0f);
  EXPECT_EQ(f.affine[2], 0.0f);
  EXPECT_EQ(f.affine[3], 1.0f);
  EXPECT_FLOAT_EQ(f.affine[4], 350 + 500 - 400);
  EXPECT_FLOAT_EQ(f.affine[5], 100 + 666 + 500 - 333);
  // The design plus one thumbnail per colour block, 48 x 38 at 1 bit.
  ASSERT_EQ(f.thumbs.size(), 4u);
  for (const std::string& t : f.thumbs) EXPECT_EQ(t.size(), 228u);
  EXPECT_EQ(f.stitch_block + f.stitch_block_length + 4 * 228, bytes.size());
}

TEST(EmbroideryPes, MovesGiveBackEveryPositionOfTheDstWithTheCountsOfThePlan) {
  const StitchPlan plan = mixed_plan();
  const PesFile f = read_pes(write_pes(plan));
  ASSERT_TRUE(f.errors.empty()) << f.errors.front();
  const std::vector<Rec> recs = y_up(f.records);
  const size_t used = expect_round_trip(plan, recs, 2047);
  EXPECT_EQ(used + 1, recs.size());  // only the end code is left
  const StitchStats st = stitch_stats(plan);
  EXPECT_EQ(count(recs, Ev::trim), st.trims);
  EXPECT_EQ(count(recs, Ev::color), st.color_changes);
  EXPECT_EQ(count(recs, Ev::stitch), st.stitches);  // no stitch of the plan is over 204.7 mm
  EXPECT_EQ(count(recs, Ev::end), 1);
  const DstFile dst = read_dst(write_dst(plan));
  ASSERT_TRUE(dst.errors.empty());
  const auto pes_at = plan_positions(plan, recs), dst_at = plan_positions(plan, fold_dst_trims(dst.records));
  ASSERT_EQ(pes_at.size(), dst_at.size());
  for (size_t i = 0; i < pes_at.size(); ++i) {
    EXPECT_LE(std::abs(pes_at[i].first - dst_at[i].first), 1) << "point " << i;  // 0.1 mm
    EXPECT_LE(std::abs(pes_at[i].second - dst_at[i].second), 1) << "point " << i;
  }
}

TEST(EmbroideryPes, SewSegmentsHoldTheAbsolutePositionsAndTheColourLog) {
  const StitchPlan plan = mixed_plan();
  const PesFile f = read_pes(write_pes(plan));
  ASSERT_TRUE(f.errors.empty()) << f.errors.front();
  // Every stitch of the plan, in order, in the stitch segments, relative to the design's left
  // and bottom edges (x -21.5 mm, image y 60.06 mm), colours by block.
  std::vector<std::pair<int, int>> want;
  for (const StitchPoint& p : plan.points)
    if (p.kind == StitchKind::stitch)
      want.push_back({static_cast<int>(std::lround(p.x_mm * 10) + 215), static_cast<int>(std::lround(p.y_mm * 10) - 601)});
  std::vector<std::pair<int, int>> got;
  int jumps = 0;
  for (const PesSegment& s : f.segments) {
    if (s.flag == 1) {
      ++jumps;
      EXPECT_EQ(s.points.size(), 2u);
      continue;
    }
    got.insert(got.end(), s.points.begin(), s.points.end());
  }
  EXPECT_EQ(got, want);
  EXPECT_EQ(jumps, 2);
  ASSERT_EQ(f.color_log.size(), 3u);
  EXPECT_EQ(f.color_log[0].first, 0);
  for (size_t c = 0; c < 3; ++c) EXPECT_EQ(f.color_log[c].second, f.threads[c]);
  for (const PesSegment& s : f.segments) EXPECT_GE(s.color, 1);
}

TEST(EmbroideryPes, LongMovesAreSplitWithinTwelveBits) {
  StitchPlan plan;
  plan.colors_rgb = {0x0000ff};
  plan.points = {{1, 1}, {0, 0, StitchKind::trim}, {1, 251, StitchKind::jump}, {1, 252}, {1, -200}};
  const PesFile f = read_pes(write_pes(plan));
  ASSERT_TRUE(f.errors.empty()) << f.errors.front();
  const std::vector<Rec> recs = y_up(f.records);
  expect_round_trip(plan, recs, 2047);
  // 250 mm of jump: a trimmed move and a jump of 125 mm each; 452 mm of stitch: three of 150.7.
  ASSERT_GE(recs.size(), 8u);
  EXPECT_EQ(static_cast<int>(recs[1].type), static_cast<int>(Ev::trim));
  EXPECT_EQ(recs[2].dy, -1250);
  EXPECT_EQ(recs[3].dy, -1250);
  EXPECT_EQ(count(recs, Ev::jump), 2);
  EXPECT_EQ(count(recs, Ev::stitch), 1 + 1 + 3);
  EXPECT_EQ(f.hoop, 1);  // over 100 mm: the 130 x 180 hoop
}

TEST(EmbroideryPes, ThumbnailsShowTheDesignAndEachColourWhereItIs) {
  // Colour 1 a square on the left, colour 2 one on the right.
  StitchPlan plan;
  plan.colors_rgb = {0xff0000, 0x00ff00};
  auto square = [&](double x0) {
    for (double y = 0; y <= 20; y += 2) plan.points.push_back({x0, y}), plan.points.push_back({x0 + 20, y});
  };
  square(-40);
  plan.points.push_back({0, 0, StitchKind::trim});
  plan.points.push_back({20, 0, StitchKind::jump});
  plan.points.push_back({0, 0, StitchKind::color_change});
  square(20);
  const PesFile f = read_pes(write_pes(plan));
  ASSERT_TRUE(f.errors.empty()) << f.errors.front();
  ASSERT_EQ(f.thumbs.size(), 3u);
  // Inside the frame (x 3..44, y 3..34): pixels set left / right of the middle.
  auto inside = [&](const std::string& t, int& left, int& right) {
    left = right = 0;
    for (int y = 3; y <= 34; ++y)
      for (int x = 3; x <= 44; ++x)
        if (thumb_bit(t, 6, x, y)) (x < 24 ? left : right)++;
  };
  int l = 0, r = 0;
  inside(f.thumbs[0], l, r);
  EXPECT_GT(l, 50);
  EXPECT_GT(r, 50);
  inside(f.thumbs[1], l, r);
  EXPECT_GT(l, 50);
  EXPECT_EQ(r, 0);
  inside(f.thumbs[2], l, r);
  EXPECT_EQ(l, 0);
  EXPECT_GT(r, 50);
  // The frame: the top edge is drawn, the corner pixel is not.
  EXPECT_TRUE(thumb_bit(f.thumbs[1], 6, 24, 1));
  EXPECT_FALSE(thumb_bit(f.thumbs[1], 6, 0, 0));
}

TEST(EmbroideryPes, ThreadsAreTheNearestAndDistinctColoursStayDistinct) {
  // The four flat colours, which once became one grey thread, and a repeat.
  StitchPlan plan;
  plan.colors_rgb = {0x789878, 0xD89878, 0x78B8B8, 0x7878A8, 0x789878};
  for (int b = 0; b < 5; ++b) {
    if (b) plan.points.push_back({0, 0, StitchKind::color_change});
    plan.points.push_back({1.0 * b, 0});
    plan.points.push_back({1.0 * b, 1});
  }
  const PesFile f = read_pes(write_pes(plan));
  ASSERT_TRUE(f.errors.empty()) << f.errors.front();
  ASSERT_EQ(f.threads.size(), 5u);
  for (int t : f.threads) {
    EXPECT_GE(t, 1);
    EXPECT_LE(t, 64);
  }
  for (size_t a = 0; a < 4; ++a)
    for (size_t b = a + 1; b < 4; ++b) EXPECT_NE(f.threads[a], f.threads[b]) << a << " " << b;
  EXPECT_EQ(f.threads[4], f.threads[0]);
  // The first colour gets its nearest thread outright.
  const std::uint32_t c = plan.colors_rgb[0];
  const double d = color_difference(c, pec_threads()[static_cast<size_t>(f.threads[0] - 1)].rgb);
  for (const Thread& t : pec_threads()) EXPECT_LE(d, color_difference(c, t.rgb) + 1e-9) << t.name;
  // Every other colour: no free thread is nearer than the one it got.
  std::vector<int> taken;
  for (size_t k = 0; k < 4; ++k) {
    const double dk = color_difference(plan.colors_rgb[k], pec_threads()[static_cast<size_t>(f.threads[k] - 1)].rgb);
    for (size_t t = 0; t < pec_threads().size(); ++t) {
      if (std::find(taken.begin(), taken.end(), static_cast<int>(t + 1)) != taken.end()) continue;
      EXPECT_LE(dk, color_difference(plan.colors_rgb[k], pec_threads()[t].rgb) + 1e-9) << k;
    }
    taken.push_back(f.threads[k]);
  }
}

TEST(EmbroideryPes, MoreColourBlocksThanPecHoldsAreRefused) {
  StitchPlan plan;
  for (int b = 0; b < 256; ++b) {
    if (b) plan.points.push_back({0, 0, StitchKind::color_change});
    plan.points.push_back({0.1 * b, 0});
  }
  EXPECT_THROW(write_pes(plan), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::embroidery

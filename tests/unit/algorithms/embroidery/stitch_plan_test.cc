// The stitch plan (algorithms/embroidery/stitch_plan.h) through both file writers: its counts and
// extents, colours and a long jump in DST and EXP, and the plans validate_plan refuses.
#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>
#include <vector>

#include "algorithms/embroidery/stitch_plan.h"
#include "convert/embroidery/dst_writer.h"
#include "convert/embroidery/exp_writer.h"
#include "tests/unit/convert/embroidery/stitch_file_fixture.h"
#include "tests/support/stitch_file_readers.h"

namespace atelier::embroidery {
namespace {

using namespace atelier::embroidery::test;

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

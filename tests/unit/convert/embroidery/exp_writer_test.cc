// EXP stitch files (convert/embroidery/exp_writer.h) checked by a reader written from the formats
// file: record ranges, positions after accumulating, long moves split, no end code.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "algorithms/embroidery/stitch_plan.h"
#include "convert/embroidery/exp_writer.h"
#include "tests/unit/convert/embroidery/stitch_file_fixture.h"
#include "tests/support/stitch_file_readers.h"

namespace atelier::embroidery {
namespace {

using namespace atelier::embroidery::test;

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

}  // namespace
}  // namespace atelier::embroidery

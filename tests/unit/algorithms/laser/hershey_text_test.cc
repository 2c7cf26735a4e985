// Single-stroke Hershey text for engraved part IDs (algorithms/laser/hershey_text.h):
// placement, size, rotation, errors. Uses the real fonts from Debian's hershey-fonts-data.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "algorithms/laser/hershey_text.h"
#include "tests/unit/convert/common/hershey_fonts_fixture.h"

namespace atelier::laser {
namespace {

using testing::font_named;
using testing::same_strokes;

const HersheyFont& rowmans() { return font_named("rowmans"); }

TEST(LaserHershey, DigitsSitOnTheBaselineAtTheCapHeight) {
  const Point base{10, 50};
  const double cap = 5, advance = hershey_text_advance(rowmans(), "12", cap);
  const auto paths = hershey_text(rowmans(), "12", base, cap);
  ASSERT_FALSE(paths.empty());
  for (const Path& p : paths)
    for (Point q : p.points) {
      EXPECT_GE(q.x, base.x);
      EXPECT_LE(q.x, base.x + advance);
      EXPECT_GE(q.y, base.y - cap - 1e-9);  // y down: the glyphs rise above the baseline
      EXPECT_LE(q.y, base.y + 1e-9);
    }
  const Bounds b = hershey_text_bounds(rowmans(), "12", base, cap);
  EXPECT_NEAR(b.max_y, base.y, 1e-9);
  EXPECT_NEAR(b.max_y - b.min_y, cap, 0.02 * cap);
  // Two digits of a Roman font: a little under two advances of 20/21 cap each.
  EXPECT_NEAR(advance, 2 * 20.0 / 21.0 * cap, 1e-9);
  EXPECT_GT(b.max_x - b.min_x, 0.5 * advance);
  EXPECT_LT(b.max_x - b.min_x, advance);
}

TEST(LaserHershey, SizeScalesWithCapHeightInEveryFont) {
  for (const char* font : {"rowmans", "futural", "rowmand", "timesr"}) {
    const Bounds small = hershey_text_bounds(font_named(font), "H", {0, 0}, 3, 0);
    const Bounds big = hershey_text_bounds(font_named(font), "H", {0, 0}, 12, 0);
    EXPECT_NEAR(small.max_y - small.min_y, 3, 0.05) << font;
    EXPECT_NEAR(big.max_y - big.min_y, 12, 0.2) << font;
    EXPECT_NEAR((big.max_x - big.min_x) / (small.max_x - small.min_x), 4.0, 1e-9) << font;
  }
}

TEST(LaserHershey, RotatingBy90DegreesSwapsTheExtentsAndReadsUpwards) {
  const Point base{100, 100};
  const Bounds flat = hershey_text_bounds(rowmans(), "A17", base, 4);
  const Bounds up = hershey_text_bounds(rowmans(), "A17", base, 4, 90);
  EXPECT_NEAR(up.max_x - up.min_x, flat.max_y - flat.min_y, 1e-9);
  EXPECT_NEAR(up.max_y - up.min_y, flat.max_x - flat.min_x, 1e-9);
  // Counter-clockwise on the sheet: the baseline runs up (-y), the glyphs stand to its left.
  EXPECT_NEAR(up.max_x, base.x, 1e-9);
  EXPECT_LT(up.max_y, base.y);
  const auto first = hershey_text(rowmans(), "A", base, 4, 90);
  const auto all = hershey_text(rowmans(), "A17", base, 4, 90);
  Bounds a, seven;
  for (const Path& p : first) a.add(bounds_of(p));
  seven.add(bounds_of(all.back()));
  EXPECT_LT(seven.max_y, a.min_y);  // the last character is furthest up the sheet
}

TEST(LaserHershey, EveryDigitHasItsOwnStrokes) {
  std::vector<std::vector<Path>> digits;
  for (char c = '0'; c <= '9'; ++c) digits.push_back(hershey_text(rowmans(), std::string(1, c), {0, 0}, 5));
  for (size_t i = 0; i < digits.size(); ++i) {
    EXPECT_FALSE(digits[i].empty()) << "digit " << i;
    for (size_t j = i + 1; j < digits.size(); ++j)
      EXPECT_FALSE(same_strokes(digits[i], digits[j])) << "digits " << i << " and " << j;
  }
  EXPECT_FALSE(same_strokes(hershey_text(rowmans(), "12", {0, 0}, 5), hershey_text(rowmans(), "21", {0, 0}, 5)));
}

TEST(LaserHershey, EveryPathIsOpenWithAtLeastTwoPoints) {
  std::string ascii;
  for (char c = 32; c < 127; ++c) ascii += c;
  for (const char* font : {"rowmans", "futural"}) {
    const auto paths = hershey_text(font_named(font), ascii, {5, 5}, 3, 33);
    EXPECT_GT(paths.size(), 95u) << font;
    for (const Path& p : paths) {
      EXPECT_FALSE(p.closed);
      EXPECT_GE(p.points.size(), 2u);
      EXPECT_GT(path_length(p), 0);
    }
  }
}

TEST(LaserHershey, SpacesAdvanceWithoutStrokes) {
  EXPECT_TRUE(hershey_text(rowmans(), " ", {0, 0}, 5).empty());
  EXPECT_TRUE(hershey_text_bounds(rowmans(), "  ", {0, 0}, 5).empty());
  EXPECT_GT(hershey_text_advance(rowmans(), " ", 5), 0);
  const auto gap = hershey_text(rowmans(), "1 1", {0, 0}, 5), tight = hershey_text(rowmans(), "11", {0, 0}, 5);
  ASSERT_EQ(gap.size(), tight.size());
  const double shift = gap.back().points[0].x - tight.back().points[0].x;
  EXPECT_NEAR(shift, hershey_text_advance(rowmans(), " ", 5), 1e-9);
}

TEST(LaserHershey, CentredTextHasItsInkCentreOnThePoint) {
  for (double angle : {0.0, 30.0, 90.0, -135.0}) {
    const Point centre{42, 17};
    Bounds ink;
    for (const Path& p : hershey_text_centred(rowmans(), "P-204", centre, 2.5, angle)) ink.add(bounds_of(p));
    if (std::fmod(std::abs(angle), 90.0) == 0) {  // the box centre survives right-angle turns
      EXPECT_NEAR((ink.min_x + ink.max_x) / 2, centre.x, 1e-9) << angle;
      EXPECT_NEAR((ink.min_y + ink.max_y) / 2, centre.y, 1e-9) << angle;
    }
    EXPECT_TRUE(ink.min_x < centre.x && centre.x < ink.max_x) << angle;
    EXPECT_TRUE(ink.min_y < centre.y && centre.y < ink.max_y) << angle;
  }
  // At 0 degrees it is hershey_text moved: same shape, same size.
  const Bounds a = hershey_text_bounds(rowmans(), "P-204", {0, 0}, 2.5);
  Bounds c;
  for (const Path& p : hershey_text_centred(rowmans(), "P-204", {0, 0}, 2.5)) c.add(bounds_of(p));
  EXPECT_NEAR(c.max_x - c.min_x, a.max_x - a.min_x, 1e-9);
  EXPECT_NEAR(c.max_y - c.min_y, a.max_y - a.min_y, 1e-9);
}

TEST(LaserHershey, RejectsCharactersWithoutGlyphsAndBadSizes) {
  try {
    hershey_text(rowmans(), "A\xc3\xa9", {0, 0}, 5);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("position 1"), std::string::npos) << e.what();
  }
  EXPECT_THROW(hershey_text(rowmans(), "A\nB", {0, 0}, 5), std::invalid_argument);
  EXPECT_THROW(hershey_text(rowmans(), "1", {0, 0}, 0), std::invalid_argument);
  EXPECT_THROW(hershey_text(rowmans(), "1", {0, 0}, NAN), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::laser

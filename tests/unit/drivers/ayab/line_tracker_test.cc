// The 256-row line tracker of the AYAB host session (drivers/ayab/line_tracker.h).
#include <gtest/gtest.h>

#include "drivers/ayab/line_tracker.h"

namespace atelier::ayab {
namespace {

TEST(AyabLineTracker, WrapsAt256AndKeepsTheAbsoluteCount) {
  LineTracker t;
  for (int k = 0; k < 600; ++k) {
    const auto r = t.on_request(static_cast<uint8_t>(k & 0xFF));
    ASSERT_EQ(r.kind, LineTracker::Kind::next) << k;
    ASSERT_EQ(r.line, k);
  }
  EXPECT_EQ(t.expected(), 600);
}

TEST(AyabLineTracker, RepeatAndOutOfSequence) {
  LineTracker t;
  EXPECT_EQ(t.on_request(1).kind, LineTracker::Kind::out_of_sequence);  // must start at 0
  EXPECT_EQ(t.on_request(0).kind, LineTracker::Kind::next);
  const auto again = t.on_request(0);
  EXPECT_EQ(again.kind, LineTracker::Kind::repeat);
  EXPECT_EQ(again.line, 0);
  for (int k = 1; k <= 256; ++k) t.on_request(static_cast<uint8_t>(k & 0xFF));
  const auto rep = t.on_request(0);  // line 256 again, on the wire as 0
  EXPECT_EQ(rep.kind, LineTracker::Kind::repeat);
  EXPECT_EQ(rep.line, 256);
  const auto bad = t.on_request(5);
  EXPECT_EQ(bad.kind, LineTracker::Kind::out_of_sequence);
  EXPECT_EQ(bad.line, 257);
}

}  // namespace
}  // namespace atelier::ayab

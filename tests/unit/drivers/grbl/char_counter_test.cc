// The character-counting window of the GRBL host (drivers/grbl/char_counter.h).
#include <gtest/gtest.h>

#include <deque>
#include <random>

#include "drivers/grbl/char_counter.h"

namespace atelier::grbl {
namespace {

TEST(GrblCharCounter, NeverExceedsTheBudgetAndFreesOldestFirst) {
  CharCounter w(127);
  EXPECT_TRUE(w.fits(127));
  EXPECT_FALSE(w.fits(128));
  w.sent(60);
  w.sent(50);
  EXPECT_FALSE(w.fits(18));
  EXPECT_TRUE(w.fits(17));
  EXPECT_EQ(w.in_flight(), 110u);
  EXPECT_EQ(w.lines_in_flight(), 2u);
  EXPECT_EQ(w.acked(), 60u);  // FIFO: the first line sent is the first answered
  EXPECT_EQ(w.acked(), 50u);
  EXPECT_EQ(w.in_flight(), 0u);
  EXPECT_THROW(w.acked(), std::logic_error);

  // A random stream: sending whenever a line fits keeps in_flight within the budget.
  std::mt19937 rng(7);
  std::uniform_int_distribution<size_t> len(2, 80);
  std::deque<size_t> mirror;
  size_t peak = 0;
  for (int i = 0; i < 5000; ++i) {
    const size_t n = len(rng);
    while (!w.fits(n)) {
      EXPECT_EQ(w.acked(), mirror.front());
      mirror.pop_front();
    }
    w.sent(n);
    mirror.push_back(n);
    peak = std::max(peak, w.in_flight());
    ASSERT_LE(w.in_flight(), 127u);
  }
  EXPECT_GE(peak, 110u);  // and it does use the buffer
}

}  // namespace
}  // namespace atelier::grbl

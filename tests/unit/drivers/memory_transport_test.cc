// The in-memory transport pair (drivers/memory_transport.h), on a fake clock: bytes both ways,
// timeouts in the pair's clock, flushing, and disconnects that wake a blocked reader.
#include <gtest/gtest.h>

#include <future>
#include <string>

#include "base/fake_clock.h"
#include "drivers/memory_transport.h"
#include "tests/unit/drivers/transport_fixture.h"

namespace atelier {
namespace {

using namespace std::chrono_literals;

using test::read_all;
using test::write_str;

TEST(TransportMemory, BytesFlowBothWaysAndTimeoutReturnsZero) {
  FakeClock clock;
  clock.set_auto_advance(true);  // this thread alone waits: a read with nothing to read times out at once
  auto [a, b] = make_memory_pair(clock);
  write_str(*a, "hello");
  write_str(*b, "back");
  EXPECT_EQ(read_all(*b, 5), "hello");
  EXPECT_EQ(read_all(*a, 4), "back");
  const auto t0 = clock.now();
  uint8_t buf[4];
  EXPECT_EQ(a->read(buf, sizeof buf, 10ms), 0u);
  EXPECT_EQ(clock.now() - t0, 10ms);  // it waited its timeout, on the pair's clock
}

TEST(TransportMemory, AReadWaitsUntilThePairsClockReachesItsTimeout) {
  FakeClock clock;
  auto [a, b] = make_memory_pair(clock);
  const auto t0 = clock.now();
  auto reader = std::async(std::launch::async, [&a = *a, &clock] {
    uint8_t buf[4];
    const size_t n = a.read(buf, sizeof buf, 500ms);
    return std::make_pair(n, clock.now());
  });
  clock.await_waiters(1);
  clock.advance(499ms);
  clock.await_waiters(1);  // not yet
  clock.advance(1ms);
  const auto [n, at] = reader.get();
  EXPECT_EQ(n, 0u);
  EXPECT_EQ(at, t0 + 500ms);
}

TEST(TransportMemory, FlushInputDiscardsUnreadBytes) {
  FakeClock clock;
  clock.set_auto_advance(true);
  auto [a, b] = make_memory_pair(clock);
  write_str(*a, "noise");
  b->flush_input();
  write_str(*a, "ok");
  EXPECT_EQ(read_all(*b, 2), "ok");
}

TEST(TransportMemory, ADtrPulseIsCountedAndDiscardsUnreadInput) {
  FakeClock clock;
  auto [a, b] = make_memory_pair(clock);
  write_str(*a, "noise");
  b->pulse_dtr(100ms);
  EXPECT_EQ(b->dtr_pulses(), 1);
  EXPECT_EQ(a->dtr_pulses(), 0);
  write_str(*a, "ok");
  EXPECT_EQ(read_all(*b, 2), "ok");
}

TEST(TransportMemory, DisconnectMakesBothEndsThrowLinkLost) {
  FakeClock clock;
  clock.set_auto_advance(true);
  auto [a, b] = make_memory_pair(clock);
  b->disconnect();
  uint8_t buf[4];
  EXPECT_THROW(a->read(buf, sizeof buf, 10ms), LinkLost);
  EXPECT_THROW(write_str(*a, "x"), LinkLost);
  EXPECT_THROW(b->read(buf, sizeof buf, 10ms), LinkLost);
}

TEST(TransportMemory, DisconnectWakesABlockedReader) {
  FakeClock clock;  // stands still: only the disconnect can end the read
  auto [a, b] = make_memory_pair(clock);
  auto reader = std::async(std::launch::async, [&a = *a] {
    uint8_t buf[4];
    try {
      a.read(buf, sizeof buf, 60000ms);
    } catch (const LinkLost&) {
      return true;
    }
    return false;
  });
  clock.await_waiters(1);  // the reader is blocked in its read
  b->disconnect();
  // A reader the disconnect did not wake would stay blocked here (ctest's timeout reports it).
  EXPECT_TRUE(reader.get());
  EXPECT_EQ(clock.now(), FakeClock::kStart);
}

}  // namespace
}  // namespace atelier

// The simulated link (drivers/simulated_transport.h): a read that would wait moves the fake
// clock to the peer's next event or to its own deadline, a peer that pulls the cable has what
// it sent read first, and close() loses the link.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "base/fake_clock.h"
#include "drivers/simulated_transport.h"

namespace atelier {
namespace {

using namespace std::chrono_literals;

// Answers each write with its bytes upper-cased, `delay` later; "bye" is answered, then the
// cable is pulled.
class DelayedEcho : public SimulatedPeer {
 public:
  explicit DelayedEcho(Clock::duration delay) : delay_(delay) {}

  void receive(const uint8_t* data, size_t size, Clock::time_point now) override {
    std::string text(reinterpret_cast<const char*>(data), size);
    for (char& c : text) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    due_ = now + delay_;
    reply_ += text;
  }
  std::vector<uint8_t> take_output(Clock::time_point now) override {
    if (!due_ || now < *due_) return {};
    due_.reset();
    if (reply_ == "BYE") unplugged_ = true;
    std::vector<uint8_t> out(reply_.begin(), reply_.end());
    reply_.clear();
    return out;
  }
  std::optional<Clock::time_point> next_event() const override { return due_; }
  bool unplugged() const override { return unplugged_; }
  void dtr_pulse(Clock::time_point now, std::chrono::milliseconds low) override {
    pulses.emplace_back(now, low);
  }

  std::vector<std::pair<Clock::time_point, std::chrono::milliseconds>> pulses;  // dtr_pulse() calls

 private:
  Clock::duration delay_;
  std::optional<Clock::time_point> due_;
  std::string reply_;
  bool unplugged_ = false;
};

void write_str(Transport& t, const std::string& s) { t.write(reinterpret_cast<const uint8_t*>(s.data()), s.size()); }

std::string read_str(Transport& t, std::chrono::milliseconds timeout, size_t max = 64) {
  uint8_t buf[64];
  const size_t n = t.read(buf, std::min(max, sizeof buf), timeout);
  return std::string(reinterpret_cast<char*>(buf), n);
}

TEST(SimulatedTransport, AReadMovesTheClockToThePeersAnswer) {
  FakeClock clock;
  SimulatedTransport link(std::make_shared<DelayedEcho>(30ms), clock);
  const auto t0 = clock.now();
  write_str(link, "ok");
  EXPECT_EQ(clock.now(), t0);  // writing takes no time
  EXPECT_EQ(read_str(link, 100ms), "OK");
  EXPECT_EQ(clock.now(), t0 + 30ms);  // exactly when the peer answered
}

TEST(SimulatedTransport, AReadWithNothingComingTimesOutAtItsDeadline) {
  FakeClock clock;
  SimulatedTransport link(std::make_shared<DelayedEcho>(500ms), clock);
  const auto t0 = clock.now();
  EXPECT_EQ(read_str(link, 40ms), "");  // nothing asked: nothing scheduled
  EXPECT_EQ(clock.now(), t0 + 40ms);
  write_str(link, "late");
  EXPECT_EQ(read_str(link, 100ms), "");  // the answer is due after the deadline
  EXPECT_EQ(clock.now(), t0 + 140ms);
  EXPECT_EQ(read_str(link, 1000ms, 2), "LA");  // and comes then, a read's worth at a time
  EXPECT_EQ(clock.now(), t0 + 540ms);
  EXPECT_EQ(read_str(link, 0ms), "TE");
}

TEST(SimulatedTransport, APeerThatPullsTheCableHasItsLastWordsReadFirst) {
  FakeClock clock;
  SimulatedTransport link(std::make_shared<DelayedEcho>(1ms), clock);
  write_str(link, "bye");
  EXPECT_EQ(read_str(link, 100ms, 2), "BY");
  write_str(link, "ignored");  // the far end is still draining: the bytes fall on the floor
  EXPECT_EQ(read_str(link, 100ms), "E");
  EXPECT_THROW(read_str(link, 100ms), LinkLost);
  EXPECT_THROW(write_str(link, "x"), LinkLost);
}

TEST(SimulatedTransport, CloseLosesTheLinkAndWhatWasInFlight) {
  FakeClock clock;
  SimulatedTransport link(std::make_shared<DelayedEcho>(1ms), clock);
  write_str(link, "hello");
  link.close();
  EXPECT_THROW(read_str(link, 100ms), LinkLost);
  EXPECT_THROW(write_str(link, "x"), LinkLost);
}

TEST(SimulatedTransport, ADtrPulseReachesThePeerTakesItsTimeAndDropsWhatWasInFlight) {
  FakeClock clock;
  auto echo = std::make_shared<DelayedEcho>(1ms);
  SimulatedTransport link(echo, clock);
  write_str(link, "boot noise");
  const auto t0 = clock.now();
  link.pulse_dtr(100ms);
  ASSERT_EQ(echo->pulses.size(), 1u);
  EXPECT_EQ(echo->pulses[0].first, t0);
  EXPECT_EQ(echo->pulses[0].second, 100ms);
  EXPECT_EQ(clock.now(), t0 + 100ms);
  EXPECT_EQ(read_str(link, 50ms), "") << "sent before the reset, read after it";
  write_str(link, "hi");
  EXPECT_EQ(read_str(link, 50ms), "HI");
}

}  // namespace
}  // namespace atelier

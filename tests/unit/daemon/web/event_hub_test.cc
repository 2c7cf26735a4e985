// The live feed: every open stream gets every event in order; a stream that falls behind is
// ended instead of holding the others up; closing the hub ends every stream.
#include "daemon/web/event_hub.h"

#include <gtest/gtest.h>

#include <thread>

namespace atelier::web {
namespace {

using namespace std::chrono_literals;

TEST(EventHub, EveryStreamGetsEveryMessageInOrder) {
  EventHub hub(4, 100);
  auto a = hub.subscribe(), b = hub.subscribe();
  ASSERT_TRUE(a && b);
  hub.publish(sse_message("job", "{\"id\":1}"));
  hub.publish(sse_message("job", "{\"id\":2}"));
  EXPECT_EQ(a->next(1s), "event: job\ndata: {\"id\":1}\n\n");
  EXPECT_EQ(a->next(1s), "event: job\ndata: {\"id\":2}\n\n");
  EXPECT_EQ(b->next(1s), "event: job\ndata: {\"id\":1}\n\n");
  EXPECT_FALSE(a->next(10ms));  // nothing more: a timeout, not an end
  EXPECT_FALSE(a->ended());
}

TEST(EventHub, AWaitingStreamWakesWhenAMessageComes) {
  EventHub hub(4, 100);
  auto a = hub.subscribe();
  std::thread publisher([&] {
    std::this_thread::sleep_for(50ms);
    hub.publish("x");
  });
  EXPECT_EQ(a->next(10s), "x");
  publisher.join();
}

TEST(EventHub, AStreamTooFarBehindIsEndedAndTheOthersGoOn) {
  EventHub hub(4, 3);
  auto slow = hub.subscribe(), fast = hub.subscribe();
  for (int i = 0; i < 5; ++i) {
    hub.publish(std::to_string(i));
    EXPECT_EQ(fast->next(1s), std::to_string(i));
  }
  EXPECT_TRUE(slow->ended());
  EXPECT_FALSE(slow->next(10ms));
  EXPECT_FALSE(fast->ended());
}

TEST(EventHub, RefusesStreamsBeyondTheCapAndFreesClosedOnes) {
  EventHub hub(2, 10);
  auto a = hub.subscribe(), b = hub.subscribe();
  EXPECT_FALSE(hub.subscribe());
  a.reset();  // the browser went away
  auto c = hub.subscribe();
  EXPECT_TRUE(c);
  EXPECT_EQ(hub.streams(), 2u);
}

TEST(EventHub, CloseEndsEveryStreamAtOnce) {
  EventHub hub(4, 10);
  auto a = hub.subscribe();
  std::thread closer([&] {
    std::this_thread::sleep_for(50ms);
    hub.close();
  });
  EXPECT_FALSE(a->next(30s));  // woken by close, long before the 30 s
  EXPECT_TRUE(a->ended());
  closer.join();
  EXPECT_FALSE(hub.subscribe());
}

}  // namespace
}  // namespace atelier::web

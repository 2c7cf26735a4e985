// SLIP framing of AYAB messages (drivers/ayab/slip.h, ../shared/protocols/ayab-v6.md): escapes,
// split input, empty packets, bad escapes and oversize packets, line noise.
#include <gtest/gtest.h>

#include "drivers/ayab/messages.h"
#include "drivers/ayab/slip.h"

namespace atelier::ayab {
namespace {

TEST(AyabSlip, EscapesEndAndEscBytes) {
  EXPECT_EQ(slip_encode({0xC0, 0xDB, 0x01}), (Bytes{0xC0, 0xDB, 0xDC, 0xDB, 0xDD, 0x01, 0xC0}));
  EXPECT_EQ(slip_encode({0x03}), (Bytes{0xC0, 0x03, 0xC0}));
}

TEST(AyabSlip, RoundTripEveryByteValue) {
  Bytes all;
  for (int i = 0; i < 256; ++i) all.push_back(static_cast<uint8_t>(i));
  SlipDecoder dec(512);
  auto packets = dec.feed(slip_encode(all));
  ASSERT_EQ(packets.size(), 1u);
  EXPECT_EQ(packets[0], all);
}

TEST(AyabSlip, SplitFeedsByteByByte) {
  const Bytes a = {0x82, 0xC0, 0x00}, b = {0xDB, 0xDB, 0x42};
  Bytes stream = slip_encode(a);
  const Bytes sb = slip_encode(b);
  stream.insert(stream.end(), sb.begin(), sb.end());
  SlipDecoder dec;
  std::vector<Bytes> got;
  for (uint8_t byte : stream)
    for (auto& p : dec.feed(&byte, 1)) got.push_back(p);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0], a);
  EXPECT_EQ(got[1], b);
}

TEST(AyabSlip, EmptyPacketsAreSkipped) {
  SlipDecoder dec;
  EXPECT_TRUE(dec.feed(Bytes{0xC0, 0xC0, 0xC0}).empty());
  auto got = dec.feed(Bytes{0xC0, 0xC0, 0x03, 0xC0, 0xC0});
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0], Bytes{0x03});
}

TEST(AyabSlip, BadEscapeAndOversizeAreDroppedAndDecodingRecovers) {
  SlipDecoder dec(8);
  Bytes stream = {0xC0, 0x01, 0xDB, 0x41, 0x02, 0xC0};  // ESC followed by a non-escape byte
  stream.insert(stream.end(), 20, 0x55);                 // 20 bytes > max 8
  stream.push_back(0xC0);
  const Bytes good = slip_encode({0x82, 0x05, 0x00});
  stream.insert(stream.end(), good.begin(), good.end());
  auto got = dec.feed(stream);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0], (Bytes{0x82, 0x05, 0x00}));
}

TEST(AyabSlip, LineNoiseBeforeFirstEndBecomesAPacketThatDecodeRejects) {
  SlipDecoder dec;
  Bytes stream = {0x13, 0x37};  // boot noise, then a framed reqLine
  const Bytes good = slip_encode({0x82, 0x00, 0x00});
  stream.insert(stream.end(), good.begin(), good.end());
  auto got = dec.feed(stream);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_FALSE(decode(got[0], 25).message.has_value());
  ASSERT_TRUE(decode(got[1], 25).message.has_value());
}

}  // namespace
}  // namespace atelier::ayab

// The AYAB v6 message layouts (drivers/ayab/messages.h, ../shared/protocols/ayab-v6.md): exact
// bytes, round trips, decoding errors, needle bits.
#include <gtest/gtest.h>

#include <string>

#include "drivers/ayab/messages.h"
#include "tests/unit/drivers/ayab/crc8_fixture.h"

namespace atelier::ayab {
namespace {

using testing::crc_of;

// Round trip through bytes: decode(encode(m)) encodes to the same bytes.
Bytes round_trip(const Message& m, int line_bytes = 25) {
  const Bytes b = encode(m);
  const DecodeResult r = decode(b, line_bytes);
  EXPECT_TRUE(r.message.has_value()) << describe(m);
  return r.message ? encode(*r.message) : Bytes{};
}

TEST(AyabMessages, ExactLayoutsFromTheProtocol) {
  EXPECT_EQ(encode(ReqInfo{}), Bytes{0x03});
  EXPECT_EQ(encode(ReqInit{MachineType::kh930}), (Bytes{0x05, 0x01, crc_of(Bytes{0x05, 0x01})}));
  EXPECT_EQ(encode(ReqInit{MachineType::kh270}), (Bytes{0x05, 0x02, crc_of(Bytes{0x05, 0x02})}));
  EXPECT_EQ(encode(CnfInit{0x20}), (Bytes{0xC5, 0x20}));
  EXPECT_EQ(encode(ReqStart{10, 189, false, true}), (Bytes{0x01, 10, 189, 0x02, crc_of(Bytes{0x01, 10, 189, 0x02})}));
  EXPECT_EQ(encode(ReqStart{0, 199, true, false})[3], 0x01);
  EXPECT_EQ(encode(CnfStart{0x10}), (Bytes{0xC1, 0x10}));
  EXPECT_EQ(encode(ReqLine{7, 0}), (Bytes{0x82, 7, 0}));
  EXPECT_EQ(encode(Debug{"hi"}), (Bytes{0x9F, 'h', 'i'})) << "no NUL: firmware 1.0's Com::sendMsg sends id + characters";
}

TEST(AyabMessages, CnfInfoIs22BytesWithNulTerminatedSuffix) {
  const Bytes b = encode(CnfInfo{6, 1, 0, 2, "rc1"});
  ASSERT_EQ(b.size(), 22u);
  EXPECT_EQ(b[0], 0xC3);
  EXPECT_EQ(b[1], 6);
  EXPECT_EQ(b[2], 1);
  EXPECT_EQ(b[3], 0);
  EXPECT_EQ(b[4], 2);
  EXPECT_EQ(b[5], 'r');
  EXPECT_EQ(b[7], '1');
  for (size_t i = 8; i < 22; ++i) EXPECT_EQ(b[i], 0) << i;
  const auto m = decode(b, 25).message;
  ASSERT_TRUE(m);
  EXPECT_EQ(std::get<CnfInfo>(*m).suffix, "rc1");
  EXPECT_EQ(std::get<CnfInfo>(*m).api, 6);
}

TEST(AyabMessages, IndStateHallValuesAreBigEndian) {
  IndState s;
  s.error = 0;
  s.state = FsmState::ready;
  s.hall_left = 0x1234;
  s.hall_right = 0xABCD;
  s.carriage = Carriage::lace;
  s.position = 150;
  s.direction = Direction::right;
  EXPECT_EQ(encode(s), (Bytes{0x84, 0x00, 0x02, 0x12, 0x34, 0xAB, 0xCD, 0x01, 150, 0x01}));
  const auto m = decode(encode(s), 25).message;
  ASSERT_TRUE(m);
  const auto& d = std::get<IndState>(*m);
  EXPECT_EQ(d.hall_left, 0x1234);
  EXPECT_EQ(d.hall_right, 0xABCD);
  EXPECT_EQ(d.position, 150);
  EXPECT_EQ(d.direction, Direction::right);
}

TEST(AyabMessages, CnfLineLengthDependsOnTheMachine) {
  CnfLine c;
  c.line = 3;
  c.colour = 1;
  c.last_line = true;
  c.needles.assign(25, 0);
  c.needles[0] = 0xC0;  // a byte that SLIP must escape
  const Bytes b = encode(c);
  ASSERT_EQ(b.size(), 4u + 25u + 1u);
  EXPECT_EQ(b[0], 0x42);
  EXPECT_EQ(b[1], 3);
  EXPECT_EQ(b[2], 1);
  EXPECT_EQ(b[3], 0x01);
  EXPECT_EQ(b.back(), crc8(b.data(), b.size() - 1));
  EXPECT_EQ(round_trip(c, 25), b);

  c.needles.assign(14, 0xFF);
  EXPECT_EQ(encode(c).size(), 4u + 14u + 1u);
  EXPECT_EQ(round_trip(c, 14), encode(c));
}

TEST(AyabMessages, EveryMessageRoundTrips) {
  IndState s;
  s.hall_left = 513;
  CnfLine line;
  line.line = 255;
  line.needles.assign(25, 0xA5);
  const Message all[] = {ReqInfo{}, CnfInfo{6, 1, 2, 3, "x"}, ReqInit{MachineType::kh910}, CnfInit{0},
                         s, ReqStart{5, 120, true, true}, CnfStart{0xE0}, ReqLine{200, 0}, line,
                         ReqTest{}, CnfTest{0}, Debug{"debug text"}, TestRes{"ok"}};
  for (const Message& m : all) EXPECT_EQ(round_trip(m), encode(m)) << describe(m);
}

TEST(AyabMessages, DecodeRejectsBadCrcTooShortAndBadId) {
  CnfLine c;
  c.needles.assign(25, 0x0F);
  Bytes b = encode(c);
  b[10] ^= 0x01;
  EXPECT_EQ(decode(b, 25).error, err::bad_crc);
  EXPECT_FALSE(decode(b, 25).message);
  const Bytes whole = encode(c);
  EXPECT_EQ(decode(Bytes(whole.begin(), whole.end() - 3), 25).error, err::too_short);
  Bytes init = encode(ReqInit{MachineType::kh930});
  init[2] ^= 0xFF;
  EXPECT_EQ(decode(init, 25).error, err::bad_crc);
  EXPECT_EQ(decode(Bytes{0x84, 0x00, 0x02}, 25).error, err::too_short);
  EXPECT_EQ(decode(Bytes{0x82, 0x01}, 25).error, err::too_short);
  EXPECT_EQ(decode(Bytes{0x77, 0x01, 0x02}, 25).error, err::bad_id);
  EXPECT_EQ(decode(Bytes{}, 25).error, err::too_short);
}

TEST(AyabMessages, NeedleBitsAreLsbFirst) {
  Bytes d(25, 0);
  select_needle(d, 0, true);
  select_needle(d, 9, true);
  select_needle(d, 199, true);
  EXPECT_EQ(d[0], 0x01);
  EXPECT_EQ(d[1], 0x02);
  EXPECT_EQ(d[24], 0x80);
  EXPECT_TRUE(needle_selected(d, 9));
  EXPECT_FALSE(needle_selected(d, 8));
}

TEST(AyabMessages, FirmwareOnesErrorCodesAndStateNamesReadAsTheUserNeedsThem) {
  EXPECT_EQ(error_text(err::wrong_machine_state), "wrong machine state (0xef)");
  EXPECT_EQ(error_text(err::bad_crc), "bad checksum (0x04)");
  EXPECT_EQ(state_name(FsmState::knit), "knitting");
  EXPECT_EQ(state_name(FsmState::wait_for_machine), "wait-for-machine");
}

}  // namespace
}  // namespace atelier::ayab

// The AYAB CRC-8 (drivers/ayab/crc8.h, ../shared/protocols/ayab-v6.md): check value and known
// values.
#include <gtest/gtest.h>

#include <string>

#include "drivers/ayab/crc8.h"
#include "tests/unit/drivers/ayab/crc8_fixture.h"

namespace atelier::ayab {
namespace {

using testing::crc_of;

TEST(AyabCrc, CheckValueAndKnownValues) {
  EXPECT_EQ(crc_of(std::string("123456789")), 0xA1);
  EXPECT_EQ(crc8(nullptr, 0), 0x00);
  EXPECT_EQ(crc_of(Bytes{0x00}), 0x00);
  EXPECT_EQ(crc_of(Bytes{0x01}), 0x5E);  // Dallas/Maxim table entry 1
  EXPECT_EQ(crc_of(Bytes{0x02}), 0xBC);
  // Appending the CRC makes the CRC of the whole zero (a property of this CRC, no final XOR).
  Bytes b = {0x05, 0x01};
  b.push_back(crc_of(b));
  EXPECT_EQ(crc_of(b), 0x00);
}

}  // namespace
}  // namespace atelier::ayab

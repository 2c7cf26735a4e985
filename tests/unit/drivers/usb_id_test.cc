// USB ids (drivers/usb_id.h): parsing, printing, matching with and without a serial.
#include <gtest/gtest.h>

#include "drivers/usb_id.h"

using namespace atelier;

namespace {

TEST(UsbId, ParsesVendorAndProduct) {
  const UsbId id = parse_usb_id("2341:0043");
  EXPECT_EQ(id.vendor, 0x2341);
  EXPECT_EQ(id.product, 0x0043);
  EXPECT_EQ(id.serial, "");
}

TEST(UsbId, ParsesSerialVerbatim) {
  const UsbId id = parse_usb_id("2341:0043:75833353035351D0F1A1");
  EXPECT_EQ(id.vendor, 0x2341);
  EXPECT_EQ(id.product, 0x0043);
  EXPECT_EQ(id.serial, "75833353035351D0F1A1");
}

TEST(UsbId, HexIsCaseInsensitive) {
  EXPECT_EQ(parse_usb_id("1A86:7523"), parse_usb_id("1a86:7523"));
  EXPECT_EQ(parse_usb_id("0403:6001").product, 0x6001);
  EXPECT_EQ(parse_usb_id("3:fFfF").vendor, 3);
  EXPECT_EQ(parse_usb_id("3:fFfF").product, 0xffff);
}

TEST(UsbId, RejectsMalformedTextNamingIt) {
  for (const std::string bad : {"", "2341", "2341:", ":0043", "23410:0043", "2341:00g3",
                                "2341:0043:", "2341:0043:AB CD", "0x2341:0043", "-341:0043"}) {
    try {
      parse_usb_id(bad);
      ADD_FAILURE() << "accepted \"" << bad << "\"";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("\"" + bad + "\""), std::string::npos) << e.what();
    }
  }
}

TEST(UsbId, ToStringRoundTrips) {
  EXPECT_EQ(to_string(parse_usb_id("2341:43")), "2341:0043");
  EXPECT_EQ(to_string(parse_usb_id("1A86:7523:ABC:1")), "1a86:7523:ABC:1");
  EXPECT_EQ(parse_usb_id(to_string(UsbId{0x0403, 0x6001, "A50285BI"})),
            (UsbId{0x0403, 0x6001, "A50285BI"}));
}

TEST(UsbId, SerialMattersOnlyWhenAsked) {
  const UsbId device{0x2341, 0x0043, "SN1"};
  EXPECT_TRUE(usb_id_matches({0x2341, 0x0043, ""}, device));
  EXPECT_TRUE(usb_id_matches({0x2341, 0x0043, "SN1"}, device));
  EXPECT_FALSE(usb_id_matches({0x2341, 0x0043, "SN2"}, device));
  EXPECT_FALSE(usb_id_matches({0x2341, 0x0042, ""}, device));
  EXPECT_FALSE(usb_id_matches({0x2342, 0x0043, ""}, device));
}

}  // namespace

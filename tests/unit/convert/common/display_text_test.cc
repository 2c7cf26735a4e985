// Names and values shown safely: valid UTF-8, no control characters, long values capped.
#include "convert/common/display_text.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace {

using atelier::display_path;
using atelier::display_value;
using atelier::redact_quoted;
using atelier::safe_text;

TEST(DisplayTextTest, InvalidBytesAndControlsAreEscapedValidTextKept) {
  EXPECT_EQ(safe_text("caf\xe9.png"), "caf\\xE9.png");
  EXPECT_EQ(safe_text("caf\xc3\xa9.png"), "caf\xc3\xa9.png");
  EXPECT_EQ(safe_text("a\nb\x1b[2Jc\t"), "a\\nb\\e[2Jc\\t");
  EXPECT_EQ(safe_text("\xc2\x9b"), "\\u{9B}");         // C1 CSI
  EXPECT_EQ(safe_text("\xed\xa0\x80"), "\\xED\\xA0\\x80");  // a surrogate is not UTF-8
  EXPECT_EQ(safe_text("\xe2\x82"), "\\xE2\\x82");     // cut sequence
  // Whatever goes in, JSON can hold it.
  EXPECT_NO_THROW(nlohmann::json(safe_text("\xff\xfe\x80 x")).dump());
}

TEST(DisplayTextTest, LongValuesAreCutWithTheirSize) {
  const std::string big(5 << 20, 'A');
  const std::string shown = display_value(big);
  EXPECT_EQ(shown, std::string(80, 'A') + "... (5242880 bytes)");
  EXPECT_EQ(display_value("short"), "short");
  // Never inside a character.
  EXPECT_EQ(display_value(std::string(79, 'a') + "\xc3\xa9", 80), std::string(79, 'a') + "... (81 bytes)");
}

TEST(DisplayTextTest, ALongPathKeepsItsFileName) {
  const std::string dir(400, 'd');
  EXPECT_EQ(display_path("/" + dir + "/face.png"), ".../face.png");
  EXPECT_EQ(display_path("/srv/face.png"), "/srv/face.png");
}

TEST(DisplayTextTest, QuotedContentOfAFileIsRedacted) {
  const std::string content = "root:x:0:0:root:/root:/bin/bash\n";
  EXPECT_EQ(redact_quoted("line 1: cannot read 'root:x:0:0:root:/root:/bin/bash' (expected 'Row 1')", content),
            "line 1: cannot read '...' (expected 'Row 1')");
}

}  // namespace

// The meanings of GRBL 1.1h's error and alarm codes (drivers/grbl/codes.h).
#include <gtest/gtest.h>

#include "drivers/grbl/codes.h"

namespace atelier::grbl {
namespace {

using namespace std::string_view_literals;

TEST(GrblCodes, ErrorMeaningsFollowGrblsTable) {
  EXPECT_EQ(error_meaning(33), "invalid target: motion command target is invalid");
  EXPECT_EQ(error_meaning(9), "G-code lock: G-code commands are locked out during alarm or jog state");
  EXPECT_EQ(error_meaning(22), "undefined feed rate: feed rate has not yet been set or is undefined");
  EXPECT_EQ(error_meaning(20), "unsupported command: unsupported or invalid G-code command found in block");
  EXPECT_EQ(error_meaning(11).rfind("line overflow:", 0), 0u);
  EXPECT_EQ(error_meaning(38), "tool number too large: tool number greater than max supported value");
  for (int code = 1; code <= 38; ++code) {
    if (code == 18 || code == 19) continue;  // unused in GRBL 1.1
    EXPECT_NE(error_meaning(code), "unknown error code") << code;
  }
  EXPECT_EQ(error_meaning(18), "unknown error code");
  EXPECT_EQ(error_meaning(0), "unknown error code");
  EXPECT_EQ(error_meaning(39), "unknown error code");
}

TEST(GrblCodes, AlarmMeaningsFollowGrblsTable) {
  EXPECT_EQ(alarm_meaning(1).rfind("hard limit:", 0), 0u);
  EXPECT_EQ(alarm_meaning(2),
            "soft limit: G-code motion target exceeds machine travel; machine position retained, alarm may be safely "
            "unlocked");
  EXPECT_EQ(alarm_meaning(3).rfind("abort during cycle: reset while in motion", 0), 0u);
  for (int code = 1; code <= 10; ++code) EXPECT_NE(alarm_meaning(code), "unknown alarm code") << code;
  EXPECT_EQ(alarm_meaning(11), "unknown alarm code");
}

// What the operator reads after an alarm: what happened and what to do, never "safe to unlock"
// for a limit alarm (GRBL's csv says so for ALARM:2; unlocking a job that does not fit only
// moves the problem).
TEST(GrblCodes, AlarmAdviceSaysWhatToDo) {
  EXPECT_EQ(alarm_advice(1).rfind("hard limit:", 0), 0u);
  EXPECT_NE(alarm_advice(1).find("check the machine, then home it ($H)"), std::string::npos);
  for (int code : {1, 2}) EXPECT_EQ(alarm_advice(code).find("safe"), std::string::npos) << code;
  EXPECT_NE(alarm_advice(2).find("start from"), std::string::npos);
  EXPECT_NE(alarm_advice(3).find("home the machine ($H)"), std::string::npos);
  for (int code = 6; code <= 10; ++code) EXPECT_NE(alarm_advice(code).find("home"), std::string::npos) << code;
  for (int code = 4; code <= 5; ++code) EXPECT_NE(alarm_advice(code).find("unlock ($X)"), std::string::npos) << code;
  EXPECT_EQ(alarm_advice(11).rfind("unknown alarm code", 0), 0u);
}

}  // namespace
}  // namespace atelier::grbl

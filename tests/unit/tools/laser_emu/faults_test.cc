// The command-line parsing of atelier-laser-emu (tools/laser_emu/faults.h): fault specs and the
// work area.
#include <gtest/gtest.h>

#include "tools/laser_emu/faults.h"

namespace atelier::laser_emu {
namespace {

TEST(LaserEmuFaults, SpecsAndWorkArea) {
  Faults f;
  EXPECT_EQ(apply_fault("drop-at-line=12", f), "");
  EXPECT_EQ(f.drop_at_line, 12);
  EXPECT_EQ(apply_fault("alarm-at-line=7:2", f), "");
  EXPECT_EQ(f.alarm_at_line, 7);
  EXPECT_EQ(f.alarm_code, 2);
  EXPECT_EQ(apply_fault("stall-at-line=3", f), "");
  EXPECT_EQ(f.stall_at_line, 3);
  EXPECT_NE(apply_fault("stall-at-line=0", f), "");
  EXPECT_NE(apply_fault("alarm-at-line=5:99", f), "");
  EXPECT_NE(apply_fault("explode=1", f).find("unknown fault"), std::string::npos);
  EXPECT_EQ(parse_work_area("300x200"), (std::pair<double, double>{300, 200}));
  EXPECT_FALSE(parse_work_area("300"));
  EXPECT_FALSE(parse_work_area("0x200"));
}

}  // namespace
}  // namespace atelier::laser_emu

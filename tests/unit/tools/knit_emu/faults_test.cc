// Fault specs of the knitting-machine emulator (tools/knit_emu/faults.h): parsing, and bad specs
// refused with a reason.
#include <gtest/gtest.h>

#include "tools/knit_emu/faults.h"

namespace atelier::knit_emu::testing {
namespace {

TEST(KnitEmuFaults, ParsesEverySpec) {
  Faults f;
  EXPECT_EQ(apply_fault("drop-after-row=3", f), "");
  EXPECT_EQ(f.drop_after_row, 3);
  EXPECT_EQ(f.replug_ms, 1000);
  EXPECT_EQ(apply_fault("drop-after-row=5:250", f), "");
  EXPECT_EQ(f.drop_after_row, 5);
  EXPECT_EQ(f.replug_ms, 250);
  EXPECT_EQ(apply_fault("replug-ms=40", f), "");
  EXPECT_EQ(f.replug_ms, 40);
  EXPECT_EQ(apply_fault("corrupt=0.25", f), "");
  EXPECT_DOUBLE_EQ(f.corrupt, 0.25);
  EXPECT_EQ(apply_fault("seed=99", f), "");
  EXPECT_EQ(f.seed, 99u);
  EXPECT_EQ(apply_fault("silent-after-row=7", f), "");
  EXPECT_EQ(f.silent_after_row, 7);
  EXPECT_EQ(apply_fault("api=5", f), "");
  EXPECT_EQ(f.api, 5);
  EXPECT_EQ(apply_fault("delay-ms=30", f), "");
  EXPECT_EQ(f.delay_ms, 30);
  EXPECT_EQ(apply_fault("corrupt-line=4", f), "");
  EXPECT_EQ(f.corrupt_line, 4);
  EXPECT_EQ(apply_fault("bad-escape-after-row=6", f), "");
  EXPECT_EQ(f.bad_escape_after_row, 6);
  EXPECT_TRUE(f.dtr_reset);
  EXPECT_EQ(apply_fault("no-dtr-reset", f), "");
  EXPECT_FALSE(f.dtr_reset);
}

TEST(KnitEmuFaults, KnitterOptionsDefaultToAQuickAttentiveKnitter) {
  Faults f;
  EXPECT_EQ(f.knitter_pause_ms, 10);
  EXPECT_EQ(f.knitter_patience_ms, std::nullopt) << "2 x row-ms";
  EXPECT_FALSE(f.impatient_knitter);
  EXPECT_EQ(apply_fault("knitter-pause-ms=0", f), "");
  EXPECT_EQ(f.knitter_pause_ms, 0);
  EXPECT_EQ(apply_fault("knitter-patience-ms=750", f), "");
  EXPECT_EQ(f.knitter_patience_ms, 750);
  EXPECT_EQ(apply_fault("impatient-knitter", f), "");
  EXPECT_TRUE(f.impatient_knitter);
}

TEST(KnitEmuFaults, RejectsBadSpecsWithAReason) {
  Faults f;
  EXPECT_NE(apply_fault("corrupt=1.5", f).find("corrupt=1.5"), std::string::npos);
  EXPECT_NE(apply_fault("corrupt=x", f), "");
  EXPECT_NE(apply_fault("drop-after-row=0", f), "");
  EXPECT_NE(apply_fault("drop-after-row=2:", f), "");
  EXPECT_NE(apply_fault("delay-ms=-1", f), "");
  EXPECT_NE(apply_fault("api=300", f), "");
  EXPECT_NE(apply_fault("explode=1", f).find("unknown fault"), std::string::npos);
  EXPECT_NE(apply_fault("api", f), "");
  EXPECT_NE(apply_fault("corrupt-line=0", f).find("corrupt-line=0"), std::string::npos);
  EXPECT_NE(apply_fault("bad-escape-after-row=x", f), "");
  EXPECT_NE(apply_fault("knitter-pause-ms=-5", f), "");
  EXPECT_NE(apply_fault("knitter-patience-ms=", f), "");
  EXPECT_EQ(f.corrupt, 0.0) << "a rejected spec changed the faults";
}

}  // namespace
}  // namespace atelier::knit_emu::testing

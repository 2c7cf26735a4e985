// The Fair-Isle float constraint (algorithms/knit/floats.h): violating windows, relaxed
// stitches and anchoring.
#include <gtest/gtest.h>

#include "algorithms/knit/floats.h"

namespace atelier::knit {
namespace {

// Grid of one row from a string of '0'/'1' (and '.' for a stitch later relaxed, taken as 0).
cv::Mat row(const std::string& s) {
  cv::Mat g(1, static_cast<int>(s.size()), CV_8UC1);
  for (size_t i = 0; i < s.size(); ++i) g.at<uint8_t>(0, static_cast<int>(i)) = s[i] == '1';
  return g;
}
cv::Mat mask(const std::string& s) {
  cv::Mat m(1, static_cast<int>(s.size()), CV_8UC1);
  for (size_t i = 0; i < s.size(); ++i) m.at<uint8_t>(0, static_cast<int>(i)) = s[i] == 'r' ? 255 : 0;
  return m;
}

TEST(KnitFloats, RunOfLViolatesLMinusF) {
  FloatRules rules;
  rules.max_float = 4;
  EXPECT_EQ(count_violations(row("0101"), rules), 0);
  EXPECT_EQ(count_violations(row("1000010"), rules), 0);          // run of 4 = f: fine
  EXPECT_EQ(count_violations(row("10000010"), rules), 1);         // run of 5
  EXPECT_EQ(count_violations(row("1000000000"), rules), 5);       // run of 9
  EXPECT_EQ(count_violations(row("1111111000000"), rules), 3 + 2); // 7 ones and 6 zeros
  rules.max_float = 2;
  EXPECT_EQ(count_violations(row("0001110"), rules), 2);
}

TEST(KnitFloats, ViolatingRunsListedLeftToRightRowByRow) {
  FloatRules rules;
  rules.max_float = 3;
  cv::Mat g;
  cv::vconcat(row("0000011010"), row("0101111111"), g);
  const auto runs = violating_runs(g, rules);  // (Run alone names testing::Test::Run here)
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[0].row, 0);
  EXPECT_EQ(runs[0].start, 0);
  EXPECT_EQ(runs[0].length, 5);
  EXPECT_EQ(runs[1].row, 1);
  EXPECT_EQ(runs[1].start, 3);
  EXPECT_EQ(runs[1].length, 7);
  EXPECT_EQ(count_row_violations(g, 0, rules), 2);
  EXPECT_EQ(count_row_violations(g, 1, rules), 4);
  EXPECT_EQ(consistent_stitches(g, rules), 20 - 5 - 7);
  EXPECT_EQ(longest_float(g, rules), 7);
}

TEST(KnitFloats, RelaxedStitchesSplitRunsAndAreExempt) {
  FloatRules rules;
  rules.max_float = 3;
  const cv::Mat g = row("1000000001");
  EXPECT_EQ(count_violations(g, rules), 5);
  rules.relax = mask("....r.....");  // 8 zeros split into 3 | relaxed | 4
  EXPECT_EQ(count_violations(g, rules), 1);
  EXPECT_EQ(longest_float(g, rules), 4);
  rules.relax = mask("...rrr....");  // 2 | relaxed | 3
  EXPECT_EQ(count_violations(g, rules), 0);
  EXPECT_EQ(consistent_stitches(g, rules), 10);
  rules.relax = mask("rrrrrrrrrr");
  EXPECT_EQ(count_violations(g, rules), 0);
  EXPECT_EQ(longest_float(g, rules), 0);
}

TEST(KnitFloats, AnchoringOffFreesRunsTouchingRowEdges) {
  FloatRules rules;
  rules.max_float = 2;
  const cv::Mat g = row("0000100011111");
  EXPECT_EQ(count_violations(g, rules), 2 + 1 + 3);
  EXPECT_EQ(longest_float(g, rules), 5);
  rules.anchoring = false;
  EXPECT_EQ(count_violations(g, rules), 1);  // only the inner run of three zeros
  EXPECT_EQ(longest_float(g, rules), 3);
  EXPECT_EQ(consistent_stitches(g, rules), 13 - 3);
  EXPECT_EQ(count_violations(row("000000"), rules), 0);  // whole row touches both edges
}

TEST(KnitFloats, RejectsBadInput) {
  FloatRules rules;
  EXPECT_THROW(count_violations(cv::Mat(), rules), std::invalid_argument);
  EXPECT_THROW(count_violations(cv::Mat(2, 2, CV_8UC1, cv::Scalar(255)), rules),
               std::invalid_argument);
  EXPECT_THROW(count_violations(cv::Mat(2, 2, CV_32F, cv::Scalar(0)), rules),
               std::invalid_argument);
  rules.max_float = 1;
  EXPECT_THROW(count_violations(cv::Mat(2, 2, CV_8UC1, cv::Scalar(0)), rules),
               std::invalid_argument);
  rules.max_float = 4;
  rules.relax = cv::Mat(3, 3, CV_8UC1, cv::Scalar(0));
  EXPECT_THROW(count_violations(cv::Mat(2, 2, CV_8UC1, cv::Scalar(0)), rules),
               std::invalid_argument);
}

}  // namespace
}  // namespace atelier::knit

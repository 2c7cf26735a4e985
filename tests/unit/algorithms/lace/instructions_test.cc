// Written lace instructions: what a hand knitter reads ("Row 1 (RS): k2, yo, ssk, ...") and the
// reader that takes the text back -- writing then reading gives the chart and cast-on back.
#include <gtest/gtest.h>

#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/instructions.h"
#include "algorithms/lace/symbols.h"
#include "tests/support/lace_test_charts.h"

namespace atelier::lace {
namespace {

using namespace test;  // row(), knit() and the charts of lace_test_charts.h

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

bool has_line(const std::string& text, const std::string& line) {
  for (const std::string& l : lines_of(text)) {
    if (l == line) return true;
  }
  return false;
}

// The example of the issue: 12 stitches, run-length and a bracketed group.
Chart example_chart() {
  return Chart{{row({"k", "k", "yo", "ssk", "k", "k", "k", "yo", "k2tog", "yo", "k2tog", "k"}),
                knit(12)}};
}

// Rows that change width: 6 -> 8 -> 8 -> 6 stitches (the paper allows intermediate rows to vary).
Chart widening_chart() {
  return Chart{{
      row({"k", "yo", "k", "k", "k", "k", "yo", "k"}),
      row({"k", "k", "yo", "k2tog", "ssk", "yo", "k", "k"}),
      row({"k", "ssk", "k", "k", "k2tog", "k"}),
  }};
}

// A random chart knittable from cast_on: each row consumes exactly what the row below made.
Chart random_chart(std::mt19937& rng, int cast_on, int rows) {
  Chart c;
  int available = cast_on;
  for (int r = 0; r < rows; ++r) {
    Row out;
    int left = available;
    std::uniform_int_distribution<int> pick(0, 9);
    while (left > 0 || (out.size() < 60 && pick(rng) == 0)) {
      const int p = pick(rng);
      Symbol s = p < 4 ? Symbol::k : p < 6 ? Symbol::yo : p < 7 ? Symbol::k2tog : p < 8 ? Symbol::ssk
                 : p < 9 ? Symbol::sk2p : Symbol::k;
      if (consumes(s) > left) s = left > 0 ? Symbol::k : Symbol::yo;
      if (out.size() > 60 && s == Symbol::yo) continue;  // keep rows finite
      out.push_back(s);
      left -= consumes(s);
    }
    available = produced(out);
    c.rows.push_back(out);
  }
  return c;
}

TEST(LaceInstructions, ExampleRowIsWrittenAsPatternBooksDo) {
  const std::string text = write_instructions(example_chart(), 12, {"Eyelet test"});
  EXPECT_TRUE(has_line(text, "Lace pattern: Eyelet test")) << text;
  EXPECT_TRUE(has_line(text, "Multiple of 12 stitches; 4-row repeat (2 right-side rows charted).")) << text;
  EXPECT_TRUE(has_line(text, "Cast on a multiple of 12 stitches.")) << text;
  EXPECT_TRUE(has_line(text, "Row 1 (RS): k2, yo, ssk, k3, [yo, k2tog] 2 times, k1. (12 sts)")) << text;
  EXPECT_TRUE(has_line(text, "Row 2 and all WS rows: purl.")) << text;
  EXPECT_TRUE(has_line(text, "Row 3 (RS): k12. (12 sts)")) << text;
  EXPECT_TRUE(has_line(text, "Repeat rows 1-4.")) << text;
  EXPECT_NE(text.find("Abbreviations:"), std::string::npos);
  EXPECT_NE(text.find("ssk"), std::string::npos);
  // Row 2's line comes right after row 1's, then row 3.
  const std::vector<std::string> lines = lines_of(text);
  for (std::size_t i = 0; i + 2 < lines.size(); ++i) {
    if (lines[i].starts_with("Row 1 (RS)")) {
      EXPECT_EQ(lines[i + 1], "Row 2 and all WS rows: purl.");
      EXPECT_TRUE(lines[i + 2].starts_with("Row 3 (RS)"));
    }
  }
}

// Issue 22, lace point 3: a double yarn-over is worked "purl 1, knit 1" on the next WS row, and
// the instructions say so where the chart has one (rows 1 and 5 here; row 3 has single ones).
TEST(LaceInstructions, DoubleYarnOversSayHowToWorkThemOnTheWrongSide) {
  const Chart c{{row({"k", "ssk", "yo", "yo", "k2tog", "k"}), row({"k", "yo", "k2tog", "k", "yo", "k2tog"}),
                 row({"k2tog", "yo", "yo", "ssk", "k", "k"})}};
  const std::string text = write_instructions(c, 6, {"double"});
  EXPECT_TRUE(has_line(text, "Row 2 and all WS rows: purl, except: purl 1, knit 1 into each double "
                             "yarn-over (yo twice) of the row below (rows 2 and 6).")) << text;
  EXPECT_NE(text.find("yo, yo double yarn-over: on the WS row after\nit purl 1, knit 1 into it"), std::string::npos) << text;
  EXPECT_EQ(parse_instructions(text).chart, c);  // the reader still takes it back
  // A double yarn-over across the repeat's edge (last stitch, then the first of the next
  // repeat) counts too; single yarn-overs only: plain "purl".
  const std::string edge = write_instructions(Chart{{row({"yo", "k", "k2tog", "k2tog", "k", "yo"})}}, 6, {});
  EXPECT_FALSE(has_line(edge, "Row 2 and all WS rows: purl.")) << edge;
  EXPECT_NE(edge.find("(row 2)"), std::string::npos) << edge;
  EXPECT_TRUE(has_line(write_instructions(example_chart(), 12, {}), "Row 2 and all WS rows: purl."));
}

TEST(LaceInstructions, RowsUseTheShortestWritingWithRepeats) {
  EXPECT_EQ(write_row(cat({row({"k2tog"}, 3), row({"yo", "k"}, 6), row({"k2tog"}, 3)})),
            "k2tog, k2tog, k2tog, [yo, k1] 6 times, k2tog, k2tog, k2tog");
  EXPECT_EQ(write_row(knit(18)), "k18");
  EXPECT_EQ(write_row(knit(1)), "k1");
  // Two repeats of a short group are written out when that is shorter.
  EXPECT_EQ(write_row(row({"yo", "k"}, 2)), "yo, k1, yo, k1");
  // Groups may hold runs of plain stitches.
  EXPECT_EQ(write_row(row({"k", "k", "k", "yo", "k2tog"}, 4)), "[k3, yo, k2tog] 4 times");
  // A single symbol repeated is never bracketed: "[ssk] 3 times" has one item.
  EXPECT_EQ(write_row(row({"ssk", "ssk", "ssk"})), "ssk, ssk, ssk");
  EXPECT_EQ(write_row(row({"k", "yo", "sk2p", "yo", "k"})), "k1, yo, sk2p, yo, k1");
}

TEST(LaceInstructions, EveryRowShowsItsStitchCount) {
  const std::string text = write_instructions(widening_chart(), 6, {});
  EXPECT_TRUE(has_line(text, "Lace pattern")) << text;
  EXPECT_TRUE(has_line(text, "Row 1 (RS): k1, yo, k4, yo, k1. (8 sts)")) << text;
  EXPECT_TRUE(has_line(text, "Row 3 (RS): k2, yo, k2tog, ssk, yo, k2. (8 sts)")) << text;
  EXPECT_TRUE(has_line(text, "Row 5 (RS): k1, ssk, k2, k2tog, k1. (6 sts)")) << text;
  EXPECT_TRUE(has_line(text, "Repeat rows 1-6.")) << text;
}

TEST(LaceInstructions, AChartEndingWiderIsWorkedOnce) {
  const Chart wider{{row({"k", "yo", "k", "yo", "k"}), knit(5)}};
  const std::string text = write_instructions(wider, 3, {"two\nlines"});
  EXPECT_TRUE(has_line(text, "Lace pattern: two lines")) << text;
  EXPECT_EQ(text.find("Repeat rows"), std::string::npos) << text;
  EXPECT_TRUE(has_line(text, "Work rows 1-4 once (the last row leaves 5 sts per repeat, so the "
                             "pattern does not repeat upward).")) << text;
  const ParsedInstructions back = parse_instructions(text);
  EXPECT_EQ(back.chart, wider);
  EXPECT_EQ(back.cast_on, 3);
}

TEST(LaceInstructions, HandMadeChartsRoundTrip) {
  struct Case {
    Chart chart;
    int cast_on;
  };
  const std::vector<Case> cases = {{example_chart(), 12},
                                   {feather_and_fan_chart(), 18},
                                   {horseshoe_chart(), 10},
                                   {widening_chart(), 6},
                                   {Chart{{row({"k"})}}, 1}};
  for (const Case& c : cases) {
    const std::string text = write_instructions(c.chart, c.cast_on, {"round trip"});
    const ParsedInstructions back = parse_instructions(text);
    EXPECT_EQ(back.chart, c.chart) << text;
    EXPECT_EQ(back.cast_on, c.cast_on) << text;
  }
}

TEST(LaceInstructions, RandomKnittableChartsRoundTrip) {
  std::mt19937 rng(20070707);
  for (int i = 0; i < 400; ++i) {
    const int cast_on = 1 + static_cast<int>(rng() % 24);
    const int rows = 1 + static_cast<int>(rng() % 8);
    const Chart chart = random_chart(rng, cast_on, rows);
    ASSERT_TRUE(knittable(chart, cast_on)) << knittable(chart, cast_on).why;
    const std::string text = write_instructions(chart, cast_on, {});
    const ParsedInstructions back = parse_instructions(text);
    ASSERT_EQ(back.chart, chart) << text;
    ASSERT_EQ(back.cast_on, cast_on) << text;
  }
}

TEST(LaceInstructions, ReaderAcceptsPlainHandWrittenRows) {
  // No header: the cast-on is what row 1 is worked over; case and spacing are free.
  const ParsedInstructions p = parse_instructions(
      "\n  ROW 1 (rs):  k1, YO, [k2tog, yo] 2 times , ssk\n"
      "row 2 and all ws rows: purl.\n\n"
      "Row 3 (RS): K7.\n");
  EXPECT_EQ(p.cast_on, 7);
  ASSERT_EQ(p.chart.rows.size(), 2u);
  EXPECT_EQ(p.chart.rows[0], row({"k", "yo", "k2tog", "yo", "k2tog", "yo", "ssk"}));
  EXPECT_EQ(p.chart.rows[1], knit(7));
}

std::string error_of(const std::string& text) {
  try {
    parse_instructions(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(LaceInstructions, ErrorsNameTheLineAndTheProblem) {
  EXPECT_EQ(error_of("Lace pattern: x\nCast on a multiple of 4 stitches.\n\nRow 1 (RS): k1, k3tog, k1. (3 sts)\n"),
            "line 4: 'k3tog' is not a stitch of this pattern (k, yo, k2tog, ssk, sk2p, s2kp)");
  // The count in parentheses is checked against the row.
  EXPECT_EQ(error_of("Row 1 (RS): k2, yo, k2tog. (5 sts)\n"),
            "line 1: row 1 makes 4 stitches but the line says (5 sts)");
  // Right-side rows are consecutive odd numbers from 1.
  EXPECT_NE(error_of("Row 1 (RS): k4.\nRow 5 (RS): k4.\n").find("line 2: found row 5 where row 3"),
            std::string::npos);
  EXPECT_NE(error_of("Row 3 (RS): k4.\n").find("line 1:"), std::string::npos);
  // A row that is not worked over what the row below made.
  EXPECT_NE(error_of("Row 1 (RS): k4.\n\nRow 3 (RS): k2tog, k3.\n").find("line 3: "), std::string::npos);
  // The cast-on must match row 1.
  EXPECT_NE(error_of("Cast on a multiple of 6 stitches.\nRow 1 (RS): k4.\n").find("line 2: "),
            std::string::npos);
  EXPECT_NE(error_of("Row 1 (RS): [k1, [yo, k1] 2 times] 2 times.\n").find("line 1: brackets inside"),
            std::string::npos);
  EXPECT_NE(error_of("Row 1 (RS): [k1, yo k1.\n").find("line 1: "), std::string::npos);
  EXPECT_NE(error_of("Row 1 (RS): k1, , k1.\n").find("line 1: an empty stitch"), std::string::npos);
  EXPECT_NE(error_of("Row 1 (RS): k4.\nKnit until you are bored.\n").find("line 2: cannot read"),
            std::string::npos);
  EXPECT_NE(error_of("Lace pattern: nothing\n").find("no 'Row 1 (RS)"), std::string::npos);
}

TEST(LaceInstructions, WriterRefusesAChartThatCannotBeKnitted) {
  EXPECT_THROW(write_instructions(example_chart(), 10, {}), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::lace

namespace atelier::lace {
namespace {

// A start chart comes from a user's file or job: odd text must be a "line N" error, never a
// crash (std::regex overflowed the stack on a 60000-item line) or gigabytes of stitches.
TEST(LaceInstructions, OversizedTextIsRefusedNotBuilt) {
  std::string items;
  for (int i = 0; i < 60000; ++i) items += i ? ", k1" : "k1";
  EXPECT_EQ(error_of("Row 1 (RS): " + items + ".\n"),
            "line 1: the line is longer than " + std::to_string(kMaxLineChars) + " characters");
  EXPECT_EQ(error_of("Row 1 (RS): k4.\nRow 3 (RS): k1" + std::string(30000, ' ') + ", k3.\n"),
            "line 2: the line is longer than " + std::to_string(kMaxLineChars) + " characters");
  EXPECT_EQ(error_of("Row 1 (RS): k536870911.\n"),
            "line 1: the row makes more than " + std::to_string(kMaxRowStitches) + " stitches");
  EXPECT_EQ(error_of("Row 1 (RS): k2, [yo, yo, k2tog] 536870911 times.\n"),
            "line 1: the row makes more than " + std::to_string(kMaxRowStitches) + " stitches");
  std::string big;
  for (int r = 0; r < 101; ++r) big += "Row " + std::to_string(2 * r + 1) + " (RS): k10000.\n";
  EXPECT_EQ(error_of(big), "line 101: the chart makes more than " +
                               std::to_string(kMaxChartStitches) + " stitches");
  // The widest rows a chart may have still read, and so does the longest line.
  EXPECT_EQ(parse_instructions("Row 1 (RS): k10000.\n").chart.rows[0].size(), kMaxRowStitches);
  std::string longest = "Row 1 (RS): k1";
  while (longest.size() + 5 <= kMaxLineChars) longest += ", k1";
  EXPECT_EQ(parse_instructions(longest + ".\n").chart.rows[0].size(), (longest.size() - 10) / 4);
  // A binary file's first line is shown short and without control bytes.
  const std::string e = error_of(std::string("\x7f") + "ELF\x02\x01\x01" + std::string(200, 'b') + "\n");
  EXPECT_EQ(e.rfind("line 1: cannot read '?ELF???bbb", 0), 0u) << e;
  EXPECT_LT(e.size(), 160u);
}

}  // namespace
}  // namespace atelier::lace

// pattern.k as a knitout consumer reads it: standard headers only, floats the report states,
// "not knittable as is" when the solution is incomplete, a bind-off that leaves no loop.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "convert/common/param_table.h"
#include "convert/convert.h"
#include "convert/knit/knit_knitout.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
const fs::path kData = ATELIER_TEST_DATA;

std::vector<std::string> lines_of(const std::string& k) {
  std::vector<std::string> out;
  std::istringstream in(k);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

// The longest float in the file as a knitout consumer follows it: for each carrier, the
// needles strictly between two of its consecutive stitches (knit or tuck), whatever lies
// between them in the file (a turn at a row's end included).
int longest_float_in_file(const std::string& k) {
  std::map<std::string, int> prev;  // carrier -> needle of its last stitch
  int longest = 0;
  for (const std::string& line : lines_of(k)) {
    std::istringstream op(line);
    std::string verb, d, needle, carrier;
    op >> verb >> d >> needle >> carrier;
    if (verb == "miss") ADD_FAILURE() << "a miss is a float the writer should not need: " << line;
    if (verb != "knit" && verb != "tuck") continue;
    const int n = std::stoi(needle.substr(1));
    if (auto it = prev.find(carrier); it != prev.end()) longest = std::max(longest, std::abs(n - it->second) - 1);
    prev[carrier] = n;
  }
  return longest;
}

// Loops on each needle after the file, by a loop-level reading of knit/tuck/xfer/drop/rack;
// fails the test when an xfer does not face its target at the current rack.
std::map<std::string, int> loops_left(const std::string& k) {
  std::map<std::string, int> loops;
  int rack = 0;
  for (const std::string& line : lines_of(k)) {
    std::istringstream op(line);
    std::string verb;
    op >> verb;
    if (verb == "rack") {
      op >> rack;
    } else if (verb == "knit" || verb == "tuck") {
      std::string d, n;
      op >> d >> n;
      loops[n] = verb == "knit" ? 1 : loops[n] + 1;
    } else if (verb == "xfer") {
      std::string a, b;
      op >> a >> b;
      const int x = std::stoi(a.substr(1)), y = std::stoi(b.substr(1));
      const int front = a[0] == 'f' ? x : y, back = a[0] == 'f' ? y : x;
      EXPECT_EQ(back, front - rack) << line << " at rack " << rack;
      loops[b] += loops[a];
      loops[a] = 0;
    } else if (verb == "drop") {
      std::string n;
      op >> n;
      loops[n] = 0;
    }
  }
  for (auto it = loops.begin(); it != loops.end();) it = it->second == 0 ? loops.erase(it) : std::next(it);
  return loops;
}

cv::Mat edge_grid() {
  // 9 stitches, 3 rows; row 1 has a 7-stitch background run on the left edge.
  cv::Mat g = (cv::Mat_<uchar>(3, 9) << 0, 0, 0, 0, 0, 0, 0, 1, 1,  //
               1, 0, 1, 0, 1, 0, 1, 0, 1,                          //
               0, 1, 1, 0, 0, 1, 1, 0, 0);
  return g;
}

TEST(KnitKnitout, HeaderLinesAreTheStandardOnes) {
  KnitoutOptions o;
  o.title = "test";
  o.stitches_per_10cm = 28;
  const std::vector<std::string> l = lines_of(make_knitout(edge_grid(), o));
  ASSERT_GE(l.size(), 5u);
  EXPECT_EQ(l[0], ";!knitout-2");
  EXPECT_EQ(l[1], ";;Machine: SWG091N2");
  EXPECT_EQ(l[2], ";;Gauge: 7");  // 28 stitches per 10 cm = 7.1 needles per inch
  EXPECT_EQ(l[3], ";;Carriers: 1 2 3 4 5 6 7 8 9 10");  // the SWG091N2's, as its backend wants
  EXPECT_EQ(l[4], ";;Position: Center");
  EXPECT_NE(std::find(l.begin(), l.end(), "; carriers used: 1 2"), l.end());
  for (size_t i = 5; i < l.size(); ++i) EXPECT_NE(l[i].rfind(";;", 0), 0u) << l[i];
}

// Row 3 (grid row 0) has a 7-stitch background run at the left edge: the contrast yarn turns
// at its last stitch instead of floating across it, so the longest float is 2 (row 1's runs).
TEST(KnitKnitout, EachYarnGoesFromStitchToStitchAndTheStatedFloatIsTheFiles) {
  const cv::Mat g = edge_grid();
  EXPECT_EQ(knitout_longest_float(g, false), 2);
  EXPECT_EQ(longest_float_in_file(make_knitout(g, {})), 2);
  KnitoutOptions top;
  top.first_row_top = true;
  EXPECT_EQ(knitout_longest_float(g, true), longest_float_in_file(make_knitout(g, top)));
  // Edge runs a turn spans (row 1 "0001111111" leftwards, then row 2 "1111111000"): carrier 1
  // ends the plain rows on needle 10 and starts row 1 on needle 3 (6 needles behind), then goes
  // from needle 1 to its first stitch of row 2 on needle 8 (6 again).
  const cv::Mat turns = (cv::Mat_<uchar>(2, 10) << 1, 1, 1, 1, 1, 1, 1, 0, 0, 0,  //
                         0, 0, 0, 1, 1, 1, 1, 1, 1, 1);
  EXPECT_EQ(knitout_longest_float(turns, false), 6);
  EXPECT_EQ(longest_float_in_file(make_knitout(turns, {})), 6);
}

// The yarn-inserting hook holds carrier 2 beside its first stitch until released: no other
// stitch may come between the inhook and carrier 2's first knit (a loop-level interpreter
// refuses carrier 1's needles next to the hook).
TEST(KnitKnitout, TheContrastYarnComesInJustBeforeItsFirstStitch) {
  cv::Mat g = edge_grid();
  g.row(2).setTo(0);  // row 1 all background: carrier 2 starts in row 2
  const std::vector<std::string> l = lines_of(make_knitout(g, {}));
  const auto in = std::find(l.begin(), l.end(), "inhook 2");
  ASSERT_NE(in, l.end());
  ASSERT_NE(in + 1, l.end());
  EXPECT_EQ((in + 1)->rfind("knit ", 0), 0u) << *(in + 1);
  EXPECT_EQ((in + 1)->back(), '2') << *(in + 1);
  const auto row2 = std::find(l.begin(), l.end(), "; row 2");
  EXPECT_LT(row2, in) << "carrier 2 has no stitch in row 1";
  EXPECT_EQ(std::count(l.begin(), l.end(), "releasehook 2"), 1);
}

TEST(KnitKnitout, NotKnittableIsSaidInTheHeader) {
  KnitoutOptions o;
  o.not_knittable = "floats up to 7 needles, limit 4";
  const std::vector<std::string> l = lines_of(make_knitout(edge_grid(), o));
  ASSERT_GE(l.size(), 6u);
  EXPECT_EQ(l[5], "; NOT KNITTABLE AS IS: floats up to 7 needles, limit 4");
  for (const std::string& line : lines_of(make_knitout(edge_grid(), {})))
    EXPECT_EQ(line.find("NOT KNITTABLE"), std::string::npos);
}

TEST(KnitKnitout, BindOffLeavesNoLoopOnTheNeedles) {
  for (int rows : {3, 2}) {  // ends on either side
    const cv::Mat g = edge_grid().rowRange(0, rows);
    const std::string k = make_knitout(g, {});
    EXPECT_NE(k.find("; bind-off"), std::string::npos);
    EXPECT_TRUE(loops_left(k).empty()) << rows << " rows";
    EXPECT_LT(k.rfind("outhook 1"), k.rfind("drop "));
    EXPECT_LT(k.rfind("outhook 2"), k.find("; bind-off"));
  }
}

class KnitJobKnitout : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = fs::temp_directory_path() / ("atelier-knitout-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(out_);
  }
  void TearDown() override { fs::remove_all(out_); }
  nlohmann::json run(const std::vector<std::string>& sets) {
    ConvertRequest req;
    req.kind = "knit";
    req.input = kData / "fruits.jpg";
    for (const auto& s : sets) apply_set(req.params, s);
    req.output_dir = out_;
    convert(req);
    std::ifstream in(out_ / "report.json");
    return nlohmann::json::parse(in);
  }
  std::string knitout() const {
    std::ifstream in(out_ / "pattern.k", std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  fs::path out_;
};

// anchoring = false frees edge runs for the solver; pattern.k does not carry a yarn into them,
// but a turn between rows can still span one: the report's longest_float is what the file
// holds, and a float over the limit is said in the report and the file's header.
TEST_F(KnitJobKnitout, ReportedFloatIsTheKnitoutsWithAnchoringOff) {
  const nlohmann::json r = run({"width=60", "anchoring=false"});
  const int in_file = longest_float_in_file(knitout());
  EXPECT_EQ(r["longest_float"].get<int>(), in_file);
  EXPECT_LE(r["longest_constrained_float"].get<int>(), 4);
  EXPECT_TRUE(r["knittable"].get<bool>());
  ASSERT_EQ(r["warnings"].size(), in_file > 4 ? 1u : 0u) << r["warnings"].dump();
  if (in_file > 4) {
    const std::string w = r["warnings"][0].get<std::string>();
    EXPECT_NE(w.find("floats up to " + std::to_string(in_file) + " needles"), std::string::npos) << w;
    EXPECT_NE(knitout().find("\n; NOTE: " + w + "\n"), std::string::npos);
  }
}

TEST_F(KnitJobKnitout, IncompleteSolutionIsNotKnittableAsIs) {
  const nlohmann::json r = run({"width=60", "solver=\"none\""});
  ASSERT_GT(r["conflicts_after"].get<long>(), 0);
  EXPECT_FALSE(r["knittable"].get<bool>());
  const int longest = longest_float_in_file(knitout());
  EXPECT_EQ(r["longest_float"].get<int>(), longest);
  ASSERT_EQ(r["warnings"].size(), 1u);
  const std::string w = r["warnings"][0].get<std::string>();
  EXPECT_EQ(w.rfind("not knittable as is: floats up to " + std::to_string(longest) + " needles, limit 4", 0), 0u)
      << w;
  EXPECT_NE(knitout().find("; NOT KNITTABLE AS IS: floats up to " + std::to_string(longest)), std::string::npos);
}

TEST_F(KnitJobKnitout, CompleteSolutionHasNoWarnings) {
  const nlohmann::json r = run({"width=60"});
  EXPECT_TRUE(r["knittable"].get<bool>());
  EXPECT_TRUE(r["warnings"].empty());
  // With anchoring every edge run is bounded by the solver, so no turn spans more either.
  EXPECT_LE(longest_float_in_file(knitout()), 4);
  EXPECT_EQ(r["longest_float"].get<int>(), longest_float_in_file(knitout()));
  EXPECT_EQ(knitout().find("NOT KNITTABLE"), std::string::npos);
}

}  // namespace
}  // namespace atelier

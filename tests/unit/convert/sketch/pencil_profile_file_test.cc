// Pencil profiles as files (issue 8): the TOML format reads back exactly what was written,
// refuses malformed files naming the file, line and key; the shipped 2H .. 8B profiles are what
// learn_profile makes of the grade model's reference scans today, and get darker and wider from
// 2H to 8B; the `pencil` parameter takes a grade or a profile file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <numeric>
#include <regex>
#include <stdexcept>
#include <string>

#include "algorithms/pencil/profile.h"
#include "algorithms/pencil/reference_scan.h"
#include "convert/convert.h"
#include "convert/sketch/pencil_profile_file.h"
#include "tests/unit/algorithms/pencil/reference_scan_fixture.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using pencil::PencilProfile;
using pencil::testing::model;

void expect_same(const PencilProfile& a, const PencilProfile& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.min_mid, b.min_mid);
  EXPECT_EQ(a.max_mid, b.max_mid);
  EXPECT_EQ(a.min_range, b.min_range);
  EXPECT_EQ(a.max_range, b.max_range);
  EXPECT_EQ(a.width_px, b.width_px);
  EXPECT_EQ(a.mid_pixels, b.mid_pixels);
  EXPECT_EQ(a.line_pixels, b.line_pixels);
  EXPECT_EQ(a.ccm_pairs, b.ccm_pairs);
  EXPECT_TRUE(a.mid_hist == b.mid_hist) << a.name << ": mid_hist differs";
  EXPECT_TRUE(a.hist == b.hist) << a.name << ": hist differs";
  EXPECT_TRUE(a.ccm == b.ccm) << a.name << ": ccm differs";
}

const PencilProfile& learned() {
  static const PencilProfile p = pencil::learn_profile(pencil::reference_scan(model("B"), 150, 5), "my B");
  return p;
}

// The message of the ConvertError that reading `text` as `source` throws ("" if none).
std::string read_error(const std::string& text, const std::string& source = "mine.toml") {
  try {
    profile_from_toml(text, source);
  } catch (const ConvertError& e) {
    return e.what();
  }
  return "";
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("'" + from + "' not in the profile text");
  return text.replace(at, from.size(), to);
}

int line_of(const std::string& text, const std::string& what) {
  const auto at = text.find(what);
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

double mean_grey(const PencilProfile& p) {
  double m = 0;
  for (int i = 0; i < 256; ++i) m += i * p.hist[i];
  return m;
}

TEST(PencilProfileFile, RoundTripGivesBackTheSameProfile) {
  const PencilProfile& p = learned();
  ASSERT_EQ(p.mid_pixels * p.width_px, static_cast<double>(p.line_pixels)) << "counts filled by learn_profile";
  const std::string text = profile_to_toml(p, "lines.png");
  EXPECT_THAT(text, HasSubstr("format = \"atelier-pencil-profile 1\""));
  EXPECT_THAT(text, HasSubstr("source = \"lines.png\""));
  EXPECT_THAT(text, HasSubstr("name = \"my B\""));
  EXPECT_EQ(text.rfind("# atelier pencil profile", 0), 0u) << "a comment header says what it is";
  const PencilProfile again = profile_from_toml(text, "lines.toml");
  expect_same(again, p);
  EXPECT_EQ(profile_to_toml(again, "lines.png"), text);

  // And through a file.
  const fs::path file = fs::temp_directory_path() / ("pencil-profile-" + std::to_string(::getpid()) + ".toml");
  std::ofstream(file) << text;
  expect_same(load_profile_file(file), p);
  fs::remove(file);
  try {
    load_profile_file(file);
    ADD_FAILURE() << "a missing file loads";
  } catch (const ConvertError& e) {
    EXPECT_THAT(e.what(), HasSubstr(file.string()));
  }
  // A profile without counts (not from learn_profile) cannot be written exactly.
  PencilProfile made = p;
  made.line_pixels = 0;
  EXPECT_THROW(profile_to_toml(made), std::invalid_argument);
}

TEST(PencilProfileFile, StrictReadingNamesTheFileLineAndKey) {
  const std::string text = profile_to_toml(learned(), "lines.png");
  ASSERT_EQ(read_error(text), "");

  EXPECT_THAT(read_error(text + "colour = 3\n"), HasSubstr("unknown key 'colour'"));
  EXPECT_THAT(read_error(text + "colour = 3\n"), HasSubstr("mine.toml:"));

  const std::string bad_ccm = replaced(text, "ccm = [\n", "ccm = [\n  [300, 2, 1],\n");
  const std::string at = "mine.toml:" + std::to_string(line_of(bad_ccm, "[300, 2, 1]")) + ": key 'ccm'";
  EXPECT_THAT(read_error(bad_ccm), HasSubstr(at));
  EXPECT_THAT(read_error(bad_ccm), HasSubstr("300 is outside 0..255"));
  EXPECT_THAT(read_error(replaced(text, "ccm = [\n", "ccm = [\n  [2, 3],\n")), HasSubstr("key 'ccm'"));

  const std::regex width_line("width_px = [^\n]*\n");
  const std::string no_width = std::regex_replace(text, width_line, "");
  EXPECT_THAT(read_error(no_width), HasSubstr("mine.toml: key 'width_px': missing"));

  const std::regex min_mid("min_mid = [0-9]+");
  EXPECT_THAT(read_error(std::regex_replace(text, min_mid, "min_mid = \"dark\"")),
              HasSubstr("key 'min_mid': expected an integer"));
  const std::regex max_range("max_range = [0-9]+");
  EXPECT_THAT(read_error(std::regex_replace(text, max_range, "max_range = 300")), HasSubstr("key 'max_range'"));
  const std::regex pixels("line_pixels = [0-9]+");
  EXPECT_THAT(read_error(std::regex_replace(text, pixels, "line_pixels = 999999")),
              HasSubstr("key 'hist': the counts add up to"));
  EXPECT_THAT(read_error(replaced(text, "mid_hist = [\n  0,", "mid_hist = [\n  -1,")),
              HasSubstr("key 'mid_hist': grey level 0: count -1 is negative"));
  EXPECT_THAT(read_error(replaced(text, "mid_hist = [\n", "mid_hist = [\n 0,")),
              HasSubstr("key 'mid_hist': expected 256 counts"));
  EXPECT_THAT(read_error(replaced(text, "atelier-pencil-profile 1", "atelier-pencil-profile 2")),
              HasSubstr("key 'format'"));
  // A TOML syntax error names the file and line too.
  EXPECT_THAT(read_error("name = \"x\"\nwidth_px = = 3\n"), HasSubstr("mine.toml:2:"));
}

TEST(PencilProfileFile, ShippedProfilesAreTheGradeModelsLearnedToday) {
  const std::vector<std::string> grades = {"2H", "H", "F", "HB", "B", "3B", "6B", "8B"};
  ASSERT_EQ(shipped_pencils(), grades) << "data/pencils/*.toml compiled in (tools/make-pencil-profiles)";
  ASSERT_EQ(pencil::grade_models().size(), grades.size());
  double last_mean = 256, last_width = 0;
  for (size_t i = 0; i < grades.size(); ++i) {
    const std::string& g = grades[i];
    SCOPED_TRACE(g);
    EXPECT_EQ(pencil::grade_models()[i].name, g);
    const PencilProfile shipped = shipped_pencil(g);
    // If this fails, the model or learn_profile changed: run tools/make-pencil-profiles.
    expect_same(shipped, pencil::learn_profile(pencil::reference_scan(model(g), pencil::kReferenceRows,
                                                                       pencil::kReferenceSeed),
                                               g));
    const double mean = mean_grey(shipped);
    std::printf("%-2s mean grey %.1f, centre %d..%d, width %.2f px\n", g.c_str(), mean, shipped.min_mid,
                shipped.max_mid, shipped.width_px);
    EXPECT_LT(mean, last_mean) << "darker than the grade before";
    EXPECT_GE(shipped.width_px, last_width) << "at least as wide as the grade before";
    last_mean = mean, last_width = shipped.width_px;
    const fs::path file = fs::path(ATELIER_SOURCE_DIR) / "data" / "pencils" / (g + ".toml");
    ASSERT_TRUE(fs::exists(file));
    EXPECT_LT(fs::file_size(file), 150u * 1024u);
    expect_same(load_profile_file(file), shipped);
  }
  EXPECT_EQ(shipped_pencil("6b").name, "6B");
  try {
    shipped_pencil("7X");
    ADD_FAILURE() << "an unknown grade";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("7X"));
    EXPECT_THAT(e.what(), HasSubstr("2H, H, F, HB, B, 3B, 6B, 8B"));
  }
}

TEST(PencilProfileFile, PencilParameterTakesAGradeOrAProfileFile) {
  EXPECT_EQ(resolve_pencil("hb", {}, "job.toml").name, "HB");
  expect_same(resolve_pencil("3B", "/nonexistent", "job.toml"), shipped_pencil("3B"));

  const fs::path dir = fs::temp_directory_path() / ("pencil-resolve-" + std::to_string(::getpid()));
  fs::create_directories(dir / "pencils");
  std::ofstream(dir / "pencils" / "mine.toml") << profile_to_toml(learned(), "lines.png");
  expect_same(resolve_pencil("pencils/mine.toml", dir, "job.toml"), learned());
  expect_same(resolve_pencil((dir / "pencils" / "mine.toml").string(), "/elsewhere", "job.toml"), learned());

  auto error = [](const std::string& value, const fs::path& base) {
    try {
      resolve_pencil(value, base, "job.toml");
    } catch (const ConvertError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string unknown = error("7X", dir);
  EXPECT_THAT(unknown, HasSubstr("job.toml: key 'pencil': '7X'"));
  EXPECT_THAT(unknown, HasSubstr("2H, H, F, HB, B, 3B, 6B, 8B"));
  const std::string missing = error("pencils/none.toml", dir);
  EXPECT_THAT(missing, HasSubstr("job.toml: key 'pencil'"));
  EXPECT_THAT(missing, HasSubstr("none.toml"));
  std::ofstream(dir / "bad.toml") << "format = \"atelier-pencil-profile 1\"\nname = 3\n";
  const std::string bad = error("bad.toml", dir);
  EXPECT_THAT(bad, HasSubstr("bad.toml:2: key 'name'"));
  fs::remove_all(dir);
}

// Counts are added in 64 bits: four of 2^62 add up to 2^64, which wrapped round to the stated
// total, and such a file was accepted.
TEST(PencilProfileFile, CountsAboveTheirTotalAreRefused) {
  std::string text = profile_to_toml(learned(), "lines.png");
  const std::string huge = " 4611686018427387904,";
  text = replaced(text, "mid_hist = [\n ", "mid_hist = [\n " + huge + huge + huge + huge);
  // ... and the last four counts (grey levels 252..255: no centre is that light) dropped, so that
  // there are still 256. The array's last line is "  c240, ..., c255,  # 240..255".
  const auto end = text.find("  # 240..255\n]", text.find("mid_hist = ["));
  ASSERT_NE(end, std::string::npos);
  auto cut = end;
  for (int k = 0; k < 5; ++k) cut = text.rfind(',', cut - 1);
  ASSERT_EQ(text.substr(cut, end - cut), ", 0, 0, 0, 0,") << "the last counts are not zeros";
  text.erase(cut + 1, end - cut - 1);
  EXPECT_THAT(read_error(text), HasSubstr("key 'mid_hist': grey level 0: count 4611686018427387904 is more than"));
  // A ccm count past 2^40 says what the range is (it said "at least 1").
  const std::string ccm = replaced(profile_to_toml(learned(), "lines.png"), "ccm = [\n", "ccm = [\n  [0, 0, 2000000000000],\n");
  EXPECT_THAT(read_error(ccm), HasSubstr("entry [0, 0, 2000000000000]: count must be 1 .. 2^40"));
}

// Reading is bounded: the largest profile that can be written (every ccm cell, the largest
// counts) reads back, and a file over 4 MiB is refused before parsing (a 15 MiB file of one long
// array took 630 MB to parse).
TEST(PencilProfileFile, TheLargestProfileReadsBackAndOversizedFilesAreRefused) {
  const fs::path dir = fs::temp_directory_path() / ("pencil-profile-size-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  PencilProfile p = learned();
  p.ccm_pairs = (int64_t{1} << 40) * 65536;
  p.ccm.assign(65536, 1.0 / 65536);
  const std::string text = profile_to_toml(p, "lines.png");
  { std::ofstream(dir / "largest.toml") << text; }
  EXPECT_GT(text.size(), 1u << 20);
  expect_same(load_profile_file(dir / "largest.toml"), p);
  { std::ofstream(dir / "padded.toml") << text << "#" << std::string(4u << 20, 'x') << "\n"; }
  try {
    load_profile_file(dir / "padded.toml");
    ADD_FAILURE() << "a file over 4 MiB was read";
  } catch (const ConvertError& e) {
    EXPECT_THAT(e.what(), HasSubstr("padded.toml: "));
    EXPECT_THAT(e.what(), HasSubstr("over the limit of 4194304 bytes"));
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace atelier

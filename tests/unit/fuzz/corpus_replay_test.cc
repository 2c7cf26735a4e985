// Every input of the fuzz corpus (tests/fuzz/corpus/<target>/) and every input a fuzzer once
// crashed on (tests/fuzz/regressions/<target>/) goes through its target here, in the normal
// test binary: each must come back normally. A crash, an abort or an escaping exception is a
// failed test run ("Fuzzing" in README.md). Inputs under tests/fuzz/known-toml-crashes/ (crashes
// inside toml++ itself) are not replayed.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include "tests/fuzz/fuzz_targets.h"

namespace fs = std::filesystem;

namespace {

const fs::path kFuzzDir = fs::path(ATELIER_SOURCE_DIR) / "tests" / "fuzz";

std::vector<fs::path> inputs_in(const fs::path& dir) {
  std::vector<fs::path> out;
  if (!fs::is_directory(dir)) return out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file()) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<uint8_t> bytes_of(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class CorpusReplay : public ::testing::TestWithParam<atelier::fuzz::TargetInfo> {};

TEST_P(CorpusReplay, EveryCorpusAndRegressionInputReturnsNormally) {
  const auto& target = GetParam();
  const std::string name(target.name);
  const auto corpus = inputs_in(kFuzzDir / "corpus" / name);
  EXPECT_FALSE(corpus.empty()) << "no seed inputs in tests/fuzz/corpus/" << name;
  auto all = corpus;
  for (const auto& f : inputs_in(kFuzzDir / "regressions" / name)) all.push_back(f);
  for (const fs::path& file : all) {
    SCOPED_TRACE(fs::relative(file, kFuzzDir).string());
    const std::vector<uint8_t> data = bytes_of(file);
    ASSERT_LE(data.size(), atelier::fuzz::kMaxFuzzInput) << "larger than a target reads";
    EXPECT_EQ(target.run(data.data(), data.size()), 0);
  }
}

INSTANTIATE_TEST_SUITE_P(Targets, CorpusReplay, ::testing::ValuesIn(atelier::fuzz::all_targets()),
                         [](const auto& info) { return std::string(info.param.name); });

// A folder named after no target would never be replayed.
TEST(CorpusReplay, EveryInputFolderNamesATarget) {
  std::set<std::string> names;
  for (const auto& t : atelier::fuzz::all_targets()) names.emplace(t.name);
  for (const char* kind : {"corpus", "regressions"}) {
    if (!fs::is_directory(kFuzzDir / kind)) continue;
    for (const auto& e : fs::directory_iterator(kFuzzDir / kind))
      EXPECT_TRUE(names.count(e.path().filename().string()))
          << "tests/fuzz/" << kind << "/" << e.path().filename().string() << " is no fuzz target";
  }
}

}  // namespace

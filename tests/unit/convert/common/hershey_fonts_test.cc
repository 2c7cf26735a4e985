// Loading the Hershey fonts (convert/common/hershey_fonts.h): a missing font names its file, a
// bad name is refused, and threads racing to load a font get one consistent font.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "algorithms/laser/hershey_text.h"
#include "convert/common/hershey_fonts.h"
#include "tests/unit/convert/common/hershey_fonts_fixture.h"

namespace atelier::laser {
namespace {

using testing::font_named;
using testing::same_strokes;

TEST(LaserHershey, MissingFontNamesTheFile) {
  try {
    hershey_text(font_named("nosuchfont"), "1", {0, 0}, 5, 0);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("nosuchfont.jhf"), std::string::npos) << what;
    EXPECT_NE(what.find("not found"), std::string::npos) << what;
  }
  EXPECT_THROW(hershey_text(font_named("../etc/passwd"), "1", {0, 0}, 5, 0), std::invalid_argument);
}

TEST(LaserHershey, ConcurrentFirstUseLoadsOneConsistentFont) {
  // "scripts" is used by no other test, so these threads race to load it.
  std::vector<std::vector<Path>> results(4);
  std::vector<std::thread> threads;
  for (size_t i = 0; i < results.size(); ++i)
    threads.emplace_back([&, i] { results[i] = hershey_text(font_named("scripts"), "Ab3", {1, 2}, 6, 15); });
  for (auto& t : threads) t.join();
  ASSERT_FALSE(results[0].empty());
  for (size_t i = 1; i < results.size(); ++i) EXPECT_TRUE(same_strokes(results[0], results[i]));
}

}  // namespace
}  // namespace atelier::laser

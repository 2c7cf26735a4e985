// Every shipped pencil (2H .. 8B) draws lines whose statistics match its own profile (DESIGN:
// "the texture's grey-level histogram and co-occurrence statistics match the chosen pencil
// profile"), better than random grey levels and better than the other grades do.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "algorithms/pencil/path.h"
#include "algorithms/pencil/profile.h"
#include "algorithms/pencil/texture.h"
#include "convert/sketch/pencil_profile_file.h"
#include "tests/support/pencil_test_lines.h"

namespace atelier::pencil {
namespace {

// Four nearly vertical hand-drawn lines, as a scan to learn from would show them.
cv::Mat drawn_lines(const PencilProfile& p, std::uint64_t seed) { return testing::drawn_lines(p, seed, 4); }

TEST(PencilGrades, EveryShippedPencilDrawsItsOwnStatistics) {
  std::vector<PencilProfile> grades, learned;
  for (const auto& name : shipped_pencils()) {
    grades.push_back(shipped_pencil(name));
    learned.push_back(learn_profile(drawn_lines(grades.back(), 5), name));
  }
  for (size_t g = 0; g < grades.size(); ++g) {
    const PencilProfile& p = grades[g];
    SCOPED_TRACE(p.name);
    // The same pixels with uniform random graphite grey levels.
    cv::Mat noise = drawn_lines(p, 5);
    std::mt19937_64 rng(3);
    std::uniform_int_distribution<int> grey(0, 244);
    for (auto it = noise.begin<std::uint8_t>(); it != noise.end<std::uint8_t>(); ++it)
      if (*it < 245) *it = static_cast<std::uint8_t>(grey(rng));
    const PencilProfile random = learn_profile(noise, "noise");
    const double hist = chi_square(p.hist, learned[g].hist), hist_noise = chi_square(p.hist, random.hist);
    const double ccm = chi_square(p.ccm, learned[g].ccm), ccm_noise = chi_square(p.ccm, random.ccm);
    std::printf("%s: hist %.3f (noise %.3f), ccm %.3f (noise %.3f), width %.2f (profile %.2f)\n", p.name.c_str(),
                hist, hist_noise, ccm, ccm_noise, learned[g].width_px, p.width_px);
    EXPECT_LT(hist, 0.5 * hist_noise);
    EXPECT_LT(ccm, 0.8 * ccm_noise);
    EXPECT_NEAR(learned[g].width_px, p.width_px, 0.25 * p.width_px + 0.3);
    // A line drawn with this pencil is closer to it than to every other grade.
    for (size_t other = 0; other < grades.size(); ++other)
      if (other != g) EXPECT_LT(hist, chi_square(grades[other].hist, learned[g].hist)) << grades[other].name;
  }
}

}  // namespace
}  // namespace atelier::pencil

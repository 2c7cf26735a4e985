// The reference textures (algorithms/embroidery/textures.h): checked, deterministic, refused by
// the synthesis when incomplete.
#include <gtest/gtest.h>

#include "algorithms/embroidery/directions.h"
#include "algorithms/embroidery/synthesis.h"
#include "algorithms/embroidery/textures.h"
#include "tests/unit/algorithms/embroidery/synthesis_fixture.h"

namespace atelier::embroidery {
namespace {

using test::drawn_design;

TEST(EmbroiderySynthesis, TexturesAreCheckedAndDeterministic) {
  const TextureSet a = procedural_textures(), b = procedural_textures();
  for (int s = 0; s < kStyleCount; ++s) {
    EXPECT_NO_THROW(validate_texture(a.style[s]));
    EXPECT_EQ(cv::norm(a.style[s].color, b.style[s].color, cv::NORM_INF), 0);
    // Seams exist (some transparency) but most of the tile is thread.
    const double thread = cv::countNonZero(a.style[s].alpha >= 128) / double(a.style[s].alpha.total());
    EXPECT_GT(thread, 0.75) << style_name(static_cast<Style>(s));
  }
  EXPECT_GT(cv::countNonZero(a.style[0].alpha < 128), 0);   // long-short stitch ends
  ReferenceTexture bad = a.style[0];
  bad.alpha = cv::Mat1b(3, 3, uchar(255));
  EXPECT_THROW(validate_texture(bad), std::invalid_argument);
  bad = a.style[0];
  bad.width_mm = 0;
  EXPECT_THROW(validate_texture(bad), std::invalid_argument);
  TextureSet set = a;
  set.style[1].normal = cv::Mat3b();
  const Segmentation seg = drawn_design();
  EXPECT_THROW(synthesize(seg, region_directions(seg), set, SynthesisParams{}), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::embroidery

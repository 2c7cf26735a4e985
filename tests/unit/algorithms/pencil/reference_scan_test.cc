// The modelled reference scans of the pencil grades (algorithms/pencil/reference_scan.h): hard and
// soft grades as modelled, grain along the line, reproducible by seed, bad models refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "algorithms/pencil/profile.h"
#include "algorithms/pencil/reference_scan.h"
#include "convert/sketch/pencil_profile_file.h"
#include "tests/unit/algorithms/pencil/reference_scan_fixture.h"

namespace atelier {
namespace {

using pencil::PencilProfile;
using pencil::testing::model;

TEST(PencilProfileFile, ReferenceScansModelHardAndSoftGrades) {
  const PencilProfile hard = shipped_pencil("2H"), soft = shipped_pencil("8B");
  auto mean_mid = [](const PencilProfile& p) {
    double m = 0;
    for (int i = 0; i < 256; ++i) m += i * p.mid_hist[i];
    return m;
  };
  EXPECT_GT(mean_mid(hard), 140);  // modelled 150..190, less the grain
  EXPECT_LT(mean_mid(hard), 200);
  EXPECT_GT(mean_mid(soft), 30);   // modelled 38..70
  EXPECT_LT(mean_mid(soft), 80);
  EXPECT_LT(hard.width_px, 0.5 * soft.width_px);

  // Grain runs along the line (paper tooth): neighbours along the line differ clearly less than
  // in the same model with uncorrelated grain.
  auto along = [](const pencil::GradeModel& m) {
    const cv::Mat scan = pencil::reference_scan(m, 300, 3);
    double sum = 0;
    int n = 0;
    for (int y = 0; y + 1 < scan.rows; ++y)
      for (int x = 0; x < scan.cols; ++x) {
        const int v = scan.at<uchar>(y, x), below = scan.at<uchar>(y + 1, x);
        if (v < 245 && below < 245) sum += std::abs(v - below), ++n;
      }
    return sum / n;
  };
  for (const char* g : {"2H", "HB", "6B"}) {
    pencil::GradeModel grainy = model(g);
    grainy.tooth_px = 0.01;  // no correlation from one row to the next
    const double correlated = along(model(g)), uncorrelated = along(grainy);
    std::printf("%s: mean |difference| along the line %.1f, %.1f with uncorrelated grain\n", g, correlated,
                uncorrelated);
    EXPECT_LT(correlated, 0.85 * uncorrelated) << g;
  }
  const cv::Mat a = pencil::reference_scan(model("HB"), 100, 1);
  EXPECT_EQ(cv::norm(a, pencil::reference_scan(model("HB"), 100, 1), cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a, pencil::reference_scan(model("HB"), 100, 2), cv::NORM_L1), 1000.0);
  EXPECT_THROW(pencil::reference_scan(model("HB"), 0, 1), std::invalid_argument);
  pencil::GradeModel broken = model("HB");
  broken.centre_lo = 200;
  EXPECT_THROW(pencil::reference_scan(broken, 10, 1), std::invalid_argument);
}

}  // namespace
}  // namespace atelier

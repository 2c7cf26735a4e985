// Choosing per seam (refine = dp): a refined cut is kept where it makes the reconstruction
// read closer to the target (blurred SSIM) and put back straight where it reads worse.
#include <gtest/gtest.h>

#include "algorithms/parquetry/quality.h"
#include "algorithms/parquetry/seam_choice.h"

namespace atelier::parquetry {
namespace {

constexpr int kPitch = 24, kHalf = 5;
constexpr double kPxPerMm = 2.0;

// Two cells side by side: black wood left, white wood right; the target's edge at `edge_x`.
struct TwoCells {
  SeamInput in;
  std::vector<cv::Mat> wood;
  cv::Mat target;
  Seams seams;
};

TwoCells two_cells(int edge_x, int cut_x) {
  TwoCells t;
  t.in.cols = 2, t.in.rows = 1, t.in.pitch = kPitch, t.in.half = kHalf;
  const int W = 2 * kPitch, H = kPitch;
  t.in.target_f1 = cv::Mat::zeros(H, W, CV_32F);
  t.in.target_f2 = cv::Mat::zeros(H, W, CV_32F);
  for (int c = 0; c < 2; ++c) {
    const cv::Rect win = cell_window(t.in, c, 0);
    t.in.wood_f1.push_back(cv::Mat::zeros(win.size(), CV_32F));
    t.in.wood_f2.push_back(cv::Mat::zeros(win.size(), CV_32F));
    t.wood.push_back(cv::Mat(win.size(), CV_8UC3, cv::Scalar::all(c == 0 ? 20 : 230)));
  }
  t.target = cv::Mat(H, W, CV_8UC3, cv::Scalar::all(230));
  t.target(cv::Rect(0, 0, edge_x, H)).setTo(cv::Scalar::all(20));
  t.seams.vertical = {std::vector<int>(H, 0), std::vector<int>(H, cut_x), std::vector<int>(H, W)};
  t.seams.horizontal = {std::vector<int>(W, 0), std::vector<int>(W, H)};
  return t;
}

TEST(ParquetrySeamChoice, KeepsACutThatFollowsTheTargetsEdge) {
  TwoCells t = two_cells(kPitch + 4, kPitch + 4);  // the cut on the edge, off its grid line
  const SeamChoice c = choose_seams(t.seams, t.in, t.wood, t.target, kPxPerMm);
  EXPECT_EQ(c.kept, 1);
  EXPECT_EQ(c.straightened, 0);
  for (int x : t.seams.vertical[1]) EXPECT_EQ(x, kPitch + 4);
}

TEST(ParquetrySeamChoice, StraightensACutThatReadsWorse) {
  TwoCells t = two_cells(kPitch, kPitch - 4);  // the edge on the grid line, the cut off it
  const SeamChoice c = choose_seams(t.seams, t.in, t.wood, t.target, kPxPerMm);
  EXPECT_EQ(c.kept, 0);
  EXPECT_EQ(c.straightened, 1);
  for (int x : t.seams.vertical[1]) EXPECT_EQ(x, kPitch);
}

TEST(ParquetrySeamChoice, LeavesStraightCutsAlone) {
  TwoCells t = two_cells(kPitch + 4, kPitch);
  const SeamChoice c = choose_seams(t.seams, t.in, t.wood, t.target, kPxPerMm);
  EXPECT_EQ(c.kept + c.straightened, 0);
}

}  // namespace
}  // namespace atelier::parquetry

// Parquetry plans on the real wood textures (pychess scans, see tests/data/SOURCES.md):
// every piece on free, usable wood, none sharing wood, the wood shown is the wood cut, and the
// paper's claims (grain beats flat colour, queue order, adaptive splitting) hold.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/parquetry/fabricability.h"
#include "algorithms/parquetry/grid_morph.h"
#include "algorithms/parquetry/plan.h"

namespace atelier::parquetry {
namespace {

// The scans are 160 or 200 px photographs of boards; read at 25.4 dpi (1 px = 1 mm) the
// 12 sheets hold 0.34 m^2 of veneer, enough for the paper's 28x17-patch eye.
constexpr double kWoodDpi = 25.4;

std::vector<Sheet> real_wood(bool with_holes) {
  const std::filesystem::path dir = std::filesystem::path(ATELIER_TEST_DATA) / "wood";
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.path().extension() == ".png") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  std::vector<Sheet> sheets;
  for (const auto& f : files) {
    Sheet s;
    s.id = f.stem().string();
    s.image = cv::imread(f.string(), cv::IMREAD_COLOR);
    s.dpi = kWoodDpi;
    if (with_holes) {
      // A ragged-free frame of 4 mm and a 30 mm screw hole in the middle are not veneer.
      s.usable = cv::Mat::zeros(s.image.size(), CV_8UC1);
      s.usable(cv::Rect(4, 4, s.image.cols - 8, s.image.rows - 8)).setTo(255);
      cv::circle(s.usable, {s.image.cols / 2, s.image.rows / 2}, 15, cv::Scalar(0), cv::FILLED);
    }
    sheets.push_back(s);
  }
  return sheets;
}

cv::Mat photo(const char* name) {
  cv::Mat m = cv::imread(std::string(ATELIER_TEST_DATA) + "/" + name, cv::IMREAD_COLOR);
  if (m.empty()) throw std::runtime_error(std::string("cannot read test image ") + name);
  return m;
}

// Adds 1 to every pixel (at `px_per_mm`) whose centre lies inside polygon `mm`, shrunk by
// `shrink` pixels on every side (the tolerance).
void rasterise(cv::Mat& count, const std::vector<cv::Point2d>& mm, double px_per_mm,
               double shrink) {
  std::vector<cv::Point> pts;
  for (const cv::Point2d& q : mm) {
    const cv::Point2d p = (q * px_per_mm - cv::Point2d(0.5, 0.5)) * 256.0;
    pts.emplace_back(static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)));
  }
  cv::Mat one = cv::Mat::zeros(count.size(), CV_8UC1);
  cv::fillPoly(one, std::vector<std::vector<cv::Point>>{pts}, cv::Scalar(1), cv::LINE_8, 8);
  const int k = static_cast<int>(std::ceil(shrink));
  if (k > 0) cv::erode(one, one, cv::getStructuringElement(cv::MORPH_RECT, {2 * k + 1, 2 * k + 1}));
  cv::Mat one16;
  one.convertTo(one16, CV_16UC1);
  count += one16;
}

const Sheet& sheet_named(const std::vector<Sheet>& sheets, const std::string& id) {
  return *std::find_if(sheets.begin(), sheets.end(), [&](const Sheet& s) { return s.id == id; });
}

// Most pieces sharing any pixel of a sheet, rasterised at 4 px/mm with a 1 px tolerance.
int most_pieces_on_a_pixel(const std::vector<Piece>& pieces, const std::vector<Sheet>& sheets) {
  constexpr double kRes = 4.0;
  std::map<std::string, cv::Mat> count;
  for (const Piece& p : pieces) {
    const Sheet& s = sheet_named(sheets, p.sheet_id);
    cv::Mat& c = count[p.sheet_id];
    if (c.empty()) {
      c = cv::Mat::zeros(cvRound(s.image.rows / s.dpi * 25.4 * kRes),
                         cvRound(s.image.cols / s.dpi * 25.4 * kRes), CV_16UC1);
    }
    rasterise(c, p.source_mm, kRes, 1.0);
  }
  double most = 0;
  for (auto& [id, c] : count) {
    double m = 0;
    cv::minMaxLoc(c, nullptr, &m);
    most = std::max(most, m);
  }
  return static_cast<int>(most);
}

Params small_params() {
  Params p;
  p.size_mm = 98;  // 7 patches on the shorter side: quick, still a picture
  return p;
}

TEST(ParquetryPlan, CoversTheTargetWithPiecesOnFreeUsableWood) {
  const auto sheets = real_wood(true);
  const Plan plan = make_plan(photo("fruits.jpg"), sheets, Stock{}, small_params());
  EXPECT_EQ(plan.grid_rows, 7);
  EXPECT_EQ(plan.grid_cols, 7);  // 512x480: 104.5 mm wide, trimmed to 7 patches
  EXPECT_DOUBLE_EQ(plan.height_mm, 98);
  ASSERT_EQ(plan.pieces.size(), 49u);

  // The target squares tile the result exactly: no overlap, nothing left out.
  double area = 0;
  // fillPoly draws boundary pixels into both neighbours: cover counts whole outlines, inner
  // counts them shrunk by a pixel.
  const cv::Size at4(cvRound(plan.width_mm * 4), cvRound(plan.height_mm * 4));
  cv::Mat cover = cv::Mat::zeros(at4, CV_16UC1), inner = cv::Mat::zeros(at4, CV_16UC1);
  for (const Piece& a : plan.pieces) {
    ASSERT_EQ(a.target_mm.size(), 4u);
    area += std::abs(polygon_area(a.target_mm));
    rasterise(cover, a.target_mm, 4.0, 0.0);
    rasterise(inner, a.target_mm, 4.0, 1.0);
  }
  EXPECT_NEAR(area, plan.width_mm * plan.height_mm, 1e-6);
  double lo = 0, hi = 0;
  cv::minMaxLoc(cover, &lo, nullptr);
  cv::minMaxLoc(inner, nullptr, &hi);
  EXPECT_EQ(lo, 1);
  EXPECT_EQ(hi, 1);

  EXPECT_LE(most_pieces_on_a_pixel(plan.pieces, sheets), 1);

  // Every piece lies on usable veneer (scan pixels, 1 px tolerance) and on the sheet.
  for (const Piece& p : plan.pieces) {
    const Sheet& s = sheet_named(sheets, p.sheet_id);
    cv::Mat on = cv::Mat::zeros(s.image.size(), CV_16UC1);
    rasterise(on, p.source_mm, s.dpi / 25.4, 1.0);
    for (const auto& c : p.source_mm) {
      EXPECT_GE(c.x, 0);
      EXPECT_GE(c.y, 0);
      EXPECT_LE(c.x, s.image.cols / s.dpi * 25.4);
      EXPECT_LE(c.y, s.image.rows / s.dpi * 25.4);
    }
    cv::Mat off_usable = (on > 0) & (s.usable == 0);
    EXPECT_EQ(cv::countNonZero(off_usable), 0) << "piece " << p.id << " on " << p.sheet_id;
  }
}

// At 0.5 px/mm patches (7x7 px) are correlated directly, at 1 px/mm (14x14) through the DFT.
class ParquetryResolution : public ::testing::TestWithParam<double> {};

TEST_P(ParquetryResolution, ThePieceCutIsTheWoodShown) {
  const auto sheets = real_wood(false);
  Params params = small_params();
  params.px_per_mm = GetParam();
  if (params.px_per_mm > 0.5) params.size_mm = 56;  // 4 rows: the DFT path is slower
  const Plan plan = make_plan(photo("butterfly.jpg"), sheets, Stock{}, params);
  EXPECT_LE(most_pieces_on_a_pixel(plan.pieces, sheets), 1);
  int checked = 0;
  for (const Piece& p : plan.pieces) {
    const Sheet& s = sheet_named(sheets, p.sheet_id);
    cv::Mat on = cv::Mat::zeros(s.image.size(), CV_16UC1);
    rasterise(on, p.source_mm, s.dpi / 25.4, 0.0);
    const cv::Scalar cut = cv::mean(s.image, on > 0);
    const double r = params.px_per_mm;  // the reconstruction's pixels per mm
    const cv::Rect shown_at(cv::Point(cvRound(p.target_mm[0].x * r), cvRound(p.target_mm[0].y * r)),
                            cv::Point(cvRound(p.target_mm[2].x * r), cvRound(p.target_mm[2].y * r)));
    const cv::Scalar shown = cv::mean(plan.reconstruction(shown_at));
    // The preview is the scan resampled to 2 mm pixels and turned: means agree to a few levels.
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(cut[ch], shown[ch], 4.0) << "piece " << p.id;
    // The piece's edges keep the patch size, turned by the stated angle.
    EXPECT_NEAR(cv::norm(p.source_mm[1] - p.source_mm[0]), 14.0, 1e-6);
    const cv::Point2d e = p.source_mm[1] - p.source_mm[0];
    double turned = std::atan2(-e.y, e.x) * 180 / CV_PI;  // counter-clockwise, y down
    // A piece laid turned by `rotation_deg` has its top edge horizontal: it was at -rotation.
    EXPECT_NEAR(std::remainder(turned + p.rotation_deg, 360.0), 0.0, 1e-6) << "piece " << p.id;
    ++checked;
  }
  EXPECT_EQ(checked, params.px_per_mm > 0.5 ? 5 * 4 : 9 * 7);  // 493x356 px
}
INSTANTIATE_TEST_SUITE_P(ParquetryCorrelation, ParquetryResolution, ::testing::Values(0.5, 1.0));

// The working resolution is a matter of matching quality only: pieces are the patch_mm the
// user asked for (WoodPixel's 9.144 mm would be 10 mm of 5 px at 0.5 px/mm).
class ParquetryPieceSize : public ::testing::TestWithParam<double> {};

TEST_P(ParquetryPieceSize, PiecesArePatchMmAtAnyResolution) {
  const auto sheets = real_wood(false);
  Params p;
  p.patch_mm = 9.144;
  p.size_mm = 40;  // 4 rows
  p.rotations = 3;
  p.px_per_mm = GetParam();
  const Plan plan = make_plan(photo("butterfly.jpg"), sheets, Stock{}, p);
  EXPECT_EQ(plan.grid_rows, 4);
  EXPECT_NEAR(plan.width_mm, plan.grid_cols * 9.144, 1e-9);
  EXPECT_NEAR(plan.height_mm, 4 * 9.144, 1e-9);
  ASSERT_EQ(plan.pieces.size(), static_cast<std::size_t>(plan.grid_cols * 4));
  for (const Piece& piece : plan.pieces) {
    for (const auto* outline : {&piece.source_mm, &piece.target_mm}) {
      ASSERT_EQ(outline->size(), 4u);
      for (int k = 0; k < 4; ++k) {
        EXPECT_NEAR(cv::norm((*outline)[(k + 1) % 4] - (*outline)[k]), 9.144, 0.01) << "piece " << piece.id;
      }
    }
  }
  // Target and reconstruction are the trimmed result at the working resolution.
  EXPECT_NEAR(plan.target.cols / plan.width_mm, working_px_per_mm(p), 1e-9);
  EXPECT_NEAR(working_px_per_mm(p), p.px_per_mm, 0.5 * p.px_per_mm / patch_px(p) + 1e-12);
}
INSTANTIATE_TEST_SUITE_P(WoodPixelsPatch, ParquetryPieceSize, ::testing::Values(0.5, 0.55, 1.97));

TEST(ParquetryPlan, GrainBeatsTheMeanColourBaselines) {
  const auto sheets = real_wood(false);
  // Defaults: the wood's grain brings the picture closer than the same wood in flat colours
  // (the paper's figure 8 baseline).
  const Plan plan = make_plan(photo("fruits.jpg"), sheets, Stock{}, small_params());
  EXPECT_LT(plan.error, 0.9 * plan.baseline_error);
  // Without the pull towards the wood's gamut (w_hist = 0), it also beats every patch filled
  // with the photo's own mean colour there.
  Params p = small_params();
  p.w_hist = 0;
  const Plan raw = make_plan(photo("fruits.jpg"), sheets, Stock{}, p);
  EXPECT_LT(raw.error, 0.9 * raw.target_mean_error);
  EXPECT_LT(raw.error, raw.baseline_error);
}

TEST(ParquetryPlan, ASecondPlanOnTheStockUsesNoWoodOfTheFirst) {
  const auto sheets = real_wood(false);
  const Plan first = make_plan(photo("fruits.jpg"), sheets, Stock{}, small_params());
  const Stock stock = with_plan(Stock{}, first, "job-1");
  std::size_t recorded = 0;
  for (const auto& [id, used] : stock.used) {
    for (const UsedPiece& u : used) EXPECT_EQ(u.job, "job-1");
    recorded += used.size();
  }
  EXPECT_EQ(recorded, first.pieces.size());
  const Plan second = make_plan(photo("fruits.jpg"), sheets, stock, small_params());
  std::vector<Piece> both = first.pieces;
  both.insert(both.end(), second.pieces.begin(), second.pieces.end());
  EXPECT_LE(most_pieces_on_a_pixel(both, sheets), 1);
  // The same photo twice: the best wood went to the first plan.
  double first_cost = 0, second_cost = 0;
  for (const Piece& p : first.pieces) first_cost += p.cost;
  for (const Piece& p : second.pieces) second_cost += p.cost;
  EXPECT_LT(first_cost, second_cost);
}

TEST(ParquetryPlan, CentreOrderStartsInTheMiddle) {
  Params p = small_params();
  p.order = Order::center;
  const Plan plan = make_plan(photo("HappyFish.jpg"), real_wood(false), Stock{}, p);
  const cv::Point2d middle(plan.width_mm / 2, plan.height_mm / 2);
  double last = 0;
  for (const Piece& piece : plan.pieces) {
    const cv::Point2d c = (piece.target_mm[0] + piece.target_mm[2]) / 2;
    const double d = cv::norm(c - middle);
    EXPECT_GE(d + 1e-9, last) << "piece " << piece.id;
    last = d;
  }
  const cv::Point2d first = (plan.pieces[0].target_mm[0] + plan.pieces[0].target_mm[2]) / 2;
  EXPECT_LT(cv::norm(first - middle), 14.0);
}

TEST(ParquetryPlan, AdaptivePatchesSplitOnlyWhenCheaper) {
  const auto sheets = real_wood(false);
  Params p;
  p.size_mm = 56;  // 4 x 4 patches
  p.adaptive_levels = 2;
  const Plan plan = make_plan(photo("fruits.jpg"), sheets, Stock{}, p);
  // 14 mm patches split into 7 mm quarters (the working resolution is 8/14 px/mm, so a patch
  // is 8 px and its quarters 4 px exactly); those are not split again: theirs would be
  // below 5 mm.
  ASSERT_EQ(plan.splits.size(), 16u);
  int split = 0;
  for (const SplitDecision& d : plan.splits) {
    EXPECT_EQ(d.split, d.quarters_cost < p.adaptive_factor * d.whole_cost);
    split += d.split;
  }
  EXPECT_GT(split, 0);
  EXPECT_EQ(plan.pieces.size(), 16u + 3u * split);
  for (const Piece& piece : plan.pieces) {
    const double edge = cv::norm(piece.source_mm[1] - piece.source_mm[0]);
    if (piece.level == 0) {
      EXPECT_NEAR(edge, 14.0, 1e-6);
    } else {
      EXPECT_NEAR(edge, 7.0, 1e-6);
    }
    EXPECT_LE(piece.level, 1);
  }
  EXPECT_LE(most_pieces_on_a_pixel(plan.pieces, sheets), 1);

  p.adaptive_factor = 0;  // nothing is cheaper than nothing
  const Plan whole = make_plan(photo("fruits.jpg"), sheets, Stock{}, p);
  EXPECT_EQ(whole.pieces.size(), 16u);
  p.adaptive_factor = 1e9;  // always split
  const Plan quarters = make_plan(photo("fruits.jpg"), sheets, Stock{}, p);
  EXPECT_EQ(quarters.pieces.size(), 4u * 16u);
}

TEST(ParquetryPlan, RunningOutOfWoodSaysHowMuchWasNeeded) {
  auto sheets = real_wood(false);
  sheets.resize(1);  // brazilwood_dark: 160 x 160 mm
  Params big = small_params();
  big.size_mm = 238;  // 18 x 17 patches
  try {
    make_plan(photo("fruits.jpg"), sheets, Stock{}, big);
    FAIL() << "expected OutOfWood";
  } catch (const OutOfWood& e) {
    EXPECT_NEAR(e.free_mm2, 160.0 * 160.0, 1.0);
    EXPECT_NEAR(e.needed_mm2, 252.0 * 238.0, 1.0);
    EXPECT_NE(std::string(e.what()).find("out of wood: the plan needs 59976 mm^2 (306 patches "
                                         "of 14 mm) but the sheets have only 25600 mm^2"),
              std::string::npos)
        << e.what();
  }
  // More area than needed, but used up by fragmenting rotations: still a clear error.
  Params p = small_params();
  p.size_mm = 140;
  sheets = real_wood(false);
  sheets.resize(1);
  try {
    make_plan(photo("fruits.jpg"), sheets, Stock{}, p);
    FAIL() << "expected OutOfWood";
  } catch (const OutOfWood& e) {
    EXPECT_NE(std::string(e.what()).find("no free window of 14"), std::string::npos) << e.what();
  }
}

// Smallest distance between the edges of two polygons that do not overlap.
double gap(const std::vector<cv::Point2d>& a, const std::vector<cv::Point2d>& b) {
  auto to_segment = [](cv::Point2d p, cv::Point2d s0, cv::Point2d s1) {
    const cv::Point2d d = s1 - s0;
    const double t = std::clamp((p - s0).dot(d) / std::max(1e-12, d.dot(d)), 0.0, 1.0);
    return cv::norm(p - (s0 + t * d));
  };
  double best = 1e300;
  for (int pass = 0; pass < 2; ++pass) {
    const auto& u = pass ? a : b;
    const auto& v = pass ? b : a;
    for (const cv::Point2d& p : u) {
      for (std::size_t i = 0; i < v.size(); ++i) {
        best = std::min(best, to_segment(p, v[i], v[(i + 1) % v.size()]));
      }
    }
  }
  return best;
}

// Regular squares, and dp pieces whose cuts reach into the wood around their cores.
class ParquetryKerf : public ::testing::TestWithParam<Refine> {};

TEST_P(ParquetryKerf, PiecesOnASheetKeepTheKerfBetweenThem) {
  const auto sheets = real_wood(false);
  Params p = small_params();
  p.kerf_mm = 1.5;
  p.refine = GetParam();
  if (p.refine == Refine::dp) p.px_per_mm = 1.0, p.size_mm = 56;  // room for the cuts to move
  const Plan plan = make_plan(photo("fruits.jpg"), sheets, Stock{}, p);
  int pairs = 0;
  for (const Piece& a : plan.pieces) {
    for (const Piece& b : plan.pieces) {
      if (a.id < b.id && a.sheet_id == b.sheet_id) {
        EXPECT_GE(gap(a.source_mm, b.source_mm), p.kerf_mm - 1e-6) << a.id << " and " << b.id;
        ++pairs;
      }
    }
  }
  EXPECT_GT(pairs, 0);
  // A second plan keeps the kerf from the first one's pieces too.
  const Plan second = make_plan(photo("fruits.jpg"), sheets, with_plan({}, plan, "1"), p);
  for (const Piece& a : plan.pieces) {
    for (const Piece& b : second.pieces) {
      if (a.sheet_id == b.sheet_id) EXPECT_GE(gap(a.source_mm, b.source_mm), p.kerf_mm - 1e-6);
    }
  }
}
INSTANTIATE_TEST_SUITE_P(RegularAndDp, ParquetryKerf, ::testing::Values(Refine::none, Refine::dp));

// refine = dp matches and takes each core as the regular grid does, so it is the regular plan
// with some seams moved: the same wood under every piece, and it never reads worse.
class ParquetryDp : public ::testing::TestWithParam<const char*> {};

TEST_P(ParquetryDp, IsTheRegularPlanWithBetterSeamsOnly) {
  const auto sheets = real_wood(false);
  Params p = small_params();
  p.px_per_mm = 1.0;  // 14 px patches, cuts move up to 2 px
  p.size_mm = 56;
  const Plan regular = make_plan(photo(GetParam()), sheets, Stock{}, p);
  p.refine = Refine::dp;
  const Plan dp = make_plan(photo(GetParam()), sheets, Stock{}, p);
  ASSERT_EQ(dp.pieces.size(), regular.pieces.size());
  for (std::size_t k = 0; k < dp.pieces.size(); ++k) {
    EXPECT_EQ(dp.pieces[k].sheet_id, regular.pieces[k].sheet_id) << "piece " << k + 1;
    EXPECT_EQ(dp.pieces[k].rotation_deg, regular.pieces[k].rotation_deg) << "piece " << k + 1;
    EXPECT_DOUBLE_EQ(dp.pieces[k].cost, regular.pieces[k].cost) << "piece " << k + 1;
  }
  EXPECT_GE(dp.ssim, regular.ssim - 1e-12);
  EXPECT_GT(dp.seams_refined + dp.seams_straightened, 0);  // the DP did move cuts
  if (!dp.curves_cut) {
    EXPECT_EQ(cv::norm(dp.reconstruction, regular.reconstruction, cv::NORM_INF), 0.0);
  }
}
INSTANTIATE_TEST_SUITE_P(Photos, ParquetryDp, ::testing::Values("fruits.jpg", "butterfly.jpg", "HappyFish.jpg"));

// Morphed grids and dp cuts: curved pieces that tile the result, each cuttable, none sharing
// wood, and the wood shown is the wood cut.
class ParquetryShapes : public ::testing::TestWithParam<int> {};

TEST_P(ParquetryShapes, CurvedPiecesTileTheResultAndCanBeCut) {
  const auto sheets = real_wood(false);
  Params p = small_params();
  if (GetParam() == 0) p.grid = Grid::morphed;
  if (GetParam() == 1) p.refine = Refine::dp;
  const Plan plan = make_plan(photo("fruits.jpg"), sheets, Stock{}, p);
  ASSERT_EQ(plan.pieces.size(), 49u);
  double area = 0;
  int curved = 0;
  for (const Piece& piece : plan.pieces) {
    area += std::abs(polygon_area(piece.target_mm));
    curved += piece.target_mm.size() > 4;
    EXPECT_EQ(fabricability_problem(piece.target_mm, kMinPatchMm, p.min_feature_mm), std::nullopt)
        << "piece " << piece.id;
    // The source is the target moved rigidly: same area, same shape.
    EXPECT_NEAR(std::abs(polygon_area(piece.source_mm)), std::abs(polygon_area(piece.target_mm)), 1e-6);
  }
  EXPECT_NEAR(area, plan.width_mm * plan.height_mm, 1e-3 * area);
  EXPECT_GT(curved, 10);  // the shapes really changed
  EXPECT_LE(most_pieces_on_a_pixel(plan.pieces, sheets), 1);
  if (GetParam() == 1) {
    EXPECT_LE(plan.seam_cost_refined, plan.seam_cost_straight);
    EXPECT_LT(plan.seam_cost_refined, plan.seam_cost_straight);  // it found better cuts
  }
  EXPECT_LT(plan.error, plan.baseline_error);
}
INSTANTIATE_TEST_SUITE_P(MorphedAndDp, ParquetryShapes, ::testing::Values(0, 1));

// Mean distance (px of the plan's target) from the edges the morph follows to the nearest cut.
double edges_to_cuts(const Plan& plan, double px_per_mm, double pitch_px) {
  const cv::Mat edges = morph_edges(plan.target, pitch_px);
  cv::Mat cuts(plan.target.size(), CV_8UC1, cv::Scalar(255));
  for (const Piece& piece : plan.pieces) {
    std::vector<cv::Point> pts;  // 4 fractional bits; pixel centres at (x + 0.5, y + 0.5)
    for (const cv::Point2d& q : piece.target_mm) {
      pts.emplace_back(cvRound((q.x * px_per_mm - 0.5) * 16), cvRound((q.y * px_per_mm - 0.5) * 16));
    }
    cv::polylines(cuts, std::vector<std::vector<cv::Point>>{pts}, true, cv::Scalar(0), 1, cv::LINE_8, 4);
  }
  cv::Mat dist;
  cv::distanceTransform(cuts, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  return cv::mean(dist, edges)[0];
}

// Morphed grids of WoodPixel's 9.144 mm pieces on photos whose morph pinched cells below 5 mm
// (fruits at 0.5 px/mm: "piece 47 is 5.0 mm across", HappyFish at 1.97: "piece 82 is
// 4.8 mm across") come out cuttable, and still follow the photo's edges.
class ParquetryMorphedPieces
    : public ::testing::TestWithParam<std::tuple<const char*, double>> {};

TEST_P(ParquetryMorphedPieces, AreCuttableAndFollowTheEdges) {
  auto sheets = real_wood(false);
  sheets.resize(4);  // the shapes depend on the target only
  Params p;
  p.patch_mm = 9.144;
  p.size_mm = 128;  // 14 rows, about 200 pieces
  p.rotations = 1;
  p.px_per_mm = std::get<1>(GetParam());
  p.grid = Grid::morphed;
  const cv::Mat target = photo(std::get<0>(GetParam()));
  const Plan morphed = make_plan(target, sheets, Stock{}, p);  // throws Unfabricable if not
  ASSERT_EQ(morphed.grid_rows, 14);
  for (const Piece& piece : morphed.pieces) {
    EXPECT_EQ(fabricability_problem(piece.target_mm, kMinPatchMm, p.min_feature_mm), std::nullopt)
        << "piece " << piece.id;
  }
  p.grid = Grid::regular;
  const Plan regular = make_plan(target, sheets, Stock{}, p);
  const double r = working_px_per_mm(p);
  // Straightening keeps the morph where it was cuttable: the edges still lie closer to the
  // cuts than on the regular grid (0.71-0.90 of its distance here).
  const double morphed_gap = edges_to_cuts(morphed, r, patch_px(p));
  const double regular_gap = edges_to_cuts(regular, r, patch_px(p));
  EXPECT_LT(morphed_gap, 0.92 * regular_gap) << morphed_gap << " vs " << regular_gap << " px";
}
INSTANTIATE_TEST_SUITE_P(
    WoodPixelsPatch, ParquetryMorphedPieces,
    ::testing::Values(std::make_tuple("fruits.jpg", 0.5), std::make_tuple("fruits.jpg", 1.97),
                      std::make_tuple("HappyFish.jpg", 1.97), std::make_tuple("butterfly.jpg", 0.5)));

TEST(ParquetryPlan, SeveralTargetsPlannedTogetherShareNoWood) {
  const auto sheets = real_wood(false);
  Params p = small_params();
  p.size_mm = 70;
  const std::vector<Plan> plans =
      make_plans({photo("fruits.jpg"), photo("butterfly.jpg")}, sheets, Stock{}, p);
  ASSERT_EQ(plans.size(), 2u);
  std::vector<Piece> both = plans[0].pieces;
  both.insert(both.end(), plans[1].pieces.begin(), plans[1].pieces.end());
  EXPECT_EQ(plans[0].pieces.size(), 5u * 5u);
  EXPECT_EQ(plans[1].pieces.size(), 6u * 5u);  // 493x356: 6 x 5 patches of 14 mm
  EXPECT_LE(most_pieces_on_a_pixel(both, sheets), 1);
  for (const Plan& plan : plans) EXPECT_LT(plan.error, plan.baseline_error);
}

TEST(ParquetryPlan, RejectsBadParametersAndStocks) {
  const auto sheets = real_wood(false);
  Params p = small_params();
  p.patch_mm = 4;
  EXPECT_THROW(make_plan(photo("fruits.jpg"), sheets, Stock{}, p), std::invalid_argument);
  p = small_params();
  p.grid = Grid::morphed;
  p.refine = Refine::dp;  // alternatives, not both
  EXPECT_THROW(make_plan(photo("fruits.jpg"), sheets, Stock{}, p), std::invalid_argument);
  p = small_params();
  p.refine = Refine::dp;
  p.adaptive_levels = 1;
  EXPECT_THROW(make_plan(photo("fruits.jpg"), sheets, Stock{}, p), std::invalid_argument);
  p = small_params();
  p.min_feature_mm = 0;
  EXPECT_THROW(make_plan(photo("fruits.jpg"), sheets, Stock{}, p), std::invalid_argument);
  EXPECT_EQ(order_from_name("center"), Order::center);
  EXPECT_THROW(order_from_name("random"), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::parquetry

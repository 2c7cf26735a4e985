#include "algorithms/parquetry/plan_shapes.h"

#include <cmath>
#include <functional>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "algorithms/parquetry/curved_grid.h"
#include "algorithms/parquetry/cut_refine.h"
#include "algorithms/parquetry/fabricability.h"
#include "algorithms/parquetry/grid_morph.h"
#include "algorithms/parquetry/quality.h"
#include "algorithms/parquetry/seam_choice.h"

namespace atelier::parquetry {

namespace {

std::vector<cv::Point2d> corners(const cv::Rect& r) {
  return {cv::Point2d(r.x, r.y), cv::Point2d(r.x + r.width, r.y),
          cv::Point2d(r.x + r.width, r.y + r.height), cv::Point2d(r.x, r.y + r.height)};
}

// Takes the wood under `polygon` (result px) of a window matched at `m` over `rect`.
void take(WoodIndex& wood, const Match& m, const cv::Rect& rect,
          const std::vector<cv::Point2d>& polygon) {
  const cv::Matx23d to_sheet = wood.window_to_sheet(m);
  std::vector<cv::Point2d> on_sheet;
  for (const cv::Point2d& q : polygon) {
    on_sheet.push_back(transformed(q - cv::Point2d(rect.x, rect.y), to_sheet));
  }
  wood.take(m.sheet, on_sheet);
}

// Regular grid: the patch at `rect`, split in four while that is cheaper (paper 3.3).
// Returns its total cost, or nullopt (nothing placed) when no free wood fits.
std::optional<double> place_square(int cell, cv::Rect rect, int level, const cv::Mat& f1,
                                   const cv::Mat& f2, WoodIndex& wood, const Params& p,
                                   std::vector<Placed>& placed,
                                   std::vector<SplitDecision>& splits) {
  const double r = p.px_per_mm;
  const std::optional<Match> whole = wood.best(f1(rect), f2(rect));
  if (!whole) return std::nullopt;
  const int hw = rect.width / 2, hh = rect.height / 2;
  if (level < p.adaptive_levels && std::min(hw, hh) / r >= kMinPatchMm - 1e-9) {
    const WoodIndex::Snapshot before = wood.save();
    const std::size_t placed_before = placed.size(), splits_before = splits.size();
    const cv::Rect quarters[4] = {{rect.x, rect.y, hw, hh},
                                  {rect.x + hw, rect.y, rect.width - hw, hh},
                                  {rect.x, rect.y + hh, hw, rect.height - hh},
                                  {rect.x + hw, rect.y + hh, rect.width - hw, rect.height - hh}};
    double sum = 0;
    for (const cv::Rect& q : quarters) {
      const std::optional<double> c = place_square(cell, q, level + 1, f1, f2, wood, p, placed, splits);
      if (!c) {
        sum = std::numeric_limits<double>::infinity();
        break;
      }
      sum += *c;
    }
    SplitDecision d{cv::Rect2d(rect.x / r, rect.y / r, rect.width / r, rect.height / r),
                    whole->cost, sum, sum < p.adaptive_factor * whole->cost};
    if (d.split) {
      splits.push_back(d);
      return sum;
    }
    wood.restore(before);
    placed.resize(placed_before);
    splits.resize(splits_before);
    splits.push_back(d);
  }
  take(wood, *whole, rect, corners(rect));
  placed.push_back({cell, rect, *whole, level, polygon_outline(corners(rect))});
  return whole->cost;
}


// Overlap reach of refine = dp beyond a cell's core, in px.
int overlap_half(int patch, const Params& p) {
  return std::max(1, static_cast<int>(std::lround(p.overlap * patch / 2)));
}

// The piece's problem, if any, for an outline in result px: the same check as
// check_fabricable() runs on the piece (its outline in mm, flattened within kFlattenMm).
std::optional<std::string> problem_of(const Outline& outline_px, double r, const Params& p) {
  const Outline mm = transformed(outline_px, cv::Matx23d(1 / r, 0, 0, 0, 1 / r, 0));
  return fabricability_problem(flatten(mm, kFlattenMm), kMinPatchMm, p.min_feature_mm);
}

// Margin of the morph over the smallest piece (mm): the curves through the vertices bow a
// cell's straight edges inwards, and a quad near a triangle has an inscribed circle of about
// 2/3 of its heights, so cells kept exactly at the minimum came out below it.
constexpr double kMorphMarginMm = 0.5;
// Rounds of straightening a morphed grid's uncuttable cells (each halves their corners'
// distance to the regular grid; after 8 they are within 1/256 of it).
constexpr int kStraightenRounds = 8;

// The outlines of the morphed `lines`, with every cell that fails check_fabricable()'s check
// moved back towards the regular grid (its four corners halfway, border vertices along their
// border) until it passes: a plan asked for comes out cuttable, keeping the morph wherever it
// already is. Cells still failing after kStraightenRounds stay (check_fabricable names them).
std::vector<Outline> cuttable_outlines(GridLines lines, double pitch, const Params& p) {
  const int cols = lines.cols, rows = lines.rows;
  std::vector<Outline> outlines = cell_outlines(lines);
  for (int round = 0; round < kStraightenRounds; ++round) {
    std::vector<char> move((cols + 1) * (rows + 1), 0);
    bool any = false;
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        if (!problem_of(outlines[r * cols + c], p.px_per_mm, p)) continue;
        any = true;
        for (int j : {r, r + 1})
          for (int i : {c, c + 1}) move[j * (cols + 1) + i] = 1;
      }
    }
    if (!any) break;
    for (int j = 0; j <= rows; ++j) {
      for (int i = 0; i <= cols; ++i) {
        if (!move[j * (cols + 1) + i]) continue;
        // Vertex (i, j) is point j of vertical line i and point i of horizontal line j.
        const cv::Point2d q = 0.5 * (lines.vertical[i][j] + cv::Point2d(i * pitch, j * pitch));
        lines.vertical[i][j] = lines.horizontal[j][i] = q;
      }
    }
    outlines = cell_outlines(lines);
  }
  return outlines;
}

// The outline (result px) lies within the available pixels of `rect` (their closed squares):
// every pixel whose centre it covers is available, and so is a pixel under every point of
// its boundary (a curve bulging a fraction of a pixel past an edge of the wood fails).
bool inside_available(const Outline& outline_px, const cv::Rect& rect, const cv::Mat& available) {
  // One pixel of border catches the outline leaving the window.
  const cv::Rect grown(rect.x - 1, rect.y - 1, rect.width + 2, rect.height + 2);
  cv::Mat allowed = cv::Mat::zeros(grown.size(), CV_8UC1);
  available.copyTo(allowed(cv::Rect(1, 1, rect.width, rect.height)));
  if (cv::countNonZero(piece_mask(outline_px, grown) & ~allowed) > 0) return false;
  auto ok = [&](cv::Point2d q) {  // some pixel whose closed square holds q is available
    constexpr double eps = 1e-6;
    for (double dx : {-eps, eps}) {
      for (double dy : {-eps, eps}) {
        const int x = static_cast<int>(std::floor(q.x + dx)) - grown.x, y = static_cast<int>(std::floor(q.y + dy)) - grown.y;
        if (x >= 0 && y >= 0 && x < allowed.cols && y < allowed.rows && allowed.at<uchar>(y, x)) return true;
      }
    }
    return false;
  };
  const std::vector<cv::Point2d> poly = flatten(outline_px, 0.02);
  for (std::size_t k = 0; k < poly.size(); ++k) {
    const cv::Point2d a = poly[k], b = poly[(k + 1) % poly.size()];
    const int steps = std::max(1, static_cast<int>(std::ceil(cv::norm(b - a) / 0.05)));
    for (int t = 0; t < steps; ++t) {
      if (!ok(a + (b - a) * (static_cast<double>(t) / steps))) return false;
    }
  }
  return true;
}

// The result painted with every placed cell's wood under `outlines` (per placed).
cv::Mat paint(const std::vector<Placed>& placed, const std::vector<Outline>& outlines,
              const WoodIndex& wood, cv::Size size) {
  cv::Mat out = cv::Mat::zeros(size, CV_8UC3);
  for (std::size_t k = 0; k < placed.size(); ++k) {
    const cv::Rect& rect = placed[k].rect;
    wood.colour(placed[k].match).copyTo(out(rect), piece_mask(outlines[k], rect));
  }
  return out;
}

// The outlines of the dp cells under `seams`, every cell that comes out unfabricable, or
// whose smoothed outline strays off the wood available to it, given straight cuts around it
// (its core: always fabricable and its own), for a few rounds that settle the neighbours.
// False if some cell still fails.
bool cuttable_seam_outlines(Seams& seams, const Shapes& shapes, const std::vector<cv::Mat>& available,
                            const Params& p, std::vector<Outline>& outlines) {
  const double knot = std::max(2.0, shapes.patch / 3.0);
  const int W = shapes.cols * shapes.patch, H = shapes.rows * shapes.patch;
  bool cuttable = false;
  for (int round = 0; round <= kStraightenRounds && !cuttable; ++round) {
    outlines = cell_outlines(seam_lines(seams, shapes.cols, shapes.rows, shapes.patch, knot));
    cuttable = true;
    for (int r = 0; r < shapes.rows; ++r) {
      for (int c = 0; c < shapes.cols; ++c) {
        const int cell = r * shapes.cols + c;
        if (!problem_of(outlines[cell], p.px_per_mm, p) &&
            inside_available(outlines[cell], shapes.rects[cell], available[cell])) {
          continue;
        }
        cuttable = false;
        // One row / column beyond the overlaps (seam_lines keeps a cut straight there too,
        // where the crossing cut may bend), and further each round: the smoothing carries a
        // neighbouring bend into the straightened part.
        // Whole held runs only (refine_seams holds vertical cuts over each horizontal band
        // and the row either side), so no cut bends inside one.
        const int reach = shapes.half + 1 + round * shapes.patch;
        const int y0 = std::max(0, r * shapes.patch - reach);
        const int y1 = std::min(H, (r + 1) * shapes.patch + reach);
        const int x0 = std::max(0, c * shapes.patch - reach);
        const int x1 = std::min(W, (c + 1) * shapes.patch + reach);
        for (int i : {c, c + 1}) {
          if (i == 0 || i == shapes.cols) continue;
          for (int y = y0; y < y1; ++y) seams.vertical[i][y] = i * shapes.patch;
        }
        for (int j : {r, r + 1}) {
          if (j == 0 || j == shapes.rows) continue;
          for (int x = x0; x < x1; ++x) seams.horizontal[j][x] = j * shapes.patch;
        }
      }
    }
  }
  return cuttable;
}

}  // namespace

cv::Mat piece_mask(const Outline& outline_px, const cv::Rect& rect) {
  constexpr int kShift = 8;
  std::vector<cv::Point> poly;
  std::vector<cv::Point2f> local;
  for (const cv::Point2d& q : flatten(outline_px, 0.05)) {
    poly.emplace_back(static_cast<int>(std::lround((q.x - rect.x - 0.5) * (1 << kShift))),
                      static_cast<int>(std::lround((q.y - rect.y - 0.5) * (1 << kShift))));
    local.emplace_back(static_cast<float>(q.x - rect.x), static_cast<float>(q.y - rect.y));
  }
  cv::Mat mask = cv::Mat::zeros(rect.size(), CV_8UC1);
  cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{poly}, cv::Scalar(255), cv::LINE_8, kShift);
  // fillPoly also takes the pixels a boundary touches (both neighbours of a seam get them);
  // keep those whose centre is inside, so neighbouring pieces share no pixel.
  for (int y = 0; y < mask.rows; ++y) {
    uchar* m = mask.ptr<uchar>(y);
    for (int x = 0; x < mask.cols; ++x) {
      if (m[x] && cv::pointPolygonTest(local, cv::Point2f(x + 0.5f, y + 0.5f), false) <= 0) m[x] = 0;
    }
  }
  return mask;
}

Shapes make_shapes(const cv::Mat& target, int cols, int rows, int patch, const Params& p) {
  Shapes s;
  s.grid = p.grid;
  s.refine = p.refine;
  s.cols = cols;
  s.rows = rows;
  s.patch = patch;
  const cv::Rect all(0, 0, cols * patch, rows * patch);
  if (p.grid == Grid::morphed) {
    // Cells keep at least half a patch (and 5 mm) across, so they stay easy to cut and lay.
    const double min_edge_mm = std::min(p.patch_mm, std::max(kMinPatchMm, p.patch_mm / 2) + kMorphMarginMm);
    const GridLines lines = morph_grid(target, cols, rows, patch, min_edge_mm * p.px_per_mm);
    s.outlines = cuttable_outlines(lines, patch, p);
    for (const Outline& o : s.outlines) {
      const std::vector<cv::Point2d> poly = flatten(o, 0.05);
      double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
      for (const cv::Point2d& q : poly) {
        x0 = std::min(x0, q.x), y0 = std::min(y0, q.y), x1 = std::max(x1, q.x), y1 = std::max(y1, q.y);
      }
      const cv::Rect rect = cv::Rect(cv::Point(static_cast<int>(std::floor(x0)), static_cast<int>(std::floor(y0))),
                                     cv::Point(static_cast<int>(std::ceil(x1)), static_cast<int>(std::ceil(y1)))) & all;
      const cv::Mat mask = piece_mask(o, rect);
      s.rects.push_back(rect);
      s.masks.push_back(mask);
      s.wood_px += cv::countNonZero(mask);
    }
    return s;
  }
  if (p.refine == Refine::dp) s.half = overlap_half(patch, p);
  SeamInput grid;
  grid.cols = cols, grid.rows = rows, grid.pitch = patch, grid.half = s.half;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const cv::Rect core(c * patch, r * patch, patch, patch);
      const cv::Rect rect = p.refine == Refine::dp ? cell_window(grid, c, r) : core;
      s.rects.push_back(rect);
      s.outlines.push_back(polygon_outline(corners(core)));
      s.wood_px += core.area();
    }
  }
  return s;
}

cv::Rect cell_core(const Shapes& shapes, int cell) {
  return {(cell % shapes.cols) * shapes.patch, (cell / shapes.cols) * shapes.patch, shapes.patch,
          shapes.patch};
}

bool place_cell(const Shapes& shapes, int cell, const cv::Mat& f1, const cv::Mat& f2,
                WoodIndex& wood, const Params& p, std::vector<Placed>& placed,
                std::vector<SplitDecision>& splits) {
  if (shapes.grid == Grid::regular && shapes.refine == Refine::none) {
    return place_square(cell, shapes.rects[cell], 0, f1, f2, wood, p, placed, splits).has_value();
  }
  const cv::Rect& rect = shapes.rects[cell];
  if (shapes.refine == Refine::dp) {
    // The core is matched and taken as on the regular grid (same wood, same plan when every
    // cut stays straight); the match is then widened to the cell's window, whose overlap
    // the cuts may use where no other piece needs the wood (dp_wood.h).
    const cv::Rect core = cell_core(shapes, cell);
    std::optional<Match> m = wood.best(f1(core), f2(core));
    if (!m) return false;
    take(wood, *m, core, corners(core));
    m->pos -= core.tl() - rect.tl();
    m->size = rect.size();
    placed.push_back({cell, rect, *m, 0, shapes.outlines[cell], core});
    return true;
  }
  const cv::Mat mask = shapes.masks.empty() ? cv::Mat() : shapes.masks[cell];
  const std::optional<Match> m = wood.best(f1(rect), f2(rect), mask);
  if (!m) return false;
  take(wood, *m, rect, flatten(shapes.outlines[cell], 0.05));  // a morphed cell's own shape
  placed.push_back({cell, rect, *m, 0, shapes.outlines[cell], {}});
  return true;
}

SeamCosts final_outlines(const Shapes& shapes, const cv::Mat& target, const cv::Mat& f1,
                         const cv::Mat& f2, const WoodIndex& wood,
                         const std::vector<cv::Mat>& available, const Params& p,
                         std::vector<Placed>& placed) {
  if (shapes.refine != Refine::dp) return {};
  SeamInput in;
  in.cols = shapes.cols, in.rows = shapes.rows, in.pitch = shapes.patch, in.half = shapes.half;
  in.target_f1 = f1;
  in.target_f2 = f2;
  const std::size_t n = static_cast<std::size_t>(shapes.cols) * shapes.rows;
  in.wood_f1.resize(n);
  in.wood_f2.resize(n);
  in.available.resize(n);
  std::vector<cv::Mat> wood_bgr(n);
  for (std::size_t k = 0; k < placed.size(); ++k) {
    const auto [a, b] = wood.features(placed[k].match);
    in.wood_f1[placed[k].cell] = a;
    in.wood_f2[placed[k].cell] = b;
    in.available[placed[k].cell] = available[k];
    wood_bgr[placed[k].cell] = wood.colour(placed[k].match);
  }
  Seams seams = refine_seams(in, 2);
  SeamCosts costs{seams.straight_cost, seams.refined_cost};
  const SeamChoice choice = choose_seams(seams, in, wood_bgr, target, p.px_per_mm);
  costs.seams_refined = choice.kept;
  costs.seams_straightened = choice.straightened;
  std::vector<Outline> outlines;
  const bool cuttable = cuttable_seam_outlines(seams, shapes, in.available, p, outlines);
  // The smoothed curves are what is cut: if, after all, they read worse than the straight
  // grid (the regular plan), or some cell still could not be cut, cut straight.
  std::vector<Outline> refined(placed.size()), straight(placed.size());
  for (std::size_t k = 0; k < placed.size(); ++k) {
    refined[k] = outlines[placed[k].cell];
    straight[k] = shapes.outlines[placed[k].cell];
  }
  const double r = p.px_per_mm;
  costs.curves_cut = cuttable && blurred_ssim(paint(placed, refined, wood, target.size()), target, r) >=
                       blurred_ssim(paint(placed, straight, wood, target.size()), target, r);
  for (std::size_t k = 0; k < placed.size(); ++k) {
    placed[k].outline_px = costs.curves_cut ? refined[k] : straight[k];
  }
  return costs;
}

void check_fabricable(const Plan& plan, const Shapes& shapes, const Params& p) {
  // Squares of the regular grid are at least 5 mm by validate() and the adaptive split rule.
  if (shapes.grid == Grid::regular && shapes.refine == Refine::none) return;
  for (const Piece& piece : plan.pieces) {
    if (auto problem = fabricability_problem(piece.target_mm, kMinPatchMm, p.min_feature_mm)) {
      throw Unfabricable("parquetry: piece " + std::to_string(piece.id) + " " + *problem +
                         "; try a larger patch_mm or grid = \"regular\"");
    }
  }
}

}  // namespace atelier::parquetry

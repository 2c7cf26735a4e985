#include "algorithms/parquetry/plan.h"

#include <cmath>
#include <functional>
#include <iomanip>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>

#include "algorithms/parquetry/features.h"
#include "algorithms/parquetry/order.h"
#include "algorithms/parquetry/wood_index.h"

namespace atelier::parquetry {

namespace {

std::string mm2(double v) { return std::to_string(std::lround(v)) + " mm^2"; }

std::string mm(double v) {
  std::ostringstream out;
  out << std::setprecision(4) << v << " mm";
  return out.str();
}

cv::Mat to_bgr(const cv::Mat& image) {
  cv::Mat out;
  switch (image.type()) {
    case CV_8UC3: return image;
    case CV_8UC1: cv::cvtColor(image, out, cv::COLOR_GRAY2BGR); return out;
    case CV_8UC4: cv::cvtColor(image, out, cv::COLOR_BGRA2BGR); return out;
    default: throw std::invalid_argument("parquetry: the target must be 8-bit grey, BGR or BGRA");
  }
}

// Mean squared grey-level difference.
double mse(const cv::Mat& a_bgr, const cv::Mat& b_bgr) {
  cv::Mat a, b, d;
  to_gray(a_bgr).convertTo(a, CV_32F);
  to_gray(b_bgr).convertTo(b, CV_32F);
  cv::subtract(a, b, d);
  return d.dot(d) / static_cast<double>(d.total());
}

struct Placed {
  cv::Rect target;  // working pixels of the result
  Match match;
  int level = 0;
};

}  // namespace

Plan make_plan(const cv::Mat& target_in, const std::vector<Sheet>& sheets, const Stock& stock,
               const Params& p) {
  validate(p);
  validate_sheets(sheets);
  if (target_in.empty()) throw std::invalid_argument("parquetry: the target image is empty");
  if (sheets.empty()) throw std::invalid_argument("parquetry: no wood sheets");
  if (!stock.used.empty() && std::abs(stock.px_per_mm - p.px_per_mm) > 1e-9) {
    throw std::invalid_argument("parquetry: the stock is at " + std::to_string(stock.px_per_mm) +
                                " px/mm but the plan works at " + std::to_string(p.px_per_mm));
  }
  const double r = p.px_per_mm;
  const int patch = static_cast<int>(std::lround(p.patch_mm * r));

  // The result: shorter side size_mm, trimmed (centred) to whole patches.
  const cv::Mat bgr = to_bgr(target_in);
  const double scale = p.size_mm * r / std::min(bgr.cols, bgr.rows);
  const cv::Size scaled(std::max(1, static_cast<int>(std::lround(bgr.cols * scale))),
                        std::max(1, static_cast<int>(std::lround(bgr.rows * scale))));
  cv::Mat resized;
  cv::resize(bgr, resized, scaled, 0, 0, scale < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
  Plan plan;
  plan.grid_cols = resized.cols / patch;
  plan.grid_rows = resized.rows / patch;
  const cv::Rect crop((resized.cols - plan.grid_cols * patch) / 2,
                      (resized.rows - plan.grid_rows * patch) / 2, plan.grid_cols * patch,
                      plan.grid_rows * patch);
  plan.target = resized(crop).clone();
  plan.width_mm = crop.width / r;
  plan.height_mm = crop.height / r;

  WoodIndex wood(sheets, stock, r, p.rotations, p.w_intens, p.w_edge);
  const double needed_mm2 = plan.width_mm * plan.height_mm;
  const double free_mm2 = wood.free_px() / (r * r);
  const std::string need = "the plan needs " + mm2(needed_mm2) + " (" +
                           std::to_string(plan.grid_cols) + "x" + std::to_string(plan.grid_rows) +
                           " patches of " + mm(patch / r) + ")";
  if (needed_mm2 > free_mm2) {
    throw OutOfWood("parquetry: out of wood: " + need + " but the sheets have only " +
                        mm2(free_mm2) + " of free wood",
                    needed_mm2, free_mm2);
  }

  // Eq. 1-2 for the target: histogram-matched intensity, and its edges.
  const cv::Mat gray = to_gray(plan.target);
  std::array<double, 256> target_hist{};
  add_histogram(target_hist, gray, cv::Mat());
  const cv::Mat intens = apply_lut(gray, matching_lut(target_hist, wood.free_histogram(), p.w_hist));
  const cv::Mat f1 = intens * p.w_intens;
  const cv::Mat f2 = edge(intens) * p.w_edge;

  std::vector<Placed> placed;
  // Places the patch at `rect`, split in four while that is cheaper (paper 3.3). Returns its
  // total cost, or nullopt (nothing placed) when no free wood fits.
  std::function<std::optional<double>(cv::Rect, int)> place = [&](cv::Rect rect, int level)
      -> std::optional<double> {
    const std::optional<Match> whole = wood.best(f1(rect), f2(rect));
    if (!whole) return std::nullopt;
    const int hw = rect.width / 2, hh = rect.height / 2;
    if (level < p.adaptive_levels && std::min(hw, hh) / r >= kMinPatchMm - 1e-9) {
      const WoodIndex::Snapshot before = wood.save();
      const std::size_t placed_before = placed.size(), splits_before = plan.splits.size();
      const cv::Rect quarters[4] = {{rect.x, rect.y, hw, hh},
                                    {rect.x + hw, rect.y, rect.width - hw, hh},
                                    {rect.x, rect.y + hh, hw, rect.height - hh},
                                    {rect.x + hw, rect.y + hh, rect.width - hw, rect.height - hh}};
      double sum = 0;
      for (const cv::Rect& q : quarters) {
        const std::optional<double> c = place(q, level + 1);
        if (!c) {
          sum = std::numeric_limits<double>::infinity();
          break;
        }
        sum += *c;
      }
      SplitDecision d{cv::Rect2d(rect.x / r, rect.y / r, rect.width / r, rect.height / r),
                      whole->cost, sum, sum < p.adaptive_factor * whole->cost};
      if (d.split) {
        plan.splits.push_back(d);
        return sum;
      }
      wood.restore(before);
      placed.resize(placed_before);
      plan.splits.resize(splits_before);
      plan.splits.push_back(d);
    }
    wood.take(*whole);
    placed.push_back({rect, *whole, level});
    return whole->cost;
  };

  const std::vector<int> order =
      patch_order(plan.target, plan.grid_cols, plan.grid_rows, patch, p.order, p.seed);
  for (std::size_t i = 0; i < order.size(); ++i) {
    const cv::Rect rect((order[i] % plan.grid_cols) * patch, (order[i] / plan.grid_cols) * patch,
                        patch, patch);
    if (!place(rect, 0)) {
      throw OutOfWood("parquetry: out of wood: " + need + " and the sheets had " +
                          mm2(free_mm2) + " free, but after " + std::to_string(i) + " of " +
                          std::to_string(order.size()) + " patches no free window of " +
                          std::to_string(patch / r) + " mm was left in any sheet and rotation (" +
                          mm2(wood.free_px() / (r * r)) + " free in pieces too small)",
                      needed_mm2, free_mm2);
    }
  }

  plan.reconstruction = cv::Mat::zeros(plan.target.size(), CV_8UC3);
  cv::Mat baseline = cv::Mat::zeros(plan.target.size(), CV_8UC3);
  cv::Mat flat = cv::Mat::zeros(plan.target.size(), CV_8UC3);
  for (std::size_t i = 0; i < placed.size(); ++i) {
    const Placed& pl = placed[i];
    Piece piece;
    piece.id = static_cast<int>(i) + 1;
    piece.sheet_id = sheets[pl.match.sheet].id;
    piece.rotation_deg = pl.match.angle_deg;
    const auto src = wood.corners_in_sheet(pl.match);
    const cv::Rect& t = pl.target;
    const std::array<cv::Point2d, 4> dst = {
        cv::Point2d(t.x, t.y), cv::Point2d(t.x + t.width, t.y),
        cv::Point2d(t.x + t.width, t.y + t.height), cv::Point2d(t.x, t.y + t.height)};
    for (int k = 0; k < 4; ++k) {
      piece.source_mm[k] = src[k] / r;
      piece.target_mm[k] = dst[k] / r;
    }
    piece.cost = pl.match.cost;
    piece.level = pl.level;
    plan.pieces.push_back(piece);
    wood.colour(pl.match).copyTo(plan.reconstruction(t));
    baseline(t).setTo(cv::mean(plan.target(t)));
    flat(t).setTo(cv::mean(plan.reconstruction(t)));
  }
  plan.error = mse(plan.reconstruction, plan.target);
  plan.baseline_error = mse(baseline, plan.target);
  plan.wood_mean_error = mse(flat, plan.target);

  plan.stock = stock;
  plan.stock.px_per_mm = r;
  for (auto& [id, mask] : wood.stock(sheets).used) plan.stock.used[id] = mask;
  return plan;
}

}  // namespace atelier::parquetry

#include "algorithms/parquetry/plan.h"

#include <cmath>
#include <functional>
#include <iomanip>
#include <limits>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <random>
#include <sstream>

#include "algorithms/parquetry/dp_wood.h"
#include "algorithms/parquetry/features.h"
#include "algorithms/parquetry/order.h"
#include "algorithms/parquetry/plan_shapes.h"
#include "algorithms/parquetry/quality.h"
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

cv::Matx23d compose(const cv::Matx23d& a, const cv::Matx23d& b) {  // a after b
  const cv::Matx33d A(a(0, 0), a(0, 1), a(0, 2), a(1, 0), a(1, 1), a(1, 2), 0, 0, 1);
  const cv::Matx33d B(b(0, 0), b(0, 1), b(0, 2), b(1, 0), b(1, 1), b(1, 2), 0, 0, 1);
  const cv::Matx33d C = A * B;
  return cv::Matx23d(C(0, 0), C(0, 1), C(0, 2), C(1, 0), C(1, 1), C(1, 2));
}

// One target being planned.
struct Job {
  Plan plan;
  int patch = 0;     // px
  cv::Mat f1, f2;    // weighted target features (eq. 1-2)
  Shapes shapes;     // the cells before matching
  std::vector<Placed> placed;
};

void prepare(Job& job, const cv::Mat& target_in, const Params& p) {
  const double r = p.px_per_mm;
  job.patch = patch_px(p);
  const cv::Mat bgr = to_bgr(target_in);
  const double scale = p.size_mm * r / std::min(bgr.cols, bgr.rows);
  const cv::Size scaled(std::max(1, static_cast<int>(std::lround(bgr.cols * scale))),
                        std::max(1, static_cast<int>(std::lround(bgr.rows * scale))));
  cv::Mat resized;
  cv::resize(bgr, resized, scaled, 0, 0, scale < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
  Plan& plan = job.plan;
  plan.grid = p.grid;
  plan.refine = p.refine;
  plan.grid_cols = resized.cols / job.patch;
  plan.grid_rows = resized.rows / job.patch;
  const cv::Rect crop((resized.cols - plan.grid_cols * job.patch) / 2,
                      (resized.rows - plan.grid_rows * job.patch) / 2,
                      plan.grid_cols * job.patch, plan.grid_rows * job.patch);
  plan.target = resized(crop).clone();
  plan.width_mm = crop.width / r;
  plan.height_mm = crop.height / r;
}

// Builds the pieces from the placed cells, the reconstruction and the error figures.
void finish(Job& job, const WoodIndex& wood, const std::vector<Sheet>& sheets, double r) {
  Plan& plan = job.plan;
  plan.reconstruction = cv::Mat::zeros(plan.target.size(), CV_8UC3);
  cv::Mat baseline = cv::Mat::zeros(plan.target.size(), CV_8UC3);
  cv::Mat flat_target = cv::Mat::zeros(plan.target.size(), CV_8UC3);
  const cv::Matx23d px_to_mm(1 / r, 0, 0, 0, 1 / r, 0), mm_to_px(r, 0, 0, 0, r, 0);
  for (std::size_t i = 0; i < job.placed.size(); ++i) {
    const Placed& pl = job.placed[i];
    Piece piece;
    piece.id = static_cast<int>(i) + 1;
    piece.sheet_id = sheets[pl.match.sheet].id;
    piece.rotation_deg = pl.match.angle_deg;
    piece.target = transformed(pl.outline_px, px_to_mm);
    const cv::Matx23d result_to_window(1, 0, -pl.rect.x, 0, 1, -pl.rect.y);
    piece.to_sheet = compose(px_to_mm, compose(wood.window_to_sheet(pl.match),
                                               compose(result_to_window, mm_to_px)));
    piece.source = transformed(piece.target, piece.to_sheet);
    piece.target_mm = flatten(piece.target, kFlattenMm);
    piece.source_mm = flatten(piece.source, kFlattenMm);
    piece.cost = pl.match.cost;
    piece.level = pl.level;

    // The piece's pixels: centres inside its outline (within its window).
    cv::Mat inside = cv::Mat::zeros(plan.target.size(), CV_8UC1);
    piece_mask(pl.outline_px, pl.rect).copyTo(inside(pl.rect));
    const cv::Mat colour = wood.colour(pl.match);
    colour.copyTo(plan.reconstruction(pl.rect), inside(pl.rect));
    if (cv::countNonZero(inside) > 0) {
      baseline.setTo(cv::mean(plan.reconstruction, inside), inside);
      flat_target.setTo(cv::mean(plan.target, inside), inside);
    }
    plan.pieces.push_back(std::move(piece));
  }
  plan.error = mse(plan.reconstruction, plan.target);
  plan.baseline_error = mse(baseline, plan.target);
  plan.target_mean_error = mse(flat_target, plan.target);
  plan.ssim = blurred_ssim(plan.reconstruction, plan.target, r);
}

}  // namespace

std::vector<Plan> make_plans(const std::vector<cv::Mat>& targets,
                             const std::vector<Sheet>& sheets, const Stock& stock,
                             const Params& params) {
  validate(params);
  // Everything below works at the resolution where a patch is whole pixels, so pieces come
  // out patch_mm exactly.
  Params p = params;
  p.px_per_mm = working_px_per_mm(params);
  validate_sheets(sheets);
  if (targets.empty()) throw std::invalid_argument("parquetry: no target image");
  for (const cv::Mat& t : targets) {
    if (t.empty()) throw std::invalid_argument("parquetry: the target image is empty");
  }
  if (sheets.empty()) throw std::invalid_argument("parquetry: no wood sheets");
  const double r = p.px_per_mm;

  std::vector<Job> jobs(targets.size());
  for (std::size_t t = 0; t < targets.size(); ++t) prepare(jobs[t], targets[t], p);

  WoodIndex wood(sheets, stock, r, p.rotations, p.w_intens, p.w_edge, p.kerf_mm);
  double needed_mm2 = 0;
  int cells = 0;
  for (Job& job : jobs) {
    job.shapes = make_shapes(job.plan.target, job.plan.grid_cols, job.plan.grid_rows, job.patch, p);
    needed_mm2 += job.shapes.wood_px / (r * r);
    cells += job.plan.grid_cols * job.plan.grid_rows;
  }
  const double free_mm2 = wood.free_px() / (r * r);
  const int patch = jobs.front().patch;
  const std::string need = "the plan needs " + mm2(needed_mm2) + " (" + std::to_string(cells) +
                           " patches of " + mm(patch / r) + ")";
  if (needed_mm2 > free_mm2) {
    throw OutOfWood("parquetry: out of wood: " + need + " but the sheets have only " +
                        mm2(free_mm2) + " of free wood",
                    needed_mm2, free_mm2);
  }

  // Eq. 1-2 per target: histogram-matched intensity (to the free wood), and its edges.
  for (Job& job : jobs) {
    const cv::Mat gray = to_gray(job.plan.target);
    std::array<double, 256> target_hist{};
    add_histogram(target_hist, gray, cv::Mat());
    const cv::Mat intens =
        apply_lut(gray, matching_lut(target_hist, wood.free_histogram(), p.w_hist));
    job.f1 = intens * p.w_intens;
    job.f2 = edge(intens) * p.w_edge;
  }

  // One priority queue over the cells of every target (paper 3.3 and 4.2).
  struct Entry {
    int job, cell;
    double priority;
  };
  std::vector<Entry> queue;
  for (std::size_t t = 0; t < jobs.size(); ++t) {
    const Job& job = jobs[t];
    const std::vector<double> pr = patch_priority(job.plan.target, job.plan.grid_cols,
                                                  job.plan.grid_rows, job.patch, p.order);
    for (std::size_t c = 0; c < pr.size(); ++c) {
      queue.push_back({static_cast<int>(t), static_cast<int>(c), pr[c]});
    }
  }
  std::mt19937_64 rng(p.seed);
  std::shuffle(queue.begin(), queue.end(), rng);
  std::stable_sort(queue.begin(), queue.end(),
                   [](const Entry& a, const Entry& b) { return a.priority < b.priority; });

  for (std::size_t i = 0; i < queue.size(); ++i) {
    Job& job = jobs[queue[i].job];
    if (!place_cell(job.shapes, queue[i].cell, job.f1, job.f2, wood, p, job.placed,
                    job.plan.splits)) {
      throw OutOfWood("parquetry: out of wood: " + need + " and the sheets had " +
                          mm2(free_mm2) + " free, but after " + std::to_string(i) + " of " +
                          std::to_string(queue.size()) + " patches no free window of " +
                          mm(patch / r) + " was left in any sheet and rotation (" +
                          mm2(wood.free_px() / (r * r)) + " free in pieces too small)",
                      needed_mm2, free_mm2);
    }
  }

  // refine = dp: the wood each cell's cuts may use, among the pieces of every target.
  std::vector<const Placed*> all;
  for (const Job& job : jobs) {
    for (const Placed& pl : job.placed) all.push_back(&pl);
  }
  const std::vector<cv::Mat> available =
      p.refine == Refine::dp ? available_wood(all, sheets, stock, wood, r, p.kerf_mm) : std::vector<cv::Mat>();
  auto next = available.begin();

  std::vector<Plan> plans;
  for (Job& job : jobs) {
    std::vector<cv::Mat> mine;  // this target's cells' (none unless dp)
    if (!available.empty()) {
      mine.assign(next, next + static_cast<std::ptrdiff_t>(job.placed.size()));
      next += static_cast<std::ptrdiff_t>(job.placed.size());
    }
    const SeamCosts seams = final_outlines(job.shapes, job.plan.target, job.f1, job.f2, wood, mine, p, job.placed);
    job.plan.seam_cost_straight = seams.straight;
    job.plan.seam_cost_refined = seams.refined;
    job.plan.seams_refined = seams.seams_refined;
    job.plan.seams_straightened = seams.seams_straightened;
    job.plan.curves_cut = seams.curves_cut;
    finish(job, wood, sheets, r);
    check_fabricable(job.plan, job.shapes, p);
    plans.push_back(std::move(job.plan));
  }
  return plans;
}

Plan make_plan(const cv::Mat& target, const std::vector<Sheet>& sheets, const Stock& stock,
               const Params& params) {
  return std::move(make_plans({target}, sheets, stock, params).front());
}

Stock with_plan(Stock stock, const Plan& plan, const std::string& job) {
  for (const Piece& piece : plan.pieces) {
    stock.used[piece.sheet_id].push_back({job, piece.id, piece.source_mm});
  }
  return stock;
}

}  // namespace atelier::parquetry

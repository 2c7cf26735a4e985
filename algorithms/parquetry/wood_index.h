// The wood side of matching (paper eq. 3-4): `rotations` rotated copies of every sheet's
// features, colour and free-wood mask, searched for the window with the smallest sum of
// squared feature differences to a target patch among windows lying wholly on free wood.
//
// How it is fast. SSD = sum(window^2) - 2 correlation + sum(patch^2), window sums from
// integral images. The correlation is direct (SIMD cv::filter2D) for patches up to 64 px and
// otherwise in the frequency domain: each copy keeps the spectra of its two feature maps
// (computed once), so a patch costs per copy two spectrum products and one inverse DFT (only
// the rows holding window positions). Used wood is rasterised into every rotated mask when a
// piece is taken; an integral image of each mask rejects windows touching used or unusable
// wood in O(1), cached per window size until the sheet changes. Masked patches (cells that
// are not rectangles) are correlated directly, three correlations per copy, pruned by the bound of a rectangle
// inside the mask. The per-window-size maps (free windows, window sums) are kept for the
// kCachedSizes most recently used sizes only, so memory does not grow with the number of
// cell shapes (a morphed grid has about a hundred). An exact lower bound per copy,
// (sum of differences)^2 / n per feature over its free windows, orders the copies and skips
// those that cannot beat the best found so far (about 70% of them). Copies are searched in
// parallel batches (cv::parallel_for_).
//
// Frames. Rotated copy k of a sheet shows the sheet turned by k * 360 / n degrees
// counter-clockwise (y down) on a canvas just holding it; copy 0 is the sheet itself. A taken
// piece is grown by the kerf and half a pixel diagonal in every copy, so every pixel within the
// kerf of it is used.
//
// Not thread-safe: one plan owns one WoodIndex.
#pragma once

#include <array>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "algorithms/parquetry/sheet.h"

namespace atelier::parquetry {

struct Match {
  int copy = -1;       // index into the rotated copies
  int sheet = -1;      // index into the sheets
  double angle_deg = 0;
  cv::Point pos;       // window's top-left in the copy's pixels
  cv::Size size;       // window size in pixels
  double cost = 0;
};

class WoodIndex {
 public:
  // `sheets` validated by the caller; used wood is the stock's pieces grown by kerf_mm.
  WoodIndex(const std::vector<Sheet>& sheets, const Stock& stock, double px_per_mm,
            int rotations, double w_intens, double w_edge, double kerf_mm);
  ~WoodIndex();

  // Histogram of the free wood's grey levels (for eq. 2).
  const std::array<double, 256>& free_histogram() const { return free_hist_; }

  // Best free window for weighted features f1, f2 (CV_32F, same size); nullopt when no window
  // of that size is free anywhere. `mask` (CV_8UC1 of that size, may be empty = all): eq. 4
  // sums only over its non-zero pixels (the window must still be wholly free).
  std::optional<Match> best(const cv::Mat& f1, const cv::Mat& f2, const cv::Mat& mask = {});

  // Marks `polygon` (sheet pixels at the working resolution, closed) used, grown by the kerf,
  // in every copy of `sheet` and in its used mask.
  void take(int sheet, const std::vector<cv::Point2d>& polygon);

  // Window pixels of `m` (its copy, origin at the window's top-left) -> sheet pixels.
  cv::Matx23d window_to_sheet(const Match& m) const;

  // Weighted wood features (CV_32F f1, f2) under the window of `m`; 0 where the window
  // leaves its copy (a dp window grown around a matched core may).
  std::pair<cv::Mat, cv::Mat> features(const Match& m) const;

  // Wood colour (CV_8UC3) under the window of `m`; black where it leaves its copy.
  cv::Mat colour(const Match& m) const;


  // Saved masks, to undo tentative takes (adaptive splitting).
  struct Snapshot {
    std::vector<cv::Mat> bad;
    std::vector<cv::Mat> used;
  };
  Snapshot save() const;
  void restore(const Snapshot& snapshot);

  // Free area left, in working pixels.
  double free_px() const;

  std::size_t copies() const { return copies_.size(); }

  // Window sizes whose per-copy maps (free windows, window sums: 13 bytes per window
  // position) are kept; the least recently used size is freed in every copy when another
  // is needed. A regular grid uses one size, dp cuts four (border and inner windows), a
  // morphed grid one per cell outline (about 94 at 1.97 px/mm, each used about twice).
  static constexpr std::size_t kCachedSizes = 4;

  // Bytes held now by the per-size maps, and by everything the index holds (the copies'
  // images, features, spectra, integral images, masks, and the per-size maps).
  std::size_t cache_bytes() const;
  std::size_t bytes() const;

 private:
  struct Copy;
  struct Slot;
  struct SizeCache;
  // Recomputes copy i's mask integral and drops its free-window maps (the mask changed).
  void refresh(int i);
  // The maps of window size pw x ph, most recently used first (evicting the oldest size).
  SizeCache& cached(int pw, int ph);
  // Windows of size pw x ph wholly on free wood in `c` (255), kept in `slot`; their count.
  static int ensure_valid(const Copy& c, Slot& slot, int pw, int ph);
  // Per copy: a lower bound of eq. 4 for patch (f1, f2) over its free windows (infinite
  // where none is free): (sum of differences)^2 / n per feature, from integral images.
  std::vector<double> lower_bounds(const cv::Mat& f1, const cv::Mat& f2);
  // Scores copies best bound first, in parallel batches, skipping every copy whose bound
  // cannot beat the best match so far; `prepare` (may be empty) runs before each batch with
  // the order and the batch's range, `score(copy, rank in batch)` on worker threads.
  std::optional<Match> search(
      const std::vector<double>& bound,
      const std::function<void(const std::vector<int>&, std::size_t, std::size_t)>& prepare,
      const std::function<Match(int, std::size_t)>& score);
  std::optional<Match> best_masked(const cv::Mat& f1, const cv::Mat& f2, const cv::Mat& mask);

  double px_per_mm_;
  double grow_px_;  // kerf + half a pixel diagonal
  std::vector<std::unique_ptr<Copy>> copies_;
  std::list<SizeCache> cache_;  // at most kCachedSizes entries
  std::vector<std::vector<int>> copies_of_sheet_;
  std::vector<cv::Mat> used_;  // per sheet, CV_8UC1 255 = used (copy 0's frame)
  std::vector<cv::Mat> usable_;
  std::array<double, 256> free_hist_{};
};

}  // namespace atelier::parquetry

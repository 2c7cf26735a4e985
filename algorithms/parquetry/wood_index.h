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
// wood in O(1), cached per window size until the sheet changes. An exact lower bound per copy,
// (sum of differences)^2 / n per feature over its free windows, orders the copies and skips
// those that cannot beat the best found so far (about 70% of them). Copies are searched in
// parallel batches (cv::parallel_for_).
//
// Frames. Rotated copy k of a sheet shows the sheet turned by k * 360 / n degrees
// counter-clockwise (y down) on a canvas just holding it; copy 0 is the sheet itself. In other
// copies a taken piece is marked with a 0.71 px margin so every pixel it touches is used.
//
// Not thread-safe: one plan owns one WoodIndex.
#pragma once

#include <array>
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
  // `sheets` and `stock` validated by the caller; stock.px_per_mm == px_per_mm or 0.
  WoodIndex(const std::vector<Sheet>& sheets, const Stock& stock, double px_per_mm,
            int rotations, double w_intens, double w_edge);
  ~WoodIndex();

  // Histogram of the free wood's grey levels (for eq. 2).
  const std::array<double, 256>& free_histogram() const { return free_hist_; }

  // Best free window for weighted features f1, f2 (CV_32F, same size); nullopt when no window
  // of that size is free anywhere.
  std::optional<Match> best(const cv::Mat& f1, const cv::Mat& f2);

  // Marks the window of `m` used in every copy of its sheet and in the sheet's stock mask.
  void take(const Match& m);

  // Wood colour (CV_8UC3) under the window of `m`.
  cv::Mat colour(const Match& m) const;

  // Window corners (top-left, top-right, bottom-right, bottom-left) in sheet pixels.
  std::array<cv::Point2d, 4> corners_in_sheet(const Match& m) const;

  // Saved masks, to undo tentative takes (adaptive splitting).
  struct Snapshot {
    std::vector<cv::Mat> bad;
    std::vector<cv::Mat> used;
  };
  Snapshot save() const;
  void restore(const Snapshot& snapshot);

  // Free area left, in working pixels.
  double free_px() const;

  // Used masks per sheet at the working resolution (the Stock to hand back).
  Stock stock(const std::vector<Sheet>& sheets) const;

  std::size_t copies() const { return copies_.size(); }

 private:
  struct Copy;
  static void refresh(Copy& c);

  double px_per_mm_;
  std::vector<std::unique_ptr<Copy>> copies_;
  std::vector<std::vector<int>> copies_of_sheet_;
  std::vector<cv::Mat> used_;  // per sheet, CV_8UC1 255 = used (copy 0's frame)
  std::vector<cv::Mat> usable_;
  std::array<double, 256> free_hist_{};
};

}  // namespace atelier::parquetry

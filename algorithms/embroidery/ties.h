// One thread run's clean-up before it is written: tiny stitches dropped, then a tie-in at its
// start and a tie-off at its end (issue 21 points 7 and 8).
// Units: millimetres, the plan's frame (stitch_plan.h). Pure functions; thread-safe.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace atelier::embroidery {

// Ink/Stitch's defaults: stitches of min_stitch_mm or less are dropped (its "minimum stitch
// length", 0.1 mm); its default lock stitch ("half stitch") goes half the first stitch
// ahead, a whole one, half back and home again: four stitches of at most 0.75 mm.
inline constexpr double kTieStitchMm = 0.75;

// True when the stitch a -> b is longer than min_mm both in mm and as the files write it
// (positions rounded to 0.1 mm).
bool stitch_longer_than(cv::Point2d a, cv::Point2d b, double min_mm);

// Drops every needle point whose stitch from the last one kept is not longer than min_mm
// (stitch_longer_than); the first is always kept. Points are dropped, never moved: every kept point is one the generator placed in its
// region. Returns the number dropped.
int drop_tiny_stitches(std::vector<cv::Point2d>& run, double min_mm);

// The run's length along its needle points, mm.
double run_length(const std::vector<cv::Point2d>& run);

// The tie-in of a run that starts at run[0]: four needle points on the run's own path (on
// thread the run then sews over) ending back at run[0]: at s, 2 s, s and 0 along the path,
// s = min(kTieStitchMm, length / 2) with the length taken up to 2 kTieStitchMm. Where that
// would make a tie stitch min_mm or shorter (a short or folded path) the tie goes back and
// forth twice towards the first needle point farther than min_mm, at most kTieStitchMm:
// no tie stitch is min_mm or shorter either (stitch_longer_than). Empty when every point of the run lies within
// min_mm of run[0] (nothing to tie: the caller drops such a run).
std::vector<cv::Point2d> tie_in(const std::vector<cv::Point2d>& run, double min_mm);

// The tie-off of a run ending at run.back(): the same four points back along the run's end,
// ending at run.back().
std::vector<cv::Point2d> tie_off(const std::vector<cv::Point2d>& run, double min_mm);

}  // namespace atelier::embroidery

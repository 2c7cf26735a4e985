// Skeleton branches of a region (paper 5.2, Fig. 6) and a smooth B-spline through a branch.
// Units: pixels of the mask passed in (x right, y down); a pixel's centre is its integer
// coordinate. Pure functions on value types; thread-safe (no shared state).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace atelier::embroidery {

struct SkeletonBranch {
  std::vector<cv::Point2f> pixels;  // ordered along the branch, pixel centres
};

// Branches of a binary mask (255 = inside), in the mask's pixel frame, after the paper's
// clean-up: Zhang-Suen thinning (OpenCV ximgproc); intersection areas (skeleton pixels within
// the local stroke radius of a pixel joining three or more arms, merged when they touch or are
// bridged by a piece shorter than min_branch_px) are removed; spurs shorter than
// min_branch_px are dropped; the arms cut off at one area are reconnected in pairs for the
// best direction continuity (an arm is left alone when every partner would turn it by more
// than 90 degrees), joined by a straight pixel line through the area; the pixels are then
// traversed again into branches. A branch with no free end (a ring) comes back once, its
// first pixel 8-adjacent to its last. Isolated pieces shorter than min_branch_px are dropped.
std::vector<SkeletonBranch> skeleton_branches(const cv::Mat1b& mask, double min_branch_px);

// True when the branch is a closed loop (first pixel 8-adjacent to the last, 3+ pixels).
bool is_closed(const SkeletonBranch& branch);

// A smooth curve through the branch: least-squares uniform cubic B-spline (control points
// about every 8 px, a light second-difference penalty keeps sparse spans stable; periodic
// for a closed branch), sampled every `step_px` of arc length, with unit tangents; an open
// curve is extended at both ends by `extend_px` along its end tangents (samples keep the
// step). A branch of one pixel gives one point with tangent (1, 0).
struct SampledCurve {
  std::vector<cv::Point2f> points, tangents;
};
SampledCurve fit_bspline(const SkeletonBranch& branch, double step_px, double extend_px);

// The stitch generators' sewing order: the branch not yet `done` with an end nearest to `from`
// (or, with no needle position yet, the first such branch), marked done and returned oriented
// to start at that end. `done` has one flag per branch and at least one is false.
SkeletonBranch next_branch(const std::vector<SkeletonBranch>& branches, std::vector<bool>& done,
                           const cv::Point2f* from);

}  // namespace atelier::embroidery

// The path of a human-like pencil line between two end points (Meraj et al. 2008, section 3.1):
// the Flash-Hogan minimum-jerk trajectory (eq. 1, t in [0, 2]) sampled at the time step of
// the paper's table 1, each interior sample displaced normal to the line by the squiggle D
// (uniform in [-D, +D], independently per control point), and a uniform Catmull-Rom spline
// through these control points.
//
// Units: pixels, image coordinates (x right, y down); times in the paper's units (t_final = 2).
// The ends are never displaced, so a line starts and ends exactly at its end points. A
// Catmull-Rom segment is an affine combination of four control points whose weights sum to
// 1.25 in absolute value at most, so the path stays within kOvershoot x D of the straight
// segment (max_deviation()).
// Pure functions; the random generator is the caller's (one thread at a time).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <random>
#include <vector>

namespace atelier::pencil {

inline constexpr double kFinalTime = 2.0;  // t_final of eq. 1 ("regardless of line length")
inline constexpr double kOvershoot = 1.25;  // uniform Catmull-Rom: max sum of |weights|

// Table 1: the time step for a line of `length_px`: 0.5 up to 200 px, 0.3 up to 400 px, 0.2
// beyond (the value of the paper's figure 1c). Longer lines get more control points.
double time_step(double length_px);

// Eq. 1: the minimum-jerk position at time t in [0, kFinalTime] on the way from `from` to `to`.
cv::Point2d min_jerk(cv::Point2d from, cv::Point2d to, double t);

struct PathParams {
  double squiggle = 5.0;    // D in px (paper: [-5, +5]); 0 = no deviation; >= 0
  double spacing_px = 0.5;  // the path's samples are at most this far apart; > 0
};

// The largest distance of a path from the straight segment between its ends.
inline double max_deviation(double squiggle) { return kOvershoot * squiggle; }

// Control points at t = 0, dt, 2 dt, ... and t = kFinalTime (dt = time_step(length)) on the
// minimum-jerk trajectory; interior ones displaced normal to the line by D ~ U[-squiggle,
// squiggle]. A line of zero length gives the single point.
std::vector<cv::Point2d> control_points(cv::Point2d from, cv::Point2d to, double squiggle,
                                        std::mt19937_64& rng);

// A uniform Catmull-Rom spline through `points` (the end points doubled), sampled so that
// consecutive samples are at most spacing_px apart; the first and last samples are the first
// and last points. Fewer than 2 points are returned as they are.
std::vector<cv::Point2d> catmull_rom(const std::vector<cv::Point2d>& points, double spacing_px);

struct HumanPath {
  std::vector<cv::Point2d> control;  // the displaced control points
  std::vector<cv::Point2d> path;     // the spline through them, from `from` to `to`
};

// The whole path, reproducible from `seed`. Throws std::invalid_argument for a negative or
// non-finite squiggle, a spacing <= 0, or non-finite end points.
HumanPath human_path(cv::Point2d from, cv::Point2d to, const PathParams& params, std::uint64_t seed);

}  // namespace atelier::pencil

// Can a veneer piece be cut on the laser and laid? The checks the plan runs on every piece
// (issue 5: one connected part, no piece below the minimum patch, no sliver below the minimum
// feature), phrased for a user.
//
// Units: mm. Pure, thread-safe (no shared state; OpenCV calls on local images only).
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

namespace atelier::parquetry {

// Resolution of the raster the checks run on (px per mm): 1/20 mm is finer than any laser's
// kerf, so a part that only holds together below it falls apart when cut anyway.
inline constexpr double kFabricabilityPxPerMm = 20.0;

// nullopt when a piece with this outline (a closed polygon in mm, the first point not
// repeated, either orientation; e.g. Piece::target_mm) can be cut and assembled; otherwise the
// first problem found, in words for a user, in this order:
//   "crosses itself"                          the outline meets or crosses itself (Boost.Geometry
//                                             validity); "has no area" / "has invalid
//                                             coordinates" for degenerate input
//   "falls apart into N parts"                rasterised at kFabricabilityPxPerMm, N > 1 pieces
//                                             (4-connected): joined below a twentieth of a mm
//   "is 3.2 mm across, below the 5 mm minimum"
//                                             across = diameter of the largest inscribed circle
//   "falls apart into N parts joined by a neck thinner than 2 mm"
//                                             opening the raster with a disc of diameter
//                                             min_feature_mm leaves N > 1 parts each larger
//                                             than min_feature_mm^2 / 2
//   "has a sliver 1.1 mm thin (minimum 2 mm)" that opening removes a connected part larger
//                                             than min_feature_mm^2 / 2 (a square's corners
//                                             lose about 0.11 * min_feature_mm^2 each); its
//                                             thickness is the largest inscribed circle there.
// Throws std::invalid_argument for negative minimums or a piece over 1 m across (the raster
// would not fit in memory; no workshop piece is that large).
std::optional<std::string> fabricability_problem(const std::vector<cv::Point2d>& polygon_mm,
                                                 double min_patch_mm, double min_feature_mm);

}  // namespace atelier::parquetry

// Image -> vector strokes for sketch jobs (issue 8, section 2): the straight segments a hand
// would draw to redraw an image's edges. The paper (Meraj et al. 2008, section 6, figure 8b)
// takes "vector line drawings" -- end point pairs -- as input; each Segment here is one such
// pair, drawn later as one human-like line (human_path from -> to, then draw_pencil_line).
// Short collinear pieces are merged into long strokes, as the paper's flowsnake example asks.
//
// Units: pixels of the input image, x right, y down; pixel (x, y) is centred at (x, y).
// Pure functions: no state, no I/O; safe from any thread on distinct or read-only images.
// Results are deterministic (the same image and parameters give the same segments, in order).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace atelier::pencil {

struct Segment {
  cv::Point2d from, to;  // pixels; the hand starts at `from`
};

struct StrokeParams {
  int smoothing_px = 9;          // edge-preserving smoothing: cv::bilateralFilter diameter (0 = none); >= 0
  double smoothing_sigma = 40;   // its sigmaColor (grey levels); sigmaSpace = smoothing_px / 2; > 0
  double canny_low = 0, canny_high = 0;  // hysteresis thresholds of cv::Canny (3x3 Sobel, L2 gradient,
                                         // so a clean step of c grey levels peaks at 4 c); both 0 =
                                         // automatic (auto_canny_thresholds); else 0 <= low <= high, high > 0
  double simplify_px = 1.5;      // cv::approxPolyDP epsilon on each traced edge; >= 0
  double merge_angle_deg = 12;   // a segment turning the stroke so far by less than this is merged ...
  double merge_offset_px = 1.5;  // ... if every vertex it replaces stays within this of the merged segment
  double min_stroke_px = 6;      // strokes (merged segments) shorter than this are dropped; >= 0
  double max_stroke_px = 0;      // 0 = no limit; else longer strokes are split into equal pieces (a hand
                                 // lifts the pencil); must then be >= 2 * min_stroke_px, so that no
                                 // piece (each longer than max_stroke_px / 2) falls under min_stroke_px
};

// The image as it lies on white paper: CV_8UC1 and CV_8UC3 (BGR) are returned as they are (shared
// data), CV_8UC4 (BGRA) is composited over white (transparent = paper) into BGR. Throws
// std::invalid_argument for an empty image or another type.
cv::Mat on_white_paper(const cv::Mat& image);

// The automatic Canny thresholds for a smoothed CV_8UC1 or CV_8UC3 image: `high` is half the
// median gradient magnitude (3x3 Sobel, L2, the largest over the channels -- what cv::Canny
// measures) of the pixels whose magnitude exceeds a noise floor of a 16-grey-level step (64),
// and at least twice that floor; `low` is high / 2. Medians follow the image: a line drawing's
// crisp edges give high thresholds that ignore paper grain and JPEG ringing, a soft photograph
// lower ones. (Half: the crisp black-on-white edges of a drawing set the median, and its softer
// colour edges must still pass; and Canny keeps only pixels strictly above `high`, while on a
// crisp drawing all ridge pixels sit at the median.) An image with no gradient above the floor
// gets (64, 128) and, having nothing that strong, no edges.
cv::Vec2d auto_canny_thresholds(const cv::Mat& smoothed);

// CV_8UC1 0/255: Canny edges (1 px wide) after the bilateral smoothing. Colour images are
// smoothed and edge-detected in colour (cv::Canny takes the strongest channel), so two colours
// of equal brightness still have an edge between them. `image`: CV_8UC1, CV_8UC3 (BGR) or
// CV_8UC4 (BGRA; transparent = paper white). Throws std::invalid_argument for a bad image or
// parameter (the message names it), std::runtime_error if OpenCV fails.
cv::Mat edge_map(const cv::Mat& image, const StrokeParams& params);

// The edges of edge_map as straight strokes, each edge drawn once:
//  0. Thinning: edge pixels whose removal changes no connection (Yokoi's 8-connectivity number
//     is 1) and that are not line ends are removed, so every edge is 8-connected and 1 px wide
//     (Canny leaves 4-connected staircase pairs, which a border walk goes round on both sides).
//  1. cv::findContours (RETR_LIST, CHAIN_APPROX_NONE) gives, for each connected edge, a walk
//     round its pixels (out along every branch and back, and a closed edge twice: as an outer
//     border and as a hole). Walks are taken longest first.
//  2. De-duplication on pixels: each walk is cut into open polylines of pixels no earlier walk
//     (nor the same walk earlier) has visited; a polyline that continues from, or runs into, a
//     visited pixel keeps that pixel as its end (so branches meet their trunk), except for the
//     pixel it just came from (no 1 px hook where a walk turns back). A walk that comes round
//     to where it started is closed with its first pixel.
//  3. Each polyline is simplified by cv::approxPolyDP (epsilon simplify_px): a closed one as a
//     closed curve (no vertex just because the walk began there), a nearly closed one split
//     first at its pixel farthest from its start (Douglas-Peucker needs distinct ends).
//  4. Merging: walking each simplified polyline, the next segment joins the current stroke
//     while the stroke's direction (start -> end) turns by less than merge_angle_deg when it
//     does, and every vertex the longer stroke replaces lies within merge_offset_px of it. (The
//     turn of the stroke, not the segment's own direction: the 1 px steps of an aliased edge
//     point 45 degrees off however straight the edge is.) A stroke therefore stays within
//     simplify_px + merge_offset_px of its edge pixels.
//  5. Strokes shorter than min_stroke_px are dropped; with max_stroke_px, longer ones are split.
// Order, as a hand would draw: the big shapes first (walks longest first; ties in
// findContours' order), each edge along its walk, each stroke in the walking direction (one
// stroke's `to` is usually the next one's `from`, and a closed edge is drawn round).
// Throws as edge_map.
std::vector<Segment> edge_strokes(const cv::Mat& image, const StrokeParams& params);

}  // namespace atelier::pencil

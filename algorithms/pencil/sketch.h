// A sketch: straight segments (edge strokes, hatching) redrawn as human-like pencil lines
// (Meraj et al. 2008, section 6: "our technique only requires the selection of a pencil type
// and specification of the end points of each line").
//
// Units: segments in image px; the drawing (canvas and paths) in drawing px = image px x scale.
// Grey levels 0 (black) .. 255 (paper). Pure; the caller owns everything; one call per thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "algorithms/pencil/path.h"
#include "algorithms/pencil/profile.h"
#include "algorithms/pencil/strokes.h"

namespace atelier::pencil {

struct SketchLine {
  std::vector<cv::Point2d> path;  // drawing px, from the segment's first end to its second;
                                  // the drawn spline thinned to within 0.05 px
  bool hatch = false;             // a hatching line (else an edge stroke)
};

struct SketchDrawing {
  cv::Mat canvas;                 // CV_8UC1, paper white, the lines in pencil
  std::vector<SketchLine> lines;  // in drawing order: strokes, then hatching
};

// The seed of line `index` of a drawing seeded with `seed` (SplitMix64 of both), so that every
// line is different and inserting hatching does not change the strokes.
std::uint64_t line_seed(std::uint64_t seed, std::size_t index);

// The at most `max_lines` segments to draw: the longest strokes first, then hatching lines while
// room is left; each list keeps its order (the order a hand draws in). Returns how many of
// `strokes` and `hatching` are kept, as {strokes, hatching}; *strokes and *hatching are trimmed.
std::pair<std::size_t, std::size_t> keep_longest(std::vector<Segment>* strokes,
                                                std::vector<Segment>* hatching, std::size_t max_lines);

// Draws every segment as a human line (human_path with `path_params`, seeded by line_seed) with
// the pencil `profile` onto a paper canvas of image_size x scale. `threads` (>= 1) threads draw
// runs of lines onto canvases of their own, merged by min at the end: a line's texture does not
// depend on what is already on the paper and marks combine by min, so the drawing is the same
// bit for bit for any thread count. `progress` (may be empty) is called from the calling thread
// only, with the fraction of lines drawn. Throws std::invalid_argument for scale <= 0, an empty
// size or threads < 1.
SketchDrawing draw_sketch(cv::Size image_size, double scale, const std::vector<Segment>& strokes,
                          const std::vector<Segment>& hatching, const PathParams& path_params,
                          const PencilProfile& profile, std::uint64_t seed,
                          const std::function<void(double)>& progress = {}, int threads = 2);

}  // namespace atelier::pencil

// Test helper shared by the pencil texture tests: nearly vertical hand-drawn lines, as a scan to
// learn a profile from would show them.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "algorithms/pencil/path.h"
#include "algorithms/pencil/profile.h"
#include "algorithms/pencil/texture.h"

namespace atelier::pencil::testing {

// `count` lines 50 px apart, 400 px long (running off the top and bottom), squiggle 1 px, on a
// white canvas 400 x 50*count; line i is seeded with seed + i.
inline cv::Mat drawn_lines(const PencilProfile& p, std::uint64_t seed, int count) {
  cv::Mat canvas(400, 50 * count, CV_8UC1, cv::Scalar(255));
  PathParams params;
  params.squiggle = 1.0;
  for (int i = 0; i < count; ++i) {
    const cv::Point2d from(25 + 50 * i, -5), to(25 + 50 * i, 404);
    draw_pencil_line(canvas, human_path(from, to, params, seed + i).path, p, seed + i);
  }
  return canvas;
}

}  // namespace atelier::pencil::testing

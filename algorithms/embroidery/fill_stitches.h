// Tatami fill of a long-short region: parallel rows at the region's angle, staggered needle
// points, rows sewn boustrophedon section by section, underlay first.
// Units: mask pixels in, millimetres out (see StitchSink::to_mm). Pure; thread-safe.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "algorithms/embroidery/running_stitches.h"
#include "algorithms/embroidery/stitch_plan.h"
#include "algorithms/embroidery/stitch_planner.h"

namespace atelier::embroidery {

// The rows of a fill: each section is a polyline (mask pixels) of rows sewn back and forth,
// consecutive rows overlapping one to one; where a row breaks into several runs a new
// section starts. Rows are `spacing_px` apart along the normal of `angle` (radians, the
// stitch direction); needle points lie on a grid along the row shifted by
// (row % stagger) / stagger * max_px; no stitch is longer than max_px. Row ends are mask
// pixel centres, so every point lies on a mask pixel.
std::vector<std::vector<cv::Point2f>> fill_sections(const cv::Mat1b& mask, double angle, double spacing_px,
                                                    double max_px, int stagger);

// Appends the tatami fill of `mask` to `sink`: underlay (if params.fill_underlay) then the top
// rows, sections nearest first with travel inside the region between them.
void fill_into(const cv::Mat1b& mask, double angle, const StitchParams& params, StitchSink& sink);

// The region's fill stitches in mm; offset_px is added to mask pixel coordinates before
// scaling (the planner passes the bounding box's corner minus the design's centre).
std::vector<StitchPoint> fill_region(const cv::Mat1b& mask, cv::Point2f offset_px, double angle,
                                     const StitchParams& params);

}  // namespace atelier::embroidery

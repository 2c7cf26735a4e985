// The priority queue of target patches (paper 3.3, figure 6): most salient first (summed
// fine-grained static saliency, Montabone & Soto 2010, from OpenCV's saliency module) or
// nearest the centre first. Pure, thread-safe.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "algorithms/parquetry/params.h"

namespace atelier::parquetry {

// Priority of every cell (row * cols + col) of a cols x rows grid of patch x patch pixel
// cells over `target`: lower first. Saliency: minus the mean fine-grained saliency (0..255)
// of the cell, so scores of several targets compare; center: distance to the centre in
// cells, relative to half the grid's diagonal (0..1).
std::vector<double> patch_priority(const cv::Mat& target, int cols, int rows, int patch,
                                   Order order);

// Cell indices (row * cols + col) of a cols x rows grid of patch x patch pixel cells over
// `target` (CV_8UC3 or CV_8UC1, at least cols*patch x rows*patch), in processing order.
// Equal priorities are ordered by a shuffle seeded with `seed`.
std::vector<int> patch_order(const cv::Mat& target, int cols, int rows, int patch, Order order,
                             std::uint64_t seed);

}  // namespace atelier::parquetry

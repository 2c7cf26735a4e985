// An upper estimate of a parquetry plan's peak memory (resident bytes), from its inputs only,
// so a job can be refused before anything is decoded or matched.
//
// What it counts (wood_index.h, plan.cc): per rotated copy of every sheet, on its canvas of
// A pixels (the turned sheet's bounding box at px_per_mm) and DFT size D: colour, features,
// spectra, integral images and masks, 44 A + 8 D bytes; the per-window-size maps, 13 A bytes
// for each size kept (WoodIndex::kCachedSizes at most); the decoded scans and targets; the
// target's working images and the preview; and the process itself (libraries, threads).
// Calibrated against measured peak RSS (README, parquetry): within 1.5x above it.
//
// Pure; thread-safe.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "algorithms/parquetry/params.h"

namespace atelier::parquetry {

// A sheet as far as memory goes: its scan's size in scan pixels and its dpi.
struct SheetSize {
  cv::Size scan_px;
  double dpi = 300;
  bool has_mask = false;
};

struct MemoryEstimate {
  double copies_bytes = 0;  // the rotated copies' images, features, spectra, integrals, masks
  double cache_bytes = 0;   // the per-window-size maps
  double inputs_bytes = 0;  // decoded scans (and masks) and targets
  double plan_bytes = 0;    // the targets' working images, the preview, thread buffers
  double base_bytes = 0;    // the process (libraries, stacks) before any of these
  double total_bytes = 0;
  int copies = 0;           // sheets x rotations
};

// `targets`: each target image's size in its own pixels.
MemoryEstimate estimate_plan_memory(const std::vector<SheetSize>& sheets,
                                    const std::vector<cv::Size>& targets, const Params& params);

// "12 sheets x 15 rotations at 1.97 px/mm": what drives the estimate, for messages.
std::string memory_drivers(const std::vector<SheetSize>& sheets, const Params& params);

}  // namespace atelier::parquetry

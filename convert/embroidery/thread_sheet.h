// threads.pdf (issue 21): the printable colour sheet a digitizer hands to the machine
// operator. One A4 portrait page (more when the colour list runs long): the design's name,
// size in mm, stitch count, colours and trims, a picture of the stitches (stitches.png), then
// the colour order: per colour block its number (the stop), a swatch, hex RGB, a thread name
// when one is known, its stitch count and its thread length in metres.
// Units: mm and metres in the data; the PDF is drawn in points (1/72 in). The picture is an
// 8-bit BGR image (not owned; copied into the PDF). Thread-safe per call.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/embroidery/stitch_plan.h"

namespace atelier {

struct ThreadBlock {
  std::uint32_t rgb = 0;   // 0xRRGGBB
  int stitches = 0;        // needle penetrations of kind `stitch` in the block
  double length_m = 0;     // the stitches' length as sewn (top thread on the fabric), metres
  std::string thread;      // catalogue names (e.g. PEC, Janome), one per line; empty if none
};

// Per colour block of the plan, in sewing order (a block ends at each colour change; the
// plan's colors_rgb give the colours, grey 0x808080 when missing). The length sums the
// distance from each stitch's previous positioned point, as the thread lies; jumps and trims
// add nothing. Pure.
std::vector<ThreadBlock> thread_blocks(const embroidery::StitchPlan& plan);

struct ThreadSheet {
  std::string design;                  // the design's name (the input file)
  double width_mm = 0, height_mm = 0;  // the design's size
  int stitches = 0, trims = 0;
  std::vector<ThreadBlock> blocks;
  cv::Mat3b picture;                   // stitches.png (may be empty: no picture)
};

// The sheet as PDF bytes. Throws std::runtime_error when cairo fails.
std::string thread_sheet_pdf(const ThreadSheet& sheet);

// Writes it through write_output (a temporary name, then rename); throws ConvertError naming
// the file when the write fails.
void write_thread_sheet(const ThreadSheet& sheet, const std::filesystem::path& file);

}  // namespace atelier

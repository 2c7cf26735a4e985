// Photo engraving, the algorithm (LightBurn's "image" mode): a grey image at the output
// resolution -> a grid of laser power per pixel -> scan lines of runs of equal power -> GRBL
// G-code (laser mode, M4 dynamic power, S per run).
//
// Grid. Row 0 is the image's top (the rear of the bed), column 0 its left. One column is one
// dot at the output dpi (25.4 / dpi mm wide), one row one scan line (line interval mm high).
// Grey levels are 0 (black) .. 255 (white).
//
// Power. darkness = 1 - grey/255 (negative: grey/255), then darkness^gamma. Dithering turns it
// into on/off dots burned at max_power_pct; greyscale burns every pixel whose darkness is above
// half a grey level at min + (max - min) * darkness. Powers are S values (0..s_max, rounded),
// so that equal neighbours merge into one run.
//
// Scanning. Only rows with a burned pixel are scanned, each from its first to its last burned
// pixel (blank margins and blank lines cost nothing). Rows alternate direction when
// bidirectional (the first scanned row runs left to right). Each row: G0 to `overscan` mm
// before its first burned pixel, G1 S0 up to that pixel (the head reaches the feed before it
// burns), one G1 per run of equal S, G1 S0 to `overscan` mm past the last burned pixel; the
// overscan is clipped to the work area [0, width].
//
// Coordinates are bed mm (X from the left edge, Y from the front edge, see plan.h).
// Pure (no I/O); thread-safe.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "algorithms/laser/geometry.h"
#include "algorithms/laser/plan.h"

namespace atelier::laser {

enum class Dither { threshold, ordered, floyd_steinberg, jarvis, stucki, greyscale };
const char* dither_name(Dither d);  // "threshold", "ordered", "floyd-steinberg", ...

// A row-major grid of values (grey levels 0..255, darkness 0..1 or S values).
template <typename T>
struct Grid {
  int cols = 0, rows = 0;
  std::vector<T> v;
  Grid() = default;
  Grid(int c, int r, T fill = T{}) : cols(c), rows(r), v(static_cast<size_t>(c) * r, fill) {}
  T& at(int row, int col) { return v[static_cast<size_t>(row) * cols + col]; }
  const T& at(int row, int col) const { return v[static_cast<size_t>(row) * cols + col]; }
};

struct PowerSettings {
  Dither dither = Dither::jarvis;
  double min_power_pct = 0, max_power_pct = 100;  // of s_max; min only for greyscale
  double gamma = 1.0;       // > 0; above 1 lightens the mid-tones
  bool negative = false;    // burn the light parts
  double threshold = 0.5;   // darkness at which `threshold` dithering burns
  double s_max = 1000;      // GRBL $30
};

// Darkness 0..1 per pixel (after negative and gamma).
Grid<float> darkness(const Grid<uint8_t>& grey, const PowerSettings& s);

// One weight of an error-diffusion kernel: the share of a pixel's error given to the pixel
// dx columns right and dy rows down (dy = 0: dx > 0, not yet visited).
struct KernelTap {
  int dx = 0, dy = 0;
  double w = 0;
};
// Floyd-Steinberg, Jarvis-Judice-Ninke, Stucki; empty for the others. Weights sum to 1.
std::vector<KernelTap> diffusion_kernel(Dither d);

// On/off dots from darkness by the chosen dithering (not greyscale): 1 = burn.
// Error diffusion runs left to right on every row (the kernel's weights sum to 1, so the mean
// darkness is kept); ordered uses the 8x8 Bayer matrix.
Grid<uint8_t> dither(const Grid<float>& dark, Dither d, double threshold = 0.5);

// S per pixel (0 = off). Throws PlanError for unusable settings (gamma <= 0, min > max, a
// power outside 0..100, s_max <= 0).
Grid<int> power_grid(const Grid<uint8_t>& grey, const PowerSettings& s);

struct Run {
  int col0 = 0, col1 = 0;  // pixels [col0, col1)
  int s = 0;
};
struct ScanLine {
  int row = 0;
  bool forward = true;     // left to right
  std::vector<Run> runs;   // in scan order, from the first to the last burned pixel; S0 gaps kept
};

// The rows to scan, in order (see "Scanning").
std::vector<ScanLine> scan_lines(const Grid<int>& power, bool bidirectional);

struct RasterPlacement {
  double x_mm = 0, y_mm = 0;  // bed mm of the image's front-left (bottom-left) corner
  double dot_mm = 0.1;        // column pitch (25.4 / dpi)
  double line_mm = 0.1;       // row pitch (line interval)
};

struct RasterMotion {
  double speed_mm_min = 3000;
  double overscan_mm = 2.5;
};

// Overscan that lets the head reach `speed_mm_min` from rest at `accel_mm_s2`: v^2 / (2 a),
// plus 10 % (GRBL accelerates per block; a little more keeps the first dot at full speed).
double overscan_for(double speed_mm_min, double accel_mm_s2);

// One move of the program (bed mm), as the time estimate takes it.
struct RasterMove {
  double x = 0, y = 0;
  double feed_mm_min = 0;
  bool rapid = false;
};

struct RasterJob {
  std::string gcode;
  Bounds bounds;               // bed mm of every burned point
  size_t scanned_rows = 0;
  size_t burn_moves = 0;       // G1 with S > 0
  double burn_length_mm = 0;   // with S > 0
  double scan_length_mm = 0;   // every G1 (burns, S0 gaps, overscan)
  double travel_length_mm = 0; // G0, from bed (0, 0)
  std::vector<RasterMove> moves;   // every move in order, for the time estimate
                                   // (motion_planner.h move_seconds)
  bool overscan_clipped = false;   // a row's overscan ran into the work area's edge
};

// Throws PlanError for speed <= 0, overscan < 0, pitches <= 0, an image with nothing to burn,
// or any burned point outside the machine's work area.
RasterJob raster_gcode(const Grid<int>& power, const std::vector<ScanLine>& lines,
                       const RasterPlacement& place, const RasterMotion& motion,
                       const Machine& machine, const std::string& comment);

}  // namespace atelier::laser

#include "algorithms/parquetry/memory_estimate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "algorithms/parquetry/wood_index.h"

namespace atelier::parquetry {

namespace {

// Resident size of the converter before planning (OpenCV, libraries, two worker stacks),
// measured at 70-80 MB on a tiny plan.
constexpr double kBaseBytes = 96.0 * (1 << 20);

// Bytes per canvas pixel of one rotated copy (wood_index.cc Copy): bgr 3, f1 f2 8, sq 4,
// three CV_64F integrals 24, bad 1, its CV_32S integral 4; plus 8 per DFT pixel (two spectra).
constexpr double kCopyBytesPerPx = 44, kSpectrumBytesPerPx = 8;
// Per window position and cached size: valid 1, window sums of f1, f2, f1^2 + f2^2 12.
constexpr double kSizeBytesPerPx = 13;

}  // namespace

MemoryEstimate estimate_plan_memory(const std::vector<SheetSize>& sheets,
                                    const std::vector<cv::Size>& targets, const Params& p) {
  MemoryEstimate e;
  const double r = working_px_per_mm(p);
  const int rotations = std::max(1, p.rotations);
  double canvas_px = 0, largest_dft = 0;
  for (const SheetSize& s : sheets) {
    const double ppmm = s.dpi / 25.4;
    // sheet_size_px: floor of the scan's size in mm at px_per_mm.
    const int w = std::max(1, static_cast<int>(std::floor(s.scan_px.width / ppmm * r)));
    const int h = std::max(1, static_cast<int>(std::floor(s.scan_px.height / ppmm * r)));
    for (int k = 0; k < rotations; ++k) {
      const double a = 2 * CV_PI * k / rotations;
      const double cs = k == 0 ? 1.0 : std::abs(std::cos(a)), sn = k == 0 ? 0.0 : std::abs(std::sin(a));
      const int cw = static_cast<int>(std::ceil(w * cs + h * sn - 1e-6));
      const int ch = static_cast<int>(std::ceil(w * sn + h * cs - 1e-6));
      const double area = static_cast<double>(cw) * ch;
      const double dft = static_cast<double>(cv::getOptimalDFTSize(cw)) * cv::getOptimalDFTSize(ch);
      canvas_px += area;
      largest_dft = std::max(largest_dft, dft);
      e.copies_bytes += kCopyBytesPerPx * area + kSpectrumBytesPerPx * dft;
      ++e.copies;
    }
    e.copies_bytes += 2.0 * w * h;  // used and usable masks
    e.inputs_bytes += s.scan_px.area() * (3.0 + (s.has_mask ? 1.0 : 0.0));
    // While a sheet's copies are built: its resampled colour, grey, features and masks.
    e.plan_bytes = std::max(e.plan_bytes, 40.0 * w * h);
  }
  // Window sizes in use at once: one for a regular grid (more with adaptive splits), four
  // for dp (inner and border windows), the cache's bound for a morphed grid.
  std::size_t sizes = WoodIndex::kCachedSizes;
  if (p.grid == Grid::regular && p.refine == Refine::none) {
    sizes = std::min<std::size_t>(sizes, 1 + 4 * static_cast<std::size_t>(std::max(0, p.adaptive_levels)));
  }
  e.cache_bytes = kSizeBytesPerPx * static_cast<double>(sizes) * canvas_px;

  double target_px = 0;
  for (const cv::Size& t : targets) {
    // Decoded, converted to 8 bit and BGR (up to three copies of 3 bytes).
    e.inputs_bytes += 9.0 * t.area();
    const double shorter = std::max(1, std::min(t.width, t.height));
    const double scale = p.size_mm * r / shorter;
    const double wpx = t.width * scale, hpx = t.height * scale;
    target_px += wpx * hpx;
    // The preview at about 4 px/mm (render.h), with its joints and the PNG encoder's copy.
    const double mm2 = (wpx / r) * (hpx / r);
    e.plan_bytes += 16.0 * mm2 * 3 * 3;
  }
  // The targets' features, saliency, reconstruction and masks per piece at px_per_mm (about
  // 60 bytes a pixel with dp's wood windows), and two threads' correlation buffers.
  e.plan_bytes += 60.0 * target_px + 2 * 3 * 4.0 * largest_dft;
  e.base_bytes = kBaseBytes;
  e.total_bytes = e.copies_bytes + e.cache_bytes + e.inputs_bytes + e.plan_bytes + e.base_bytes;
  return e;
}

std::string memory_drivers(const std::vector<SheetSize>& sheets, const Params& p) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%zu sheet%s x %d rotation%s at %.3g px/mm", sheets.size(),
                sheets.size() == 1 ? "" : "s", p.rotations, p.rotations == 1 ? "" : "s", working_px_per_mm(p));
  return buf;
}

}  // namespace atelier::parquetry

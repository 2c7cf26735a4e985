#include "algorithms/pencil/profile.h"

#include <stdexcept>
#include <tuple>
#include <utility>

namespace atelier::pencil {

namespace {

// The grey levels below which `trim` of the histogram's mass lies, from either end.
std::pair<int, int> trimmed_range(const std::vector<double>& hist, double trim) {
  double total = 0.0;
  for (double x : hist) total += x;
  int lo = 0, hi = 255;
  for (double below = 0.0; lo < 255 && below + hist[lo] <= trim * total; ++lo) below += hist[lo];
  for (double above = 0.0; hi > 0 && above + hist[hi] <= trim * total; --hi) above += hist[hi];
  return {lo, std::max(lo, hi)};
}

void normalise(std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  if (sum > 0.0)
    for (double& x : v) x /= sum;
}

}  // namespace

PencilProfile learn_profile(const cv::Mat& gray, const std::string& name, int paper_threshold) {
  if (gray.empty() || gray.type() != CV_8UC1)
    throw std::invalid_argument("learn_profile: need a non-empty 8-bit grey image");
  PencilProfile p;
  p.name = name;
  p.mid_hist.assign(256, 0.0);
  p.hist.assign(256, 0.0);
  p.ccm.assign(256 * 256, 0.0);
  long runs = 0, run_pixels = 0;
  for (int y = 0; y < gray.rows; ++y) {
    const std::uint8_t* row = gray.ptr<std::uint8_t>(y);
    const std::uint8_t* below = y + 1 < gray.rows ? gray.ptr<std::uint8_t>(y + 1) : nullptr;
    int x = 0;
    while (x < gray.cols) {
      if (row[x] >= paper_threshold) {
        ++x;
        continue;
      }
      // One run of line pixels across the (vertical) line: its darkest pixel is the centre.
      int darkest = row[x];
      const int start = x;
      for (; x < gray.cols && row[x] < paper_threshold; ++x) {
        const int v = row[x];
        p.hist[v] += 1.0;
        darkest = std::min(darkest, v);
        if (below && below[x] < paper_threshold) p.ccm[v * 256 + below[x]] += 1.0;
      }
      p.mid_hist[darkest] += 1.0;
      ++runs;
      run_pixels += x - start;
    }
  }
  if (runs == 0) throw std::invalid_argument("learn_profile: no pencil line in the image");
  p.width_px = static_cast<double>(run_pixels) / static_cast<double>(runs);
  std::tie(p.min_mid, p.max_mid) = trimmed_range(p.mid_hist, kRangeTrim);
  std::tie(p.min_range, p.max_range) = trimmed_range(p.hist, kRangeTrim);
  p.mid_pixels = runs;
  p.line_pixels = run_pixels;
  for (double c : p.ccm) p.ccm_pairs += static_cast<long long>(c);
  normalise(p.mid_hist);
  normalise(p.hist);
  normalise(p.ccm);
  return p;
}

double chi_square(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) throw std::invalid_argument("chi_square: histograms of different sizes");
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double s = a[i] + b[i];
    if (s > 0.0) sum += (a[i] - b[i]) * (a[i] - b[i]) / s;
  }
  return sum / 2.0;
}

}  // namespace atelier::pencil

#include "algorithms/pencil/reference_scan.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace atelier::pencil {

const std::vector<GradeModel>& grade_models() {
  // Modelled, not measured (see the header). Meraj et al. 2008 (section 3.2, figure 2, table 2):
  // soft grades dark and wide with little paper showing, hard grades light, narrow and grainy.
  //                         name  centre   width grain edge  tooth amp
  static const std::vector<GradeModel> models = {
      {"2H", 150, 190, 3.0, 0.30, 228, 2.0, 9.0},
      {"H", 135, 172, 3.5, 0.26, 224, 2.2, 9.0},
      {"F", 120, 156, 4.0, 0.22, 220, 2.4, 10.0},
      {"HB", 104, 140, 4.5, 0.18, 216, 2.6, 10.0},
      {"B", 88, 124, 5.0, 0.14, 212, 2.8, 11.0},
      {"3B", 66, 100, 6.0, 0.10, 208, 3.0, 11.0},
      {"6B", 48, 80, 7.0, 0.06, 204, 3.5, 12.0},
      {"8B", 38, 70, 8.0, 0.04, 200, 4.0, 12.0},
  };
  return models;
}

const GradeModel* find_grade_model(const std::string& name) {
  for (const GradeModel& m : grade_models())
    if (m.name == name) return &m;
  return nullptr;
}

namespace {

// z such that a standard normal exceeds it with probability `share` (bisection on erfc: there
// is no inverse in <cmath>, and 60 halvings are exact to a double).
double upper_quantile(double share) {
  double lo = -10.0, hi = 10.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = (lo + hi) / 2.0;
    if (0.5 * std::erfc(mid / std::sqrt(2.0)) > share) lo = mid;
    else hi = mid;
  }
  return (lo + hi) / 2.0;
}

void check(const GradeModel& m, int rows) {
  auto grey = [](double v) { return v >= 0.0 && v <= 255.0; };
  if (rows < 1) throw std::invalid_argument("reference_scan: rows must be >= 1");
  if (!grey(m.centre_lo) || !grey(m.centre_hi) || m.centre_lo > m.centre_hi || !grey(m.edge_grey))
    throw std::invalid_argument("reference_scan: grey levels of " + m.name + " outside 0..255 or out of order");
  if (!(m.width_px > 0.0 && m.width_px <= 64.0) || !(m.grain >= 0.0 && m.grain < 1.0) || !(m.tooth_px > 0.0) ||
      !(m.grain_amp >= 0.0 && m.grain_amp <= 128.0))
    throw std::invalid_argument("reference_scan: width, grain, tooth or grain amplitude of " + m.name +
                                " out of bounds");
}

}  // namespace

cv::Mat reference_scan(const GradeModel& m, int rows, std::uint64_t seed) {
  check(m, rows);
  const double half = m.width_px / 2.0;
  const int spacing = static_cast<int>(std::ceil(m.width_px)) + 24;  // paper between the lines
  cv::Mat img(rows, spacing * (kReferenceLines + 1), CV_8UC1, cv::Scalar(255));
  cv::RNG rng(seed);
  // Bell-shaped fall-off (figure 2): a Gaussian across the line, scaled so that the tone is the
  // centre's at the centre and edge_grey at the half width.
  const double sigma = half / 1.6;
  const double bell_edge = std::exp(-half * half / (2.0 * sigma * sigma));
  // Paper tooth: unit-variance AR(1) along each column; rho gives correlation length tooth_px.
  const double rho = std::exp(-1.0 / m.tooth_px), innovation = std::sqrt(1.0 - rho * rho);
  const double paper_z = upper_quantile(m.grain);
  // Pressure: slow AR(1) (correlation ~25 px) mapped onto [centre_lo, centre_hi].
  const double rho_p = std::exp(-1.0 / 25.0), innovation_p = std::sqrt(1.0 - rho_p * rho_p);
  std::vector<double> tooth(static_cast<size_t>(img.cols));
  for (int line = 0; line < kReferenceLines; ++line) {
    const double base = spacing * (line + 1);
    const int x0 = static_cast<int>(std::floor(base - half - 1)), x1 = static_cast<int>(std::ceil(base + half + 1));
    for (int x = x0; x <= x1; ++x) tooth[x] = rng.gaussian(1.0);
    double wander = 0.0, pressure = rng.gaussian(1.0);
    for (int y = 0; y < rows; ++y) {
      wander = std::clamp(wander + rng.uniform(-0.15, 0.15), -0.5, 0.5);
      pressure = rho_p * pressure + innovation_p * rng.gaussian(1.0);
      const double u = std::clamp(0.5 + 0.25 * pressure, 0.0, 1.0);
      const double centre = m.centre_lo + u * (m.centre_hi - m.centre_lo);
      std::uint8_t* row = img.ptr<std::uint8_t>(y);
      for (int x = x0; x <= x1; ++x) {
        tooth[x] = rho * tooth[x] + innovation * rng.gaussian(1.0);
        const double k = x - (base + wander);
        if (std::abs(k) > half) continue;
        const double fall = (1.0 - std::exp(-k * k / (2.0 * sigma * sigma))) / (1.0 - bell_edge);
        double v = centre + fall * (m.edge_grey - centre) + m.grain_amp * tooth[x];
        // Where the tooth is highest the graphite skipped the paper's valleys: lighter, up to
        // paper white.
        const double through = std::clamp((tooth[x] - paper_z) / 0.7, 0.0, 1.0);
        v += through * 0.9 * (252.0 - v);
        row[x] = static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 255.0)));
      }
    }
  }
  return img;
}

}  // namespace atelier::pencil

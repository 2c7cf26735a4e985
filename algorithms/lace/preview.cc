#include "algorithms/lace/preview.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <opencv2/imgproc.hpp>

namespace atelier::lace {
namespace {

constexpr int kShift = 4;  // fillPoly fractional bits: sub-pixel outlines
constexpr double kRelax = 0.65; // how far each course moves toward even spacing
constexpr double kLean = 0.6;   // a decrease's top is this many stitch widths right (k2tog) of its bottom

cv::Scalar scaled(const cv::Vec3b& c, double f) {
  return cv::Scalar(std::min(255.0, c[0] * f), std::min(255.0, c[1] * f), std::min(255.0, c[2] * f));
}

// An ellipse (centre (cx, cy), semi-axes a along `angle` from vertical, b across) in a stitch's
// local frame (pixels, y down), sheared by `lean` (x += lean * -y: the top moves right for
// lean > 0), placed at `at`.
std::vector<cv::Point> leg(double cx, double cy, double a, double b, double angle, double lean,
                           cv::Point2d at) {
  std::vector<cv::Point> pts;
  const double ux = std::sin(angle), uy = -std::cos(angle);  // major axis, pointing up
  const double vx = -uy, vy = ux;
  for (int i = 0; i < 28; ++i) {
    const double t = 2 * std::numbers::pi * i / 28;
    const double x = cx + a * std::cos(t) * ux + b * std::sin(t) * vx;
    const double y = cy + a * std::cos(t) * uy + b * std::sin(t) * vy;
    const double sx = x + lean * -y;
    pts.emplace_back(cvRound((at.x + sx) * (1 << kShift)), cvRound((at.y + y) * (1 << kShift)));
  }
  return pts;
}

void fill(cv::Mat& img, const std::vector<cv::Point>& pts, const cv::Scalar& colour) {
  const cv::Point* p = pts.data();
  const int n = static_cast<int>(pts.size());
  cv::fillPoly(img, &p, &n, 1, colour, cv::LINE_AA, kShift);
}

// A shaded loop: a darker rim, the yarn body, a light highlight toward the top left.
void shaded_loop(cv::Mat& img, double cx, double cy, double a, double b, double angle, double lean,
                 cv::Point2d at, const cv::Vec3b& yarn) {
  fill(img, leg(cx, cy, a, b, angle, lean, at), scaled(yarn, 0.55));
  fill(img, leg(cx, cy, a * 0.86, b * 0.7, angle, lean, at), scaled(yarn, 0.85));
  fill(img, leg(cx - b * 0.15, cy - a * 0.1, a * 0.6, b * 0.35, angle, lean, at), scaled(yarn, 1.0));
}

// A knit "V" of width w and height h centred at `at`: two slanted loops meeting at the bottom.
void knit_v(cv::Mat& img, cv::Point2d at, double w, double h, double lean, const cv::Vec3b& yarn) {
  const double a = 0.5 * h, b = 0.25 * w;
  const double tilt = std::atan2(0.3 * w, h);  // legs splay: tops apart, bottoms together
  shaded_loop(img, -0.2 * w, 0, a, b, -tilt, lean, at, yarn);
  shaded_loop(img, 0.2 * w, 0, a, b, tilt, lean, at, yarn);
}

int tiles_high(const Chart& chart, int cast_on, const PreviewOptions& o) {
  return produced(chart.rows.back()) == cast_on ? o.repeats_y : 1;
}

}  // namespace

PreviewLayout layout_preview(const Chart& chart, int cast_on, const PreviewOptions& o) {
  if (const Knittability k = knittable(chart, cast_on); !k)
    throw std::invalid_argument("lace preview: " + k.why);
  if (o.repeats_x < 1 || o.repeats_y < 1 || o.repeats_x > 64 || o.repeats_y > 64)
    throw std::invalid_argument("lace preview: repeats must be 1-64");
  if (o.stitch_px < 4 || o.stitch_px > 200)
    throw std::invalid_argument("lace preview: stitch_px must be 4-200");

  PreviewLayout out;
  out.tiles_y = tiles_high(chart, cast_on, o);
  out.row_px = std::max(3, static_cast<int>(std::lround(0.8 * o.stitch_px)));
  const int total = cast_on * o.repeats_x;  // cast-on stitches across the picture
  const int courses = 2 * static_cast<int>(chart.rows.size()) * out.tiles_y;
  out.size = cv::Size(total * o.stitch_px, courses * out.row_px);

  // Positions in stitch units measured from the right edge (knitting order runs leftwards).
  std::vector<double> below(static_cast<std::size_t>(total));
  for (int i = 0; i < total; ++i) below[static_cast<std::size_t>(i)] = i + 0.5;
  auto relax = [total](std::vector<double>& xs) {
    const double step = static_cast<double>(total) / static_cast<double>(xs.size());
    for (std::size_t j = 0; j < xs.size(); ++j)
      xs[j] = (1 - kRelax) * xs[j] + kRelax * (static_cast<double>(j) + 0.5) * step;
  };
  auto place = [&](const std::vector<double>& xs, const Row& row, int chart_row) {
    const int c = static_cast<int>(out.courses.size());
    const double y = out.size.height - (c + 0.5) * out.row_px;
    std::vector<PlacedStitch> course;
    for (std::size_t j = 0; j < xs.size(); ++j) {
      course.push_back({row[j], cv::Point2d(out.size.width - xs[j] * o.stitch_px, y), chart_row,
                        static_cast<int>(j)});
    }
    out.courses.push_back(std::move(course));
  };

  for (int t = 0; t < out.tiles_y; ++t) {
    for (std::size_t r = 0; r < chart.rows.size(); ++r) {
      Row row;
      for (int k = 0; k < o.repeats_x; ++k) row.insert(row.end(), chart.rows[r].begin(), chart.rows[r].end());
      std::vector<double> xs(row.size());
      std::size_t p = 0;  // next stitch of the row below
      for (std::size_t j = 0; j < row.size();) {
        if (row[j] != Symbol::yo) {
          const int n = consumes(row[j]);
          double sum = 0;
          for (int i = 0; i < n; ++i) sum += below[p + static_cast<std::size_t>(i)];
          xs[j++] = sum / n;
          p += static_cast<std::size_t>(n);
          continue;
        }
        // A run of yarn-overs spreads evenly between the stitches either side of it.
        std::size_t end = j;
        while (end < row.size() && row[end] == Symbol::yo) ++end;
        const double left = p > 0 ? below[p - 1] : below.front() - 1;
        const double right = p < below.size() ? below[p] : below.back() + 1;
        const double m = static_cast<double>(end - j);
        for (std::size_t i = j; i < end; ++i)
          xs[i] = left + (right - left) * (static_cast<double>(i - j) + 1) / (m + 1);
        j = end;
      }
      relax(xs);
      place(xs, row, static_cast<int>(r));
      relax(xs);  // the purl row above: one plain stitch over each
      place(xs, Row(xs.size(), Symbol::k), -1);
      below = xs;
    }
  }
  return out;
}

cv::Mat render_preview(const Chart& chart, int cast_on, const PreviewOptions& o) {
  const PreviewLayout layout = layout_preview(chart, cast_on, o);
  try {
    cv::Mat img(layout.size, CV_8UC3, cv::Scalar(o.background[0], o.background[1], o.background[2]));
    const double w = o.stitch_px, h = 1.45 * layout.row_px;
    // Bottom course first: each stitch lies over the loops of the one below it. The decreases'
    // top stitches and the double decrease's spine lie over everything around them: drawn after.
    struct Overlay {
      cv::Point2d at;
      double sw;
      Symbol symbol;
    };
    std::vector<Overlay> overlays;
    for (const auto& course : layout.courses) {
      for (std::size_t j = 0; j < course.size(); ++j) {
        const PlacedStitch& s = course[j];
        if (s.symbol == Symbol::yo) continue;
        // The stitch is as wide as the room its neighbours leave (fabric stretches).
        double gap = 0;
        int n = 0;
        if (j > 0) gap += std::abs(course[j - 1].centre.x - s.centre.x), ++n;
        if (j + 1 < course.size()) gap += std::abs(course[j + 1].centre.x - s.centre.x), ++n;
        const double sw = std::clamp(n > 0 ? gap / n : w, 0.75 * w, 1.6 * w);
        const cv::Point2d at(s.centre.x, s.centre.y - 0.15 * layout.row_px);
        // The top moves right for a right-leaning stitch (k2tog), left for ssk and sk2p.
        const double lean = lace::lean(s.symbol) * kLean * sw / h;
        knit_v(img, at, sw, h, lean, o.yarn);
        if (s.symbol != Symbol::k) overlays.push_back({at, sw, s.symbol});
      }
    }
    for (const Overlay& v : overlays) {
      if (lace::lean(v.symbol) == 0) {  // s2kp: the centre stitch standing up over the other two
        shaded_loop(img, 0, -0.05 * h, 0.6 * h, 0.15 * v.sw, 0.0, 0.0, v.at, o.yarn);
      } else {  // the stitch lying on top, slanting the way the decrease leans
        const double slant = std::atan2(kLean * v.sw, h) * lace::lean(v.symbol);
        shaded_loop(img, 0, -0.05 * h, 0.62 * h, 0.2 * v.sw, slant, 0.0, v.at, o.yarn);
      }
    }
    // Holes last: nothing of the neighbours' loops covers a yarn-over's opening.
    const cv::Scalar bg(o.background[0], o.background[1], o.background[2]);
    for (const auto& course : layout.courses) {
      for (const PlacedStitch& s : course) {
        if (s.symbol != Symbol::yo) continue;
        const cv::Point c(cvRound(s.centre.x * (1 << kShift)),
                          cvRound((s.centre.y - 0.2 * layout.row_px) * (1 << kShift)));
        const cv::Size axes(cvRound(0.36 * w * (1 << kShift)), cvRound(0.62 * layout.row_px * (1 << kShift)));
        const int ring = std::max(1, cvRound(w / 12.0));
        cv::ellipse(img, c, axes, 0, 0, 360, scaled(o.yarn, 0.8), ring + 2, cv::LINE_AA, kShift);
        cv::ellipse(img, c, axes, 0, 0, 360, bg, cv::FILLED, cv::LINE_AA, kShift);
        cv::ellipse(img, c, axes, 0, 0, 360, scaled(o.yarn, 0.9), ring, cv::LINE_AA, kShift);
      }
    }
    return img;
  } catch (const cv::Exception& e) {
    throw std::runtime_error(std::string("lace preview: ") + e.what());
  }
}

}  // namespace atelier::lace

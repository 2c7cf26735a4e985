#include "convert/knit/knit_knitout.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace atelier {
namespace {

void pass(std::ostringstream& out, const std::string& op, char dir, int width, int carrier,
          const unsigned char* row) {
  for (int i = 0; i < width; ++i) {
    int c = dir == '+' ? i : width - 1 - i;  // column, left to right for '+'
    bool own = row == nullptr || (row[c] != 0) == (carrier == 2);
    out << (own ? op : "miss") << ' ' << dir << " f" << (c + 1) << ' ' << carrier << '\n';
  }
}

// One-line comment text: a line break would start a line of operations.
std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

// Chain bind-off of the `width` front needles with `carrier`, working in direction `dir`
// (the side the carrier is on): knit a needle, move its loop onto the next needle (via the
// back bed, rack +-1), knit that one, ... then a 4-stitch tail on the last needle, dropped
// once the yarn is out. Bounded: width - 1 steps.
void bind_off(std::ostringstream& out, int width, char dir, int carrier) {
  out << "; bind-off (chain, with carrier " << carrier << ")\n";
  const int step = dir == '+' ? 1 : -1;
  int n = dir == '+' ? 1 : width;
  for (int i = 0; i + 1 < width; ++i, n += step) {
    out << "knit " << dir << " f" << n << ' ' << carrier << '\n'
        << "xfer f" << n << " b" << n << '\n'
        << "rack " << step << '\n'  // at rack R, f(x) faces b(x - R): b(n) faces f(n + step)
        << "xfer b" << n << " f" << (n + step) << '\n'
        << "rack 0\n";
  }
  const char back = dir == '+' ? '-' : '+';
  for (int t = 0; t < 4; ++t) out << "knit " << (t % 2 == 0 ? dir : back) << " f" << n << ' ' << carrier << '\n';
  out << "outhook " << carrier << '\n' << "drop f" << n << '\n';
}

}  // namespace

int knitout_gauge(double stitches_per_10cm) {
  return std::max(1, static_cast<int>(std::lround(stitches_per_10cm * 2.54 / 10.0)));
}

int knitout_longest_float(const cv::Mat& grid) {
  CV_Assert(grid.type() == CV_8UC1);
  int longest = 0;
  for (int y = 0; y < grid.rows; ++y) {
    const unsigned char* row = grid.ptr<unsigned char>(y);
    for (int x = 0, run = 0; x < grid.cols; ++x) {
      run = (x > 0 && (row[x] != 0) == (row[x - 1] != 0)) ? run + 1 : 1;
      longest = std::max(longest, run);
    }
  }
  return longest;
}

std::string make_knitout(const cv::Mat& grid, const KnitoutOptions& options) {
  CV_Assert(grid.type() == CV_8UC1);
  const int width = grid.cols, rows = grid.rows;
  std::ostringstream out;
  out << ";!knitout-2\n"
      << ";;Machine: " << kKnitoutMachine << "\n"
      << ";;Gauge: " << knitout_gauge(options.stitches_per_10cm) << "\n"
      << ";;Carriers: 1 2\n";
  if (!options.not_knittable.empty()) out << "; NOT KNITTABLE AS IS: " << one_line(options.not_knittable) << "\n";
  for (const std::string& note : options.notes) out << "; NOTE: " << one_line(note) << "\n";
  out << "; " << one_line(options.title) << "\n"
      << "; Fair Isle, " << width << " stitches x " << rows
      << " rows; carrier 1 = background yarn, carrier 2 = contrast yarn\n"
      << "; needle f1 = leftmost stitch seen on the right side; row 1 = "
      << (options.first_row_top ? "top of the picture (knitted top-down)" : "bottom of the picture")
      << "\n";

  // Cast-on with the background yarn: tuck every other needle leftwards, the rest rightwards,
  // then two plain rows before the yarn-inserting hook lets go.
  out << "inhook 1\n";
  for (int c = width - 1; c >= 0; c -= 2) out << "tuck - f" << (c + 1) << " 1\n";
  for (int c = (width % 2 == 0) ? 0 : 1; c < width; c += 2) out << "tuck + f" << (c + 1) << " 1\n";
  out << "; plain rows\n";
  pass(out, "knit", '-', width, 1, nullptr);
  out << "releasehook 1\n";
  pass(out, "knit", '+', width, 1, nullptr);

  // Both carriers are now on the right: the first pattern row goes leftwards.
  out << "inhook 2\n";
  char dir = '-';
  for (int n = 1; n <= rows; ++n) {
    const unsigned char* row = grid.ptr<unsigned char>(options.first_row_top ? n - 1 : rows - n);
    out << "; row " << n << "\n";
    pass(out, "knit", dir, width, 1, row);
    pass(out, "knit", dir, width, 2, row);
    if (n == 1) out << "releasehook 2\n";
    dir = dir == '-' ? '+' : '-';
  }
  // Both carriers are on the side `dir` starts from: the contrast yarn leaves, the background
  // yarn binds off.
  out << "outhook 2\n";
  bind_off(out, width, dir, 1);
  return out.str();
}

}  // namespace atelier

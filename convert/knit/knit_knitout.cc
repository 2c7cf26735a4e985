#include "convert/knit/knit_knitout.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "convert/common/knitout_header.h"

namespace atelier {
namespace {

// The needles of one pass in the order the carrier meets them: c = 0..width-1 (needle c+1),
// left to right for '+'. `row` null: every needle (the plain rows); else the needles whose
// stitch is the carrier's colour (carrier 2 = contrast = 1).
template <typename F>
void for_each_own(char dir, int width, int carrier, const unsigned char* row, F&& f) {
  for (int i = 0; i < width; ++i) {
    const int c = dir == '+' ? i : width - 1 - i;
    if (row == nullptr || (row[c] != 0) == (carrier == 2)) f(c);
  }
}

// One carrier's knits of a row. No `miss`: the carrier moves on to its next stitch by itself
// (knitout), and the yarn runs behind the other colour's stitches only where it must.
void pass(std::ostringstream& out, const std::string& op, char dir, int width, int carrier,
          const unsigned char* row) {
  for_each_own(dir, width, carrier, row,
               [&](int c) { out << op << ' ' << dir << " f" << (c + 1) << ' ' << carrier << '\n'; });
}

// The pattern rows in knitting order: grid row of pattern row n (1-based) and its direction
// (row 1 goes leftwards, as both carriers start on the right).
int grid_row(const cv::Mat& grid, bool first_row_top, int n) { return first_row_top ? n - 1 : grid.rows - n; }
char row_dir(int n) { return n % 2 == 1 ? '-' : '+'; }

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

int knitout_longest_float(const cv::Mat& grid, bool first_row_top) {
  CV_Assert(grid.type() == CV_8UC1);
  const int width = grid.cols;
  // Each carrier's previous stitch (column); carrier 1 ends the plain rows on the right,
  // carrier 2 starts at its first stitch.
  int prev[3] = {0, width - 1, -1};
  int longest = 0;
  auto stitch = [&](int carrier, int c) {
    if (prev[carrier] >= 0) longest = std::max(longest, std::abs(c - prev[carrier]) - 1);
    prev[carrier] = c;
  };
  for (int n = 1; n <= grid.rows; ++n) {
    const unsigned char* row = grid.ptr<unsigned char>(grid_row(grid, first_row_top, n));
    for (int carrier : {1, 2}) for_each_own(row_dir(n), width, carrier, row, [&](int c) { stitch(carrier, c); });
  }
  stitch(1, row_dir(grid.rows + 1) == '+' ? 0 : width - 1);  // the bind-off's first stitch
  return longest;
}

std::string make_knitout(const cv::Mat& grid, const KnitoutOptions& options) {
  CV_Assert(grid.type() == CV_8UC1);
  const int width = grid.cols, rows = grid.rows;
  std::ostringstream out;
  out << knitout_header(options.stitches_per_10cm);
  if (!options.not_knittable.empty()) out << "; NOT KNITTABLE AS IS: " << one_line(options.not_knittable) << "\n";
  for (const std::string& note : options.notes) out << "; NOTE: " << one_line(note) << "\n";
  out << "; " << one_line(options.title) << "\n"
      << "; carriers used: 1 2\n"
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

  // Carrier 1 is now on the right: the first pattern row goes leftwards. Carrier 2 comes in
  // just before its first stitch (the yarn-inserting hook blocks the needles beside it until
  // released, so it must not be in while carrier 1 knits there).
  bool carrier2_in = false;
  for (int n = 1; n <= rows; ++n) {
    const char dir = row_dir(n);
    const unsigned char* row = grid.ptr<unsigned char>(grid_row(grid, options.first_row_top, n));
    out << "; row " << n << "\n";
    pass(out, "knit", dir, width, 1, row);
    const bool contrast = std::any_of(row, row + width, [](unsigned char v) { return v != 0; });
    if (contrast && !carrier2_in) out << "inhook 2\n";
    pass(out, "knit", dir, width, 2, row);
    if (contrast && !carrier2_in) out << "releasehook 2\n";
    carrier2_in = carrier2_in || contrast;
  }
  const char dir = row_dir(rows + 1);
  // Both carriers are on the side `dir` starts from: the contrast yarn leaves, the background
  // yarn binds off.
  if (carrier2_in) out << "outhook 2\n";
  bind_off(out, width, dir, 1);
  return out.str();
}

}  // namespace atelier

#include "convert/knit/knit_knitout.h"

#include <cstdio>
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

}  // namespace

std::string make_knitout(const cv::Mat& grid, const KnitoutOptions& options) {
  CV_Assert(grid.type() == CV_8UC1);
  const int width = grid.cols, rows = grid.rows;
  std::ostringstream out;
  char gauge[32];
  std::snprintf(gauge, sizeof gauge, "%.1f", options.stitches_per_10cm * 2.54 / 10.0);
  out << ";!knitout-2\n"
      << ";;Machine: generic two-carrier flat knitting machine\n"
      << ";;Gauge: " << gauge << "\n"
      << ";;Carriers: 1 2\n"
      << "; " << options.title << "\n"
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
  out << "; end of pattern: the work stays on the needles for binding off or waste yarn\n"
      << "outhook 2\n"
      << "outhook 1\n";
  return out.str();
}

}  // namespace atelier

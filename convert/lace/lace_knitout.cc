#include "convert/lace/lace_knitout.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <sstream>
#include <stdexcept>

#include "algorithms/lace/transfers.h"
#include "convert/common/knitout_header.h"

namespace atelier {
namespace {

constexpr int kMaxRack = 4;

// Needles of both beds: which hold loops (the writer's own bookkeeping, to route transfers
// over empty needles only).
struct Beds {
  int needles = 0;                  // 1..needles
  std::vector<char> front, back;    // occupied, index = needle
  std::vector<char>& bed(bool is_front) { return is_front ? front : back; }
};

class Writer {
 public:
  Writer(std::ostringstream& out, int needles) : out_(out) {
    beds_.needles = needles;
    beds_.front.assign(static_cast<size_t>(needles + 1), 0);
    beds_.back.assign(static_cast<size_t>(needles + 1), 0);
  }

  void rack(int r) {
    if (r == rack_) return;
    out_ << "rack " << r << "\n";
    rack_ = r;
  }
  // Moves the loops of one needle to the other bed across from `to`.
  void xfer(bool from_front, int from, int to) {
    rack(from_front ? from - to : to - from);  // at rack R, f.x faces b.(x - R)
    out_ << "xfer " << (from_front ? 'f' : 'b') << from << ' ' << (from_front ? 'b' : 'f') << to << "\n";
    beds_.bed(from_front)[static_cast<size_t>(from)] = 0;
    beds_.bed(!from_front)[static_cast<size_t>(to)] = 1;
  }
  // From back needle `from` to front needle `to` in hops over empty needles (|rack| <= 4 each),
  // landing on `to` whatever it holds (the stitch's own decrease). Breadth-first: fewest hops.
  void route(int from, int to) {
    const int n = beds_.needles;
    auto key = [&](bool front, int x) { return (front ? 1 : 0) * (n + 1) + x; };
    std::vector<int> prev(static_cast<size_t>(2 * (n + 1)), -1);
    std::deque<int> open{key(false, from)};
    prev[static_cast<size_t>(key(false, from))] = key(false, from);
    const int goal = key(true, to);
    while (!open.empty() && prev[static_cast<size_t>(goal)] < 0) {
      const int k = open.front();
      open.pop_front();
      const bool front = k > n;
      const int x = k - (front ? n + 1 : 0);
      for (int d = -kMaxRack; d <= kMaxRack; ++d) {
        const int y = x + d;
        if (y < 1 || y > n) continue;
        const int next = key(!front, y);
        if (prev[static_cast<size_t>(next)] >= 0) continue;
        if (next != goal && beds_.bed(!front)[static_cast<size_t>(y)]) continue;
        prev[static_cast<size_t>(next)] = k;
        open.push_back(next);
      }
    }
    if (prev[static_cast<size_t>(goal)] < 0)
      throw std::logic_error("lace knitout: no free path for the stitch on b" + std::to_string(from) + " to f" +
                             std::to_string(to));
    std::vector<int> path;
    for (int k = goal; k != key(false, from); k = prev[static_cast<size_t>(k)]) path.push_back(k);
    std::reverse(path.begin(), path.end());
    bool front = false;
    int x = from;
    for (int k : path) {
      const int y = k - (front ? 0 : n + 1);
      xfer(front, x, y);
      front = !front;
      x = y;
    }
  }
  void knit_pass(char dir, int lo, int hi) {
    for (int i = 0; i <= hi - lo; ++i) {
      const int x = dir == '-' ? hi - i : lo + i;
      out_ << "knit " << dir << " f" << x << " 1\n";
      beds_.front[static_cast<size_t>(x)] = 1;
    }
  }

 private:
  std::ostringstream& out_;
  Beds beds_;
  int rack_ = 0;
};

// The transfers of one row: stitch s of the row below on f(right - s) goes to f(right - o).
// Grouped passes (schedule_vbed_row: to the back, far stitches shuttled a racking at a time,
// then home one pass per racking); a row it cannot schedule is routed stitch by stitch.
void transfer_row_routed(Writer& w, const lace::RowTransfers& t, int right);
void transfer_row(Writer& w, const lace::RowTransfers& t, int right) {
  const lace::VbedRowSchedule plan = lace::schedule_vbed_row(t, kMaxRack);
  if (!plan.ok) return transfer_row_routed(w, t, right);
  // The needle each stitch is on (a far stitch crosses the gap more than once).
  std::vector<int> at(static_cast<size_t>(t.consumed), 0);
  for (int s = 0; s < t.consumed; ++s) at[static_cast<size_t>(s)] = right - s;
  for (const lace::VbedPass& pass : plan.passes)
    for (int s : pass.stitches) {
      int& x = at[static_cast<size_t>(s)];
      // At rack R, f(x) faces b(x - R): racks to pass.rack.
      const int to = pass.to_back ? x - pass.rack : x + pass.rack;
      w.xfer(pass.to_back, x, to);
      x = to;
    }
  w.rack(0);
}

void transfer_row_routed(Writer& w, const lace::RowTransfers& t, int right) {
  std::vector<int> moving;  // consumed stitches that leave their needle for a while
  for (int s = 0; s < t.consumed; ++s) {
    const int o = t.target[static_cast<size_t>(s)];
    if (o != s || t.stack[static_cast<size_t>(o)].size() > 1) moving.push_back(s);
  }
  if (moving.empty()) return;
  for (int s : moving) w.xfer(true, right - s, right - s);
  // Back to the front in two queues that never get in each other's way: stitches heading
  // right (in needle numbers) by target from the right end, those heading left by target from
  // the left end, so a stitch in transit only ever passes empty needles or its own decrease.
  // A stitch goes only once the ones it must lie on are home (those that stay above their own
  // needle, rack 0, as soon as that is so).
  std::vector<int> rightwards, leftwards, staying;
  std::vector<int> home(static_cast<size_t>(t.produced), 0);  // loops back on each target
  auto from = [&](int s) { return right - s; };
  auto to = [&](int s) { return right - t.target[static_cast<size_t>(s)]; };
  auto place = [&](int s) {
    w.route(from(s), to(s));
    ++home[static_cast<size_t>(t.target[static_cast<size_t>(s)])];
  };
  for (int s : moving) {
    (to(s) == from(s) ? staying : to(s) > from(s) ? rightwards : leftwards).push_back(s);
  }
  std::stable_sort(rightwards.begin(), rightwards.end(), [&](int a, int b) {
    return to(a) != to(b) ? to(a) > to(b) : t.layer[static_cast<size_t>(a)] < t.layer[static_cast<size_t>(b)];
  });
  std::stable_sort(leftwards.begin(), leftwards.end(), [&](int a, int b) {
    return to(a) != to(b) ? to(a) < to(b) : t.layer[static_cast<size_t>(a)] < t.layer[static_cast<size_t>(b)];
  });
  auto ready = [&](int s) {
    return home[static_cast<size_t>(t.target[static_cast<size_t>(s)])] == t.layer[static_cast<size_t>(s)];
  };
  size_t r = 0, l = 0;
  while (r < rightwards.size() || l < leftwards.size() || !staying.empty()) {
    auto stay = std::find_if(staying.begin(), staying.end(), ready);
    if (stay != staying.end()) {
      place(*stay);
      staying.erase(stay);
    } else if (r < rightwards.size() && ready(rightwards[r])) {
      place(rightwards[r++]);
    } else if (l < leftwards.size() && ready(leftwards[l])) {
      place(leftwards[l++]);
    } else {
      throw std::logic_error("lace knitout: the stacking order of a decrease cannot be met");
    }
  }
  w.rack(0);
}

// The title as one comment line: a line break in it (a job file's name may hold one) would
// start a line of knitout operations.
std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

}  // namespace

std::string make_lace_knitout(const lace::Chart& chart, int cast_on, const LaceKnitoutOptions& o) {
  if (o.repeats_wide < 1 || o.repeats_high < 1)
    throw std::invalid_argument("lace knitout: repeats_wide and repeats_high must be at least 1");
  if (const lace::Knittability k = lace::knittable(chart, cast_on); !k)
    throw std::invalid_argument("lace knitout: " + k.why);
  if (o.repeats_high > 1 && lace::produced(chart.rows.back()) != cast_on)
    throw std::invalid_argument("lace knitout: the chart ends " + std::to_string(lace::produced(chart.rows.back())) +
                                " stitches wide but starts from " + std::to_string(cast_on) +
                                ", so it cannot be repeated on top of itself");

  std::vector<lace::RowTransfers> rows;
  int widest = cast_on * o.repeats_wide;
  for (const lace::Row& r : chart.rows) {
    rows.push_back(lace::row_transfers(lace::tile_row(r, o.repeats_wide)));
    widest = std::max(widest, rows.back().produced);
  }
  // A margin on both sides for transfers that hop around occupied needles.
  const int right = widest + kMaxRack;
  const int needles = right + kMaxRack;

  std::ostringstream out;
  const int start_width = cast_on * o.repeats_wide;
  // The knitout spec's headers only; the needle count the writer uses is a plain comment.
  out << knitout_header(o.stitches_per_10cm) << "; carriers used: 1\n"
      << "; " << one_line(o.title) << "\n"
      << "; lace, " << chart.rows.size() << " chart rows x " << o.repeats_high << ", " << cast_on
      << " stitches x " << o.repeats_wide << " repeats; stitches on the front bed, lace by transfers\n"
      << "; needle f" << right << " = first stitch of each right-side row (its right edge); needles f1 to f"
      << needles << " used\n";

  Writer w(out, needles);
  const int lo0 = right - start_width + 1;
  out << "inhook 1\n";
  for (int x = right; x >= lo0; x -= 2) out << "tuck - f" << x << " 1\n";
  for (int x = (start_width % 2 == 0) ? lo0 : lo0 + 1; x <= right; x += 2) out << "tuck + f" << x << " 1\n";
  out << "; plain rows\n";
  w.knit_pass('-', lo0, right);
  out << "releasehook 1\n";
  w.knit_pass('+', lo0, right);

  int n = 0;
  for (int v = 0; v < o.repeats_high; ++v) {
    for (const lace::RowTransfers& t : rows) {
      ++n;
      out << "; row " << n << "\n";
      transfer_row(w, t, right);
      const int lo = right - t.produced + 1;
      w.knit_pass('-', lo, right);
      w.knit_pass('+', lo, right);
    }
  }
  // Chain bind-off leftwards from the right edge (the carrier is there after the wrong-side
  // row): knit a needle, move its loop to the next needle on the left, knit that one; a short
  // tail on the last needle, dropped once the yarn is out.
  const int lo = right - (rows.empty() ? start_width : rows.back().produced) + 1;
  out << "; bind-off (chain, leftwards)\n";
  for (int x = right; x > lo; --x) {
    out << "knit - f" << x << " 1\n";
    w.xfer(true, x, x);
    w.xfer(false, x, x - 1);
    w.rack(0);
  }
  for (int t = 0; t < 4; ++t) out << "knit " << (t % 2 == 0 ? '-' : '+') << " f" << lo << " 1\n";
  out << "outhook 1\n"
      << "drop f" << lo << "\n";
  return out.str();
}

}  // namespace atelier

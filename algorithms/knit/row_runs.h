// Internal helper for the knit library: runs of equal stitches in one row.
//
// A run is a maximal sequence of equal, non-relaxed stitches; relaxed stitches split runs and
// belong to none. With anchoring off, a run touching the first or last stitch of the row is
// "free": it never violates. Pure, header-only, no state.
#pragma once

#include <cstdint>

namespace atelier::knit::detail {

// One row of the grid as seen by the float constraint. Pointers are borrowed from the grid
// and the relax mask (relax may be null); width is the row length in stitches.
struct RowView {
  uint8_t* cells;
  const uint8_t* relax;
  int width;
  int max_float;
  bool anchoring;

  bool relaxed(int x) const { return relax != nullptr && relax[x] != 0; }

  // Violated windows of a run [start, start + length): max(0, length - f), 0 when free.
  long run_violations(int start, int length) const {
    if (length <= max_float) return 0;
    if (!anchoring && (start == 0 || start + length == width)) return 0;
    return length - max_float;
  }

  // First column of the run containing non-relaxed stitch x.
  int run_start(int x) const {
    const uint8_t c = cells[x];
    while (x > 0 && !relaxed(x - 1) && cells[x - 1] == c) --x;
    return x;
  }
  // Last column of the run containing non-relaxed stitch x.
  int run_end(int x) const {
    const uint8_t c = cells[x];
    while (x + 1 < width && !relaxed(x + 1) && cells[x + 1] == c) ++x;
    return x;
  }

  // Calls fn(start, length) for every run of the row, left to right.
  template <class Fn>
  void for_each_run(Fn&& fn) const {
    for_each_run_in(0, width - 1, fn);
  }

  // Same for the runs within [first, last], which must begin and end on run boundaries.
  template <class Fn>
  void for_each_run_in(int first, int last, Fn&& fn) const {
    int x = first;
    while (x <= last) {
      if (relaxed(x)) {
        ++x;
        continue;
      }
      const int end = run_end(x);
      fn(x, end - x + 1);
      x = end + 1;
    }
  }

  // Change in the row's violation count if non-relaxed stitch x were flipped (negative =
  // repairs). Looks only at the run holding x and the runs it would merge with.
  long flip_delta(int x) const {
    const int s = run_start(x), e = run_end(x);
    const int ls = (x == s && x > 0 && !relaxed(x - 1)) ? run_start(x - 1) : x;
    const int re = (x == e && x + 1 < width && !relaxed(x + 1)) ? run_end(x + 1) : x;
    return flip_delta(x, s, e, ls, re);
  }

  // Same, with the extents already known: x lies in run [s, e]; when x == s, ls is the start
  // of the run on its left that it would join (ls == x if none); when x == e, re is the end
  // of the run on its right (re == x if none).
  long flip_delta(int x, int s, int e, int ls, int re) const {
    const long before_run = run_violations(s, e - s + 1);
    if (x != s && x != e) {  // interior: the run splits, the flipped stitch stands alone
      return run_violations(s, x - s) + run_violations(x + 1, e - x) - before_run;
    }
    // An end stitch joins the neighbouring run(s) of the other colour.
    long before = before_run;
    if (ls < x) before += run_violations(ls, x - ls);
    if (re > x) before += run_violations(x + 1, re - x);
    long after = run_violations(ls, re - ls + 1);  // the merged run of the other colour
    if (s != e) after += (x == s) ? run_violations(s + 1, e - s) : run_violations(s, e - s);
    return after - before;
  }
};

}  // namespace atelier::knit::detail

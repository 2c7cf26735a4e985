#include "algorithms/knit/floats.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "algorithms/knit/problem.h"

namespace atelier::knit {
namespace detail {

void check_problem(const cv::Mat& grid, const FloatRules& rules, const char* who) {
  const std::string w(who);
  if (grid.empty()) throw std::invalid_argument(w + ": the stitch grid is empty");
  if (grid.type() != CV_8UC1)
    throw std::invalid_argument(w + ": the stitch grid must be CV_8UC1 (one byte per stitch)");
  double max_value = 0;
  cv::minMaxLoc(grid, nullptr, &max_value);
  if (max_value > 1)
    throw std::invalid_argument(w + ": the stitch grid must hold only 0 and 1, found " +
                                std::to_string(static_cast<int>(max_value)));
  if (rules.max_float < 2)
    throw std::invalid_argument(w + ": max_float must be at least 2, got " +
                                std::to_string(rules.max_float));
  if (!rules.relax.empty() && (rules.relax.type() != CV_8UC1 || rules.relax.size() != grid.size()))
    throw std::invalid_argument(w + ": the relax mask must be CV_8UC1 of the grid's size (" +
                                std::to_string(grid.cols) + "x" + std::to_string(grid.rows) + ")");
}

}  // namespace detail

namespace {
long row_violations(const detail::RowView& r) {
  long total = 0;
  r.for_each_run([&](int s, int len) { total += r.run_violations(s, len); });
  return total;
}
}  // namespace

long count_row_violations(const cv::Mat& grid, int row, const FloatRules& rules) {
  detail::check_problem(grid, rules, "count_row_violations");
  if (row < 0 || row >= grid.rows)
    throw std::invalid_argument("count_row_violations: row " + std::to_string(row) +
                                " is outside the grid");
  return row_violations(detail::row_view(grid, rules, row));
}

long count_violations(const cv::Mat& grid, const FloatRules& rules) {
  detail::check_problem(grid, rules, "count_violations");
  long total = 0;
  for (int y = 0; y < grid.rows; ++y) total += row_violations(detail::row_view(grid, rules, y));
  return total;
}

std::vector<Run> violating_runs(const cv::Mat& grid, const FloatRules& rules) {
  detail::check_problem(grid, rules, "violating_runs");
  std::vector<Run> runs;
  for (int y = 0; y < grid.rows; ++y) {
    const detail::RowView r = detail::row_view(grid, rules, y);
    r.for_each_run([&](int s, int len) {
      if (r.run_violations(s, len) > 0) runs.push_back(Run{y, s, len});
    });
  }
  return runs;
}

long consistent_stitches(const cv::Mat& grid, const FloatRules& rules) {
  detail::check_problem(grid, rules, "consistent_stitches");
  // Every stitch of a violating run lies in at least one of its violated windows.
  long in_conflict = 0;
  for (int y = 0; y < grid.rows; ++y) {
    const detail::RowView r = detail::row_view(grid, rules, y);
    r.for_each_run([&](int s, int len) {
      if (r.run_violations(s, len) > 0) in_conflict += len;
    });
  }
  return static_cast<long>(grid.total()) - in_conflict;
}

int longest_float(const cv::Mat& grid, const FloatRules& rules) {
  detail::check_problem(grid, rules, "longest_float");
  int longest = 0;
  for (int y = 0; y < grid.rows; ++y) {
    const detail::RowView r = detail::row_view(grid, rules, y);
    r.for_each_run([&](int s, int len) {
      const bool free = !rules.anchoring && (s == 0 || s + len == grid.cols);
      if (!free) longest = std::max(longest, len);
    });
  }
  return longest;
}

}  // namespace atelier::knit

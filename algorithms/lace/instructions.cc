#include "algorithms/lace/instructions.h"

#include <algorithm>
#include <cctype>
#include <limits>
#include <regex>
#include <stdexcept>
#include <utility>
#include <vector>

namespace atelier::lace {
namespace {

constexpr const char* kStitchList = "k, yo, k2tog, ssk, sk2p, s2kp";

// The flat writing of row[a, b): maximal runs of k as "kN", other symbols by name.
std::vector<std::string> flat_items(const Row& row, std::size_t a, std::size_t b) {
  std::vector<std::string> items;
  for (std::size_t i = a; i < b;) {
    if (row[i] == Symbol::k) {
      std::size_t j = i;
      while (j < b && row[j] == Symbol::k) ++j;
      items.push_back("k" + std::to_string(j - i));
      i = j;
    } else {
      items.emplace_back(name(row[i]));
      ++i;
    }
  }
  return items;
}

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) {
    if (!out.empty()) out += ", ";
    out += s;
  }
  return out;
}

std::string trim(std::string_view s) {
  std::size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return std::string(s.substr(a, b - a));
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

[[noreturn]] void fail(int line, const std::string& what) {
  throw std::invalid_argument("line " + std::to_string(line) + ": " + what);
}

int to_int(const std::string& digits, int line) {
  try {
    const long v = std::stol(digits);
    if (v > std::numeric_limits<int>::max() / 4) throw std::out_of_range("big");
    return static_cast<int>(v);
  } catch (const std::exception&) {
    fail(line, "the number " + digits + " is too large");
  }
}

// The start of a line for a message: at most 60 characters, control bytes (a binary file's)
// shown as '?', so the message stays one readable line.
std::string excerpt(const std::string& line) {
  std::string out = line.substr(0, 60);
  for (char& c : out)
    if (std::iscntrl(static_cast<unsigned char>(c))) c = '?';
  return line.size() > 60 ? out + "..." : out;
}

// Refuses a row that would make more than kMaxRowStitches: `have` so far, `more` to add.
void check_row_size(std::size_t have, std::size_t more, int line) {
  if (more > kMaxRowStitches - std::min(have, kMaxRowStitches))
    fail(line, "the row makes more than " + std::to_string(kMaxRowStitches) + " stitches");
}

// One item ("k3", "yo", ...) appended to `out`.
void parse_item(const std::string& raw, int line, Row& out) {
  const std::string item = lower(trim(raw));
  if (item.empty()) fail(line, "an empty stitch between commas");
  static const std::regex run(R"(k\s*(\d+))");
  std::smatch m;
  if (std::regex_match(item, m, run)) {
    const int n = to_int(m[1].str(), line);
    if (n < 1) fail(line, "'" + trim(raw) + "' knits no stitches");
    check_row_size(out.size(), static_cast<std::size_t>(n), line);
    out.insert(out.end(), static_cast<std::size_t>(n), Symbol::k);
    return;
  }
  for (Symbol s : kAllSymbols) {
    if (name(s) == item) {
      out.push_back(s);
      return;
    }
  }
  fail(line, "'" + trim(raw) + "' is not a stitch of this pattern (" + kStitchList + ")");
}

// "k2, yo, [yo, k2tog] 2 times, k1" -> symbols in knitting order.
Row parse_items(const std::string& text, int line) {
  Row row;
  static const std::regex times(R"(^\s*(\d+)\s*times?\s*)", std::regex::icase);
  std::size_t pos = 0;
  while (pos < text.size()) {
    while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos]))) ++pos;
    if (pos >= text.size()) break;
    if (text[pos] == '[') {
      const std::size_t close = text.find(']', pos + 1);
      if (close == std::string::npos) fail(line, "a '[' without its ']'");
      const std::string inner = text.substr(pos + 1, close - pos - 1);
      if (inner.find('[') != std::string::npos) fail(line, "brackets inside brackets");
      Row group;
      std::size_t a = 0;
      while (true) {
        const std::size_t comma = inner.find(',', a);
        parse_item(inner.substr(a, comma == std::string::npos ? std::string::npos : comma - a),
                   line, group);
        if (comma == std::string::npos) break;
        a = comma + 1;
      }
      const std::string rest = text.substr(close + 1);
      std::smatch m;
      if (!std::regex_search(rest, m, times))
        fail(line, "a bracketed group must be followed by 'N times'");
      const int n = to_int(m[1].str(), line);
      if (n < 1) fail(line, "a group repeated " + m[1].str() + " times");
      check_row_size(row.size(), group.size() * static_cast<std::size_t>(n), line);
      for (int t = 0; t < n; ++t) row.insert(row.end(), group.begin(), group.end());
      pos = close + 1 + static_cast<std::size_t>(m.length(0));
      if (pos < text.size()) {
        if (text[pos] != ',') fail(line, "expected ',' after '" + text.substr(close + 1, m.length(0)) + "'");
        ++pos;
      }
    } else {
      const std::size_t comma = text.find(',', pos);
      const std::string item = text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
      if (item.find(']') != std::string::npos) fail(line, "a ']' without its '['");
      parse_item(item, line, row);
      pos = comma == std::string::npos ? text.size() : comma + 1;
      if (comma != std::string::npos && trim(text.substr(pos)).empty())
        fail(line, "the row ends with a comma");
    }
  }
  return row;
}

// "Row 2 and all WS rows: purl." and, when right-side rows have a double yarn-over (two side
// by side, also across the repeat's edge), how to work it on the wrong side: a double
// yarn-over is one wrapped loop twice round the needle, purled once and knitted once so it
// makes two stitches over the big hole.
std::string ws_rows_line(const Chart& chart) {
  std::vector<int> ws;  // WS row numbers after a RS row with a double yarn-over
  for (std::size_t r = 0; r < chart.rows.size(); ++r)
    if (max_adjacent_yarn_overs(chart.rows[r], true) >= 2) ws.push_back(2 * static_cast<int>(r) + 2);
  if (ws.empty()) return "Row 2 and all WS rows: purl.\n";
  std::string rows;
  for (std::size_t i = 0; i < ws.size(); ++i) {
    rows += i == 0 ? "" : i + 1 == ws.size() ? " and " : ", ";
    rows += std::to_string(ws[i]);
  }
  return "Row 2 and all WS rows: purl, except: purl 1, knit 1 into each double yarn-over "
         "(yo twice) of the row below (row" + std::string(ws.size() > 1 ? "s " : " ") + rows + ").\n";
}

}  // namespace

std::string write_row(const Row& row) {
  const std::size_t n = row.size();
  if (n == 0) return "";
  // best[i]: length of the shortest writing of row[i, n); choice[i]: its first item and where
  // the rest starts. Filled from the end.
  std::vector<std::size_t> best(n + 1, 0);
  std::vector<std::pair<std::string, std::size_t>> choice(n);
  for (std::size_t i = n; i-- > 0;) {
    std::size_t best_len = std::numeric_limits<std::size_t>::max();
    auto consider = [&](std::string item, std::size_t next) {
      const std::size_t len = item.size() + (next < n ? 2 + best[next] : 0);
      if (len < best_len) {
        best_len = len;
        choice[i] = {std::move(item), next};
      }
    };
    if (row[i] == Symbol::k) {
      // A shorter run than the maximal one can pay off when a group starts inside the run.
      std::size_t run = 0;
      while (i + run < n && row[i + run] == Symbol::k) ++run;
      for (std::size_t len = 1; len <= run; ++len) consider("k" + std::to_string(len), i + len);
    } else {
      consider(std::string(name(row[i])), i + 1);
    }
    for (std::size_t g = 1; i + 2 * g <= n; ++g) {
      const std::vector<std::string> inner = flat_items(row, i, i + g);
      if (inner.size() < 2) continue;
      const std::string body = "[" + join(inner) + "] ";
      std::size_t reps = 1;
      while (i + (reps + 1) * g <= n &&
             std::equal(row.begin() + i, row.begin() + i + g, row.begin() + i + reps * g))
        ++reps;
      for (std::size_t r = 2; r <= reps; ++r)
        consider(body + std::to_string(r) + " times", i + r * g);
    }
    best[i] = best_len;
  }
  std::string out;
  for (std::size_t i = 0; i < n; i = choice[i].second) {
    if (!out.empty()) out += ", ";
    out += choice[i].first;
  }
  return out;
}

std::string write_instructions(const Chart& chart, int cast_on, const InstructionsInfo& info) {
  if (const Knittability k = knittable(chart, cast_on); !k) throw std::invalid_argument(k.why);
  const int rs_rows = static_cast<int>(chart.rows.size());
  const std::string n = std::to_string(cast_on);
  std::string title = trim(info.title);
  std::replace_if(title.begin(), title.end(), [](char ch) { return ch == '\n' || ch == '\r'; }, ' ');
  std::string out = title.empty() ? "Lace pattern\n" : "Lace pattern: " + title + "\n";
  out += "Multiple of " + n + " stitches; " + std::to_string(2 * rs_rows) + "-row repeat (" +
         std::to_string(rs_rows) + " right-side row" + (rs_rows == 1 ? "" : "s") + " charted).\n";
  out += "Cast on a multiple of " + n + " stitches.\n\n";
  for (int r = 0; r < rs_rows; ++r) {
    const Row& row = chart.rows[static_cast<std::size_t>(r)];
    out += "Row " + std::to_string(2 * r + 1) + " (RS): " + write_row(row) + ". (" +
           std::to_string(produced(row)) + " sts)\n";
    if (r == 0) out += ws_rows_line(chart);
  }
  const int last = produced(chart.rows.back());
  if (last == cast_on) {
    out += "Repeat rows 1-" + std::to_string(2 * rs_rows) + ".\n\n";
  } else {  // eq. 1 does not hold: the rows cannot be stacked again
    out += "Work rows 1-" + std::to_string(2 * rs_rows) + " once (the last row leaves " +
           std::to_string(last) + " sts per repeat, so the pattern does not repeat upward).\n\n";
  }
  out +=
      "Abbreviations: k knit; yo yarn over; k2tog knit 2 together (right-slanting decrease); ssk\n"
      "slip, slip, knit (left-slanting decrease); sk2p slip 1, knit 2 together, pass slipped stitch\n"
      "over (left-slanting double decrease); s2kp slip 2 together knitwise, knit 1, pass the 2\n"
      "slipped stitches over (centred double decrease); yo, yo double yarn-over: on the WS row after\n"
      "it purl 1, knit 1 into it; kN knit N stitches; [ ] N times: work the stitches in brackets N\n"
      "times; (N sts): stitches on the needle after the row; RS right side; WS wrong side.\n";
  return out;
}

ParsedInstructions parse_instructions(std::string_view text) {
  static const std::regex row_re(R"(^row\s+(\d+)\s*\(\s*rs\s*\)\s*:\s*(.*)$)", std::regex::icase);
  static const std::regex count_re(R"(^(.*?)\s*\(\s*(\d+)\s*sts?\s*\)\s*\.?$)", std::regex::icase);
  static const std::regex multiple_re(R"(^multiple of (\d+) (st|sts|stitch|stitches)\b.*)");
  static const std::regex cast_on_re(R"(^cast on (a multiple of )?(\d+) (st|sts|stitch|stitches)\b.*)");

  ParsedInstructions out;
  std::vector<int> row_lines;  // text line of each chart row
  int multiple = 0, cast_on = 0, multiple_line = 0, cast_on_line = 0;
  bool in_abbreviations = false;
  int line_no = 0;
  std::size_t pos = 0, stitches = 0;
  while (pos <= text.size()) {
    const std::size_t nl = text.find('\n', pos);
    const std::string_view raw = text.substr(pos, nl == std::string_view::npos ? text.npos : nl - pos);
    pos = nl == std::string_view::npos ? text.size() + 1 : nl + 1;
    ++line_no;
    if (raw.size() > kMaxLineChars)
      fail(line_no, "the line is longer than " + std::to_string(kMaxLineChars) + " characters");
    const std::string line = trim(raw);
    if (line.empty()) {
      in_abbreviations = false;
      continue;
    }
    if (in_abbreviations) continue;
    const std::string low = lower(line);
    std::smatch m;
    if (std::regex_match(line, m, row_re)) {
      const int number = to_int(m[1].str(), line_no);
      const int expected = 2 * static_cast<int>(out.chart.rows.size()) + 1;
      if (number != expected) {
        fail(line_no, "found row " + m[1].str() + " where row " + std::to_string(expected) +
                          " (RS) was expected (right-side rows are numbered 1, 3, 5, ...)");
      }
      std::string body = m[2].str();
      int count = -1;
      std::smatch c;
      if (std::regex_match(body, c, count_re)) {
        count = to_int(c[2].str(), line_no);
        body = c[1].str();
      }
      body = trim(body);
      if (!body.empty() && body.back() == '.') body.pop_back();
      Row row = parse_items(body, line_no);
      if (row.empty()) fail(line_no, "row " + m[1].str() + " has no stitches");
      if (count >= 0 && count != produced(row)) {
        fail(line_no, "row " + m[1].str() + " makes " + std::to_string(produced(row)) +
                          " stitches but the line says (" + std::to_string(count) + " sts)");
      }
      stitches += row.size();
      if (stitches > kMaxChartStitches)
        fail(line_no, "the chart makes more than " + std::to_string(kMaxChartStitches) + " stitches");
      out.chart.rows.push_back(std::move(row));
      row_lines.push_back(line_no);
    } else if (low.starts_with("row 2 and all ws rows") || low.starts_with("lace pattern") ||
               low.starts_with("repeat rows") || low.starts_with("work rows")) {
      continue;
    } else if (low.starts_with("abbreviations")) {
      in_abbreviations = true;  // the rest of the paragraph explains the abbreviations
    } else if (std::regex_match(low, m, multiple_re)) {
      multiple = to_int(m[1].str(), line_no);
      multiple_line = line_no;
    } else if (std::regex_match(low, m, cast_on_re)) {
      cast_on = to_int(m[2].str(), line_no);
      cast_on_line = line_no;
    } else {
      fail(line_no, "cannot read '" + excerpt(line) + "' (expected a line such as 'Row 1 (RS): k2, yo, k2tog. (4 sts)')");
    }
  }
  if (out.chart.rows.empty()) fail(line_no, "the text has no 'Row 1 (RS): ...' line");
  if (cast_on_line > 0 && multiple_line > 0 && cast_on != multiple) {
    fail(cast_on_line, "casts on a multiple of " + std::to_string(cast_on) +
                           " stitches but line " + std::to_string(multiple_line) +
                           " says a multiple of " + std::to_string(multiple));
  }
  out.cast_on = cast_on_line > 0   ? cast_on
                : multiple_line > 0 ? multiple
                                    : consumed(out.chart.rows[0]);
  if (const Knittability k = knittable(out.chart, out.cast_on); !k) {
    fail(k.bad_row >= 0 ? row_lines[static_cast<std::size_t>(k.bad_row)]
                        : (cast_on_line > 0 ? cast_on_line : multiple_line),
         k.why);
  }
  return out;
}

}  // namespace atelier::lace

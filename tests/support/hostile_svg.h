// Generators of hostile SVG drawings for the reader's limits (nothing big is committed):
// deep nesting, many elements, coordinates that flatten to millions of points, non-finite
// numbers. Each returns the file's text.
#pragma once

#include <string>

namespace atelier::testing {

inline const char* kSvgHead =
    R"(<svg xmlns="http://www.w3.org/2000/svg" width="400mm" height="400mm" viewBox="0 0 400 400">)";

// `depth` nested <g> around one stroked line (nested-1e6.svg: a million of them).
inline std::string nested_groups(size_t depth) {
  std::string s = kSvgHead;
  s.reserve(s.size() + depth * 7 + 100);
  for (size_t i = 0; i < depth; ++i) s += "<g>";
  s += R"(<path d="M 1 1 L 2 2" stroke="black"/>)";
  for (size_t i = 0; i < depth; ++i) s += "</g>";
  return s + "</svg>";
}

// `n` small stroked squares in rows (many-paths.svg), each its own <path>, within 400 mm.
inline std::string many_paths(size_t n) {
  std::string s = kSvgHead;
  const size_t per_row = 400;
  for (size_t i = 0; i < n; ++i) {
    const double x = 0.5 + static_cast<double>(i % per_row) * 0.99;
    const double y = 0.5 + static_cast<double>(i / per_row) * 0.99 * 400 / ((n + per_row - 1) / per_row + 1);
    s += "<path d=\"M" + std::to_string(x) + " " + std::to_string(y) + "h0.5v0.3h-0.5z\" stroke=\"black\"/>";
  }
  return s + "</svg>";
}

// Circles far larger than any bed but within the coordinate limit, at a fine tolerance:
// at 0.1 um each flattens to about 250000 points, `n` of them to n times that (the effect
// of scale-bomb.svg).
inline std::string point_bomb(size_t n) {
  std::string s =
      R"(<svg xmlns="http://www.w3.org/2000/svg" width="999000mm" height="999000mm" viewBox="0 0 999000 999000">)";
  for (size_t i = 0; i < n; ++i)
    s += "<circle cx=\"499000\" cy=\"499000\" r=\"" + std::to_string(400000 + i) + "\" stroke=\"black\"/>";
  return s + "</svg>";
}

}  // namespace atelier::testing

// Reading the shapes of an SVG drawing as laser paths in mm (parsed with SVG++ over
// rapidxml_ns).
//
// Supported: path (every command, relative and absolute, quadratic and arcs), rect (also
// rounded), circle, ellipse, line, polyline, polygon, inside nested g / svg / a elements with
// `transform` attributes; stroke, fill and color from attributes and `style=`, inherited from
// groups; display="none" hides. Not drawn: text (convert it to paths first), use, image,
// defs, clipPath, mask. Gradient or pattern strokes count as no stroke.
//
// Units. The root's width/height (mm, cm, in, pt, pc, px = 1/96 in; unitless = px) and
// viewBox give the scale from user units to mm. Without width/height the viewBox units are
// px; with neither, the user units are px and the drawing's size is its extent.
// Coordinates are as in SVG: x right, y down, origin top-left.
// Curves are flattened (laser::flatten_cubic; arcs and quadratics become cubics first) so
// that no chord deviates more than `tolerance_mm` from the curve.
//
// Limits (SvgLimits; each refusal names the file and the limit): a hostile drawing must cost
// a clear error, not the converter's stack or memory. Checked on the raw text before parsing:
// nesting depth (256), elements (100000) and attributes (1000000). While reading: path
// commands and flattened points of the whole drawing (1000000, about 16 MB of points, which
// plan, preview and G-code copy a few times), coordinates within 1e6 mm of the origin after
// every transform (a laser bed is under 2 m; this refuses scale bombs before flattening), and
// finite numbers everywhere (NaN or infinite values in transforms, lengths or arcs are refused
// with the arc's numbers; arcs are checked before SVG++'s arc conversion sees them).
//
// Thread-safe (no shared state).
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "algorithms/laser/geometry.h"

namespace atelier {

struct SvgShape {
  std::vector<laser::Path> paths;  // one per subpath, mm
  std::string stroke;              // "#rrggbb" lower case, or "" for no stroke
  bool filled = false;             // has a fill other than none
};

struct SvgLimits {
  size_t max_depth = 256;          // element nesting levels
  size_t max_elements = 100000;    // elements of any kind
  size_t max_attributes = 1000000;
  size_t max_points = 1000000;     // path commands and flattened points, whole drawing
  double max_coordinate_mm = 1e6;  // |x|, |y| after transforms, and the drawing's size
};

struct SvgDrawing {
  double width_mm = 0, height_mm = 0;
  std::vector<SvgShape> shapes;  // document order; shapes without geometry are left out
  // Drawing elements that are not burned, by element name ("text", "use", "image"): the
  // report names them so a missing engraving is not a surprise.
  std::map<std::string, size_t> unburned;
};

// Throws ConvertError naming the file and the problem ("x.svg: not an SVG file: ...",
// "x.svg: line 3: XML error: expected >", "x.svg: invalid value of attribute d ...").
// Files larger than `max_bytes` are refused before reading; `limits` as above.
SvgDrawing read_svg(const std::filesystem::path& file, double tolerance_mm,
                    uintmax_t max_bytes = 200u << 20, const SvgLimits& limits = {});

}  // namespace atelier

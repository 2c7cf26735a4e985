#include "convert/common/svg_paths.h"

// SVG++'s arc-to-Bezier iterator trips g++ 12's -Wmaybe-uninitialized after inlining (a
// false positive inside the library); the warning is only silenced for this file.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include <map>
#include <rapidxml_ns/rapidxml_ns.hpp>
#include <svgpp/policy/xml/rapidxml_ns.hpp>
#include <svgpp/svgpp.hpp>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <type_traits>

#include "convert/common/xml_extent.h"
#include "convert/convert.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
namespace tag = svgpp::tag;
using laser::Point;

constexpr double kMmPerPx = 25.4 / 96;  // CSS pixel: 1/96 inch

// 2-D affine map in SVG's matrix(a b c d e f) form: x' = a x + c y + e, y' = b x + d y + f.
struct Affine {
  double a = 1, b = 0, c = 0, d = 1, e = 0, f = 0;
  Point apply(Point p) const { return {a * p.x + c * p.y + e, b * p.x + d * p.y + f}; }
};

// l * r: applies r first, then l (SVG nests transforms this way).
Affine operator*(const Affine& l, const Affine& r) {
  return {l.a * r.a + l.c * r.b, l.b * r.a + l.d * r.b,         l.a * r.c + l.c * r.d,
          l.b * r.c + l.d * r.d, l.a * r.e + l.c * r.f + l.e, l.b * r.e + l.d * r.f + l.f};
}

struct Paint {
  enum Kind { none, color, current_color, other } kind = none;
  int rgb = 0;
};

// Path geometry as SVG++ delivers it (absolute; arcs and quadratics already cubics), kept in
// the element's user space until its transform is known (attributes come in any order).
struct Segment {
  enum Kind { move, line, cubic, close } kind;
  Point p[3];
};

struct Frame {
  Affine ctm;    // the parent's user space -> root viewport px
  Affine local;  // this element's transform and viewport
  Paint stroke;  // inherited properties ...
  Paint fill{Paint::color, 0};
  int color = 0;
  bool hidden = false;  // ... and display="none" of any ancestor
  std::vector<Segment> segments;
};

std::string hex_color(int rgb) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%06x", rgb & 0xffffff);
  return buf;
}

// SVG++ treats much of what real files contain (editor attributes, CSS it does not know,
// elements outside our set) as errors; a laser job only needs the geometry, so those are
// skipped. Values that do not parse stay errors: a half-read path would burn wrongly.
template <class Context>
struct lenient_errors : svgpp::policy::error::raise_exception<Context> {
  template <class... A>
  static bool unknown_element(const Context&, const A&...) { return true; }
  template <class... A>
  static bool unexpected_element(const Context&, const A&...) { return true; }
  template <class... A>
  static bool unknown_attribute(const Context&, const A&...) { return true; }
  template <class... A>
  static bool unexpected_attribute(const Context&, const A&...) { return true; }
};

// Pass 1: the root's viewBox size, which gives "100%" its meaning when width/height are
// missing.
class RootProbe {
 public:
  void on_enter_element(tag::element::any) { ++depth_; }  // not sent for the root itself
  void on_exit_element() { --depth_; }
  void set(tag::attribute::viewBox, double, double, double w, double h) {
    if (depth_ > 0) return;  // a nested svg
    has_viewbox = true;
    viewbox_w = w;
    viewbox_h = h;
  }
  bool has_viewbox = false;
  double viewbox_w = 0, viewbox_h = 0;

 private:
  int depth_ = 0;
};

// SVG++'s own path conversion, except that arcs come to the Collector: SVG++'s arc code
// casts an angle to int, undefined for the NaN a degenerate or non-finite arc gives, so the
// Collector checks each arc before converting it with SVG++'s helpers.
struct PathPolicy {
  static const bool absolute_coordinates_only = true;
  static const bool no_ortho_line_to = true;
  static const bool no_quadratic_bezier_shorthand = true;
  static const bool no_cubic_bezier_shorthand = true;
  static const bool quadratic_bezier_as_cubic = true;
  static const bool arc_as_cubic_bezier = false;
};

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

bool finite(Point p) { return std::isfinite(p.x) && std::isfinite(p.y); }

class Collector {
 public:
  typedef svgpp::factory::length::unitless<> length_factory_type;

  Collector(const length_factory_type& lengths, double tolerance_mm, const SvgLimits& limits,
            const std::string& name)
      : lengths_(lengths), tolerance_mm_(tolerance_mm), limits_(limits), name_(name), stack_(1) {}

  const length_factory_type& length_factory() const { return lengths_; }

  template <class ElementTag>
  void on_enter_element(ElementTag) {
    Frame child;
    const Frame& parent = stack_.back();
    child.ctm = parent.ctm * parent.local;
    child.stroke = parent.stroke;
    child.fill = parent.fill;
    child.color = parent.color;
    child.hidden = parent.hidden;
    stack_.push_back(std::move(child));
  }

  void on_exit_element() {
    Frame& f = stack_.back();
    if (!f.hidden && !f.segments.empty()) emit(f);
    stack_.pop_back();
  }

  // Viewport events (svg elements).
  void set_viewport(double x, double y, double w, double h) {
    if (stack_.size() == 1) {  // the root: its x/y do not apply
      root_w_px = w;
      root_h_px = h;
      return;
    }
    top().local = top().local * Affine{1, 0, 0, 1, x, y};
  }
  void set_viewbox_transform(double tx, double ty, double sx, double sy, bool) {
    top().local = top().local * Affine{sx, 0, 0, sy, tx, ty};
  }
  void set_viewbox_size(double, double) {}
  void disable_rendering() { top().hidden = true; }

  void transform_matrix(const boost::array<double, 6>& m) {
    top().local = top().local * Affine{m[0], m[1], m[2], m[3], m[4], m[5]};
  }

  // Path events, absolute coordinates only (PathPolicy).
  void path_move_to(double x, double y, tag::coordinate::absolute) {
    add(Segment::move, {Point{x, y}});
    at_ = start_ = Point{x, y};
  }
  void path_line_to(double x, double y, tag::coordinate::absolute) {
    add(Segment::line, {Point{x, y}});
    at_ = Point{x, y};
  }
  void path_cubic_bezier_to(double x1, double y1, double x2, double y2, double x, double y,
                            tag::coordinate::absolute) {
    add(Segment::cubic, {Point{x1, y1}, Point{x2, y2}, Point{x, y}});
    at_ = Point{x, y};
  }
  // SVG 1.1 F.6: radii are absolute values, a zero radius is a line (and so is a small arc
  // of radii a billion times its chord), an arc to its own start is nothing; then endpoint to centre form and cubics, as SVG++ would, once every number
  // that reaches the conversion (and its cast) is known to be finite.
  void path_elliptical_arc_to(double rx, double ry, double rotation_deg, bool large_arc,
                              bool sweep, double x, double y, tag::coordinate::absolute) {
    const Point to{x, y};
    if (!std::isfinite(rx) || !std::isfinite(ry) || !std::isfinite(rotation_deg) || !finite(to) ||
        !finite(at_)) {
      throw ConvertError(name_ + ": an arc has a number that is not finite (rx " + number_text(rx) +
                         ", ry " + number_text(ry) + ", rotation " + number_text(rotation_deg) +
                         ", to " + number_text(x) + "," + number_text(y) + ")");
    }
    if (to.x == at_.x && to.y == at_.y) return;
    rx = std::fabs(rx);
    ry = std::fabs(ry);
    // A small arc whose radii dwarf its chord bows out by at most chord^2 * rx / (8 ry^2)
    // (ry the smaller radius): below 1e-9 of the chord it is the chord, and computing its
    // centre (1e300 away, say) would only lose every digit of the end points.
    const double r_min = std::min(rx, ry), r_max = std::max(rx, ry);
    const double chord = std::hypot(x - at_.x, y - at_.y);
    if (rx == 0 || ry == 0 || (!large_arc && r_min / r_max * r_min > 1e9 * chord)) {
      path_line_to(x, y, tag::coordinate::absolute());
      return;
    }
    const double phi = std::fmod(rotation_deg, 360.0) * boost::math::constants::degree<double>();
    double cx, cy, theta1, theta2;
    svgpp::arc_endpoint_to_center(at_.x, at_.y, x, y, rx, ry, phi, large_arc, sweep, cx, cy,
                                  theta1, theta2);
    if (!std::isfinite(cx) || !std::isfinite(cy) || !std::isfinite(theta1) ||
        !std::isfinite(theta2) || !std::isfinite(rx) || !std::isfinite(ry)) {
      // Radii so far from the chord's size that the centre cannot be computed (e.g. 1e-300 or
      // 1e300): the arc is, within any tolerance, the straight chord.
      path_line_to(x, y, tag::coordinate::absolute());
      return;
    }
    constexpr double kTwoPi = boost::math::constants::two_pi<double>();
    if (sweep && theta2 < theta1) theta2 += kTwoPi;
    if (!sweep && theta2 > theta1) theta2 -= kTwoPi;
    using ArcToBezier = svgpp::arc_to_bezier<double>;
    ArcToBezier a2b(cx, cy, rx, ry, phi, ArcToBezier::circle_angle_tag(), theta1, theta2,
                    ArcToBezier::max_angle_tag(), boost::math::constants::half_pi<double>());
    for (ArcToBezier::iterator it(a2b); !it.eof(); it.advance())
      add(Segment::cubic, {Point{it.p1x(), it.p1y()}, Point{it.p2x(), it.p2y()},
                           Point{it.p3x(), it.p3y()}});
    add(Segment::line, {to});  // lands exactly on the end point
    at_ = to;
  }
  void path_close_subpath() {
    add(Segment::close, {});
    at_ = start_;
  }
  void path_exit() {}

  // Paint and display.
  void set(tag::attribute::stroke, tag::value::none) { top().stroke = Paint{Paint::none}; }
  void set(tag::attribute::stroke, tag::value::currentColor) {
    top().stroke = Paint{Paint::current_color};
  }
  void set(tag::attribute::stroke, int rgb) { top().stroke = Paint{Paint::color, rgb}; }
  template <class... A>
  void set(tag::attribute::stroke, const A&...) {  // url(#gradient) and the like
    top().stroke = Paint{Paint::other};
  }
  void set(tag::attribute::fill, tag::value::none) { top().fill = Paint{Paint::none}; }
  void set(tag::attribute::fill, tag::value::currentColor) {
    top().fill = Paint{Paint::current_color};
  }
  void set(tag::attribute::fill, int rgb) { top().fill = Paint{Paint::color, rgb}; }
  template <class... A>
  void set(tag::attribute::fill, const A&...) {
    top().fill = Paint{Paint::other};
  }
  void set(tag::attribute::color, int rgb) { top().color = rgb; }
  template <class... A>
  void set(tag::attribute::color, const A&...) {}
  void set(tag::attribute::display, tag::value::none) { top().hidden = true; }
  template <class... A>
  void set(tag::attribute::display, const A&...) {}

  std::vector<SvgShape> shapes;
  double root_w_px = 0, root_h_px = 0;

 private:
  Frame& top() { return stack_.back(); }

  void add(Segment::Kind kind, std::initializer_list<Point> pts) {
    // Every command becomes at least one point: a path of millions of commands is refused
    // before its segments fill memory.
    if (++commands_ > limits_.max_points) points_over_limit();
    Segment s{kind, {}};
    size_t i = 0;
    for (Point p : pts) s.p[i++] = p;
    top().segments.push_back(s);
  }

  [[noreturn]] void points_over_limit() const {
    throw ConvertError(name_ + ": more than " + std::to_string(limits_.max_points) +
                       " points after flattening the curves to " + number_text(tolerance_mm_) +
                       " mm (limit " + std::to_string(limits_.max_points) +
                       " points per drawing; simplify it or raise tolerance_mm)");
  }

  // Every point in mm must be finite and within the limit before it is flattened or planned.
  Point checked(Point p) const {
    if (!finite(p)) {
      throw ConvertError(name_ + ": a shape's coordinates are not finite numbers after its "
                         "transforms and units (an infinite or NaN value, or an overflowing "
                         "scale)");
    }
    const double far = std::max(std::fabs(p.x), std::fabs(p.y));
    if (far > limits_.max_coordinate_mm) {
      throw ConvertError(name_ + ": a shape reaches " + number_text(far) +
                         " mm from the origin after its transforms (limit " +
                         number_text(limits_.max_coordinate_mm) + " mm)");
    }
    return p;
  }

  void push_point(laser::Path& path, Point p) {
    if (++points_ > limits_.max_points) points_over_limit();
    if (!path.points.empty()) {
      Point q = path.points.back();
      if (std::fabs(p.x - q.x) < 1e-9 && std::fabs(p.y - q.y) < 1e-9) return;
    }
    path.points.push_back(p);
  }

  // A subpath whose end meets its start encloses an area, Z or not (kerf needs to know).
  void finish(laser::Path& path, std::vector<laser::Path>& out) {
    auto& pts = path.points;
    if (pts.size() >= 2 && laser::distance(pts.front(), pts.back()) < 1e-6) {
      pts.pop_back();
      path.closed = pts.size() >= 2;
    }
    if (pts.size() >= 2) out.push_back(std::move(path));
    path = laser::Path{};
  }

  void emit(const Frame& f) {
    const Affine to_mm = Affine{kMmPerPx, 0, 0, kMmPerPx, 0, 0} * f.ctm * f.local;
    SvgShape shape;
    laser::Path path;
    Point start{0, 0}, at{0, 0};  // mm
    for (const Segment& s : f.segments) {
      switch (s.kind) {
        case Segment::move:
          finish(path, shape.paths);
          start = at = checked(to_mm.apply(s.p[0]));
          push_point(path, at);
          break;
        case Segment::line:
          if (path.points.empty()) push_point(path, at);
          at = checked(to_mm.apply(s.p[0]));
          push_point(path, at);
          break;
        case Segment::cubic: {
          if (path.points.empty()) push_point(path, at);
          flat_.clear();
          Point end = checked(to_mm.apply(s.p[2]));
          const size_t room = limits_.max_points - std::min(points_, limits_.max_points);
          if (!laser::flatten_cubic(at, checked(to_mm.apply(s.p[0])),
                                    checked(to_mm.apply(s.p[1])), end, tolerance_mm_, flat_,
                                    room))
            points_over_limit();
          for (Point p : flat_) push_point(path, p);
          at = end;
          break;
        }
        case Segment::close:
          path.closed = true;
          if (path.points.size() >= 2 && laser::distance(path.points.front(), path.points.back()) < 1e-6) {
            path.points.pop_back();
          }
          if (path.points.size() >= 2) shape.paths.push_back(std::move(path));
          path = laser::Path{};
          at = start;  // after Z the pen is back at the subpath's start
          break;
      }
    }
    finish(path, shape.paths);
    if (shape.paths.empty()) return;
    const Paint& stroke = f.stroke;
    if (stroke.kind == Paint::color) shape.stroke = hex_color(stroke.rgb);
    if (stroke.kind == Paint::current_color) shape.stroke = hex_color(f.color);
    shape.filled = f.fill.kind != Paint::none;
    shapes.push_back(std::move(shape));
  }

  const length_factory_type& lengths_;
  double tolerance_mm_;
  const SvgLimits& limits_;
  const std::string& name_;
  size_t commands_ = 0;  // path commands so far, whole drawing
  size_t points_ = 0;    // flattened points so far, whole drawing
  std::vector<Point> flat_;  // scratch for one curve
  Point at_{0, 0}, start_{0, 0};  // current point and subpath start, user units
  // [0] is the root svg element: SVG++ sends no enter/exit events for it, only its attributes.
  std::vector<Frame> stack_;
};

using ProcessedElements = boost::mpl::set<tag::element::svg, tag::element::g, tag::element::a,
                                          tag::element::path, tag::element::rect,
                                          tag::element::circle, tag::element::ellipse,
                                          tag::element::line, tag::element::polyline,
                                          tag::element::polygon>::type;

using ProcessedAttributes = boost::mpl::fold<
    boost::mpl::protect<boost::mpl::joint_view<
        svgpp::traits::shapes_attributes_by_element,
        boost::mpl::set<boost::mpl::pair<tag::element::svg, tag::attribute::x>,
                        boost::mpl::pair<tag::element::svg, tag::attribute::y>,
                        boost::mpl::pair<tag::element::svg, tag::attribute::width>,
                        boost::mpl::pair<tag::element::svg, tag::attribute::height>,
                        boost::mpl::pair<tag::element::svg, tag::attribute::viewBox>,
                        boost::mpl::pair<tag::element::svg, tag::attribute::preserveAspectRatio>,
                        tag::attribute::transform, tag::attribute::stroke,
                        tag::attribute::fill, tag::attribute::color,
                        tag::attribute::display>::type>>,
    boost::mpl::set0<>, boost::mpl::insert<boost::mpl::_1, boost::mpl::_2>>::type;

std::string shorten(std::string s) {
  if (s.size() > 200) s = s.substr(0, 200) + "...";
  return s;
}

std::vector<char> read_file(const fs::path& file, uintmax_t max_bytes) {
  const std::string name = file.filename().string();
  std::error_code ec;
  uintmax_t size = fs::file_size(file, ec);
  if (ec) throw ConvertError(name + ": cannot read: " + ec.message());
  if (size > max_bytes) {
    throw ConvertError(name + ": the file has " + std::to_string(size) +
                       " bytes, more than the limit of " + std::to_string(max_bytes));
  }
  std::ifstream in(file, std::ios::binary);
  std::vector<char> text(size + 1, '\0');  // rapidxml wants a terminated, writable buffer
  if (!in || !in.read(text.data(), static_cast<std::streamsize>(size))) {
    throw ConvertError(name + ": cannot read: " + std::strerror(errno));
  }
  return text;
}

void parse(rapidxml_ns::xml_document<>& doc, std::vector<char>& text, const std::string& name) {
  try {
    doc.parse<0>(text.data());
  } catch (const rapidxml_ns::parse_error& e) {
    const char* at = e.where<char>();
    long line = 1;
    const char* end = text.data() + text.size();
    // rapidxml has written NULs into the buffer by now; count up to `at` regardless.
    for (const char* p = text.data(); at && p < at && p < end; ++p) line += *p == '\n';
    throw ConvertError(name + ": line " + std::to_string(line) + ": not well-formed XML: " +
                       e.what());
  }
}

// Elements that draw but that the laser does not burn (text would need a font outline, <use>
// a clone's resolution, <image> a raster engrave), by name, counted below `node`.
void count_unburned(const rapidxml_ns::xml_node<>* node, std::map<std::string, size_t>& out) {
  for (auto* c = node->first_node(); c; c = c->next_sibling()) {
    if (c->type() != rapidxml_ns::node_element) continue;
    const std::string local(c->local_name(), c->local_name_size());
    if (local == "text" || local == "use" || local == "image") {
      ++out[local];
      continue;
    }
    if (local != "defs" && local != "symbol") count_unburned(c, out);
  }
}

rapidxml_ns::xml_node<>* document_element(rapidxml_ns::xml_document<>& doc) {
  rapidxml_ns::xml_node<>* node = doc.first_node();
  while (node && node->type() != rapidxml_ns::node_element) node = node->next_sibling();
  return node;
}

// Refuses, before any parser sees the text, a document deeper or larger than the limits:
// rapidxml and SVG++ recurse per nesting level (a million nested groups overflow the
// stack) and allocate per element and attribute.
void check_extent(const std::vector<char>& text, const SvgLimits& limits, const std::string& name) {
  const XmlExtent x = measure_xml(std::string_view(text.data(), text.size() - 1),
                                  limits.max_elements, limits.max_attributes, limits.max_depth);
  if (x.max_depth > limits.max_depth) {
    throw ConvertError(name + ": elements nested more than " + std::to_string(limits.max_depth) +
                       " deep (limit " + std::to_string(limits.max_depth) + " levels)");
  }
  if (x.elements > limits.max_elements) {
    throw ConvertError(name + ": more than " + std::to_string(limits.max_elements) +
                       " elements (limit " + std::to_string(limits.max_elements) +
                       " per drawing)");
  }
  if (x.attributes > limits.max_attributes) {
    throw ConvertError(name + ": more than " + std::to_string(limits.max_attributes) +
                       " attributes (limit " + std::to_string(limits.max_attributes) +
                       " per drawing)");
  }
}

}  // namespace

SvgDrawing read_svg(const fs::path& file, double tolerance_mm, uintmax_t max_bytes,
                    const SvgLimits& limits) {
  const std::string name = file.filename().string();
  std::vector<char> text = read_file(file, max_bytes);
  check_extent(text, limits, name);
  std::vector<char> original = text;
  rapidxml_ns::xml_document<> doc;
  parse(doc, text, name);
  rapidxml_ns::xml_node<>* root = document_element(doc);
  if (!root || std::string(root->local_name(), root->local_name_size()) != "svg") {
    std::string found = root ? std::string(root->name(), root->name_size()) : "nothing";
    throw ConvertError(name + ": not an SVG file: the document element is " +
                       (root ? "<" + found + ">" : found) + ", not <svg>");
  }
  if (root->namespace_uri_size() == 0) {
    // Hand-written files often lack xmlns; SVG++ would then see no SVG element at all.
    // Declare the SVG namespace on the root and parse again (rapidxml parses in place).
    size_t at = static_cast<size_t>(root->name() - text.data()) + root->name_size();
    text = std::move(original);
    static const std::string decl = " xmlns=\"http://www.w3.org/2000/svg\"";
    text.insert(text.begin() + static_cast<long>(at), decl.begin(), decl.end());
    doc.clear();
    parse(doc, text, name);
    root = document_element(doc);
  }

  SvgDrawing drawing;
  count_unburned(root, drawing.unburned);
  try {
    RootProbe probe;
    svgpp::document_traversal<
        svgpp::processed_elements<boost::mpl::set<tag::element::svg>::type>,
        svgpp::processed_attributes<
            boost::mpl::set<boost::mpl::pair<tag::element::svg, tag::attribute::viewBox>>::type>,
        svgpp::error_policy<lenient_errors<RootProbe>>>::load_document(
        static_cast<const rapidxml_ns::xml_node<>*>(root), probe);

    Collector::length_factory_type lengths;  // user unit = px, 96 px per inch
    const bool sized = root->first_attribute("width") && root->first_attribute("height");
    if (!sized && probe.has_viewbox) lengths.set_viewport_size(probe.viewbox_w, probe.viewbox_h);

    Collector collector(lengths, tolerance_mm, limits, name);
    svgpp::document_traversal<
        svgpp::processed_elements<ProcessedElements>,
        svgpp::processed_attributes<ProcessedAttributes>,
        svgpp::viewport_policy<svgpp::policy::viewport::calculate>,
        svgpp::path_policy<PathPolicy>,
        svgpp::length_policy<svgpp::policy::length::forward_to_method<Collector>>,
        svgpp::transform_events_policy<svgpp::policy::transform_events::forward_to_method<Collector>>,
        svgpp::error_policy<lenient_errors<Collector>>>::load_document(
        static_cast<const rapidxml_ns::xml_node<>*>(root), collector);

    drawing.shapes = std::move(collector.shapes);
    if (sized || probe.has_viewbox) {
      drawing.width_mm = collector.root_w_px * kMmPerPx;
      drawing.height_mm = collector.root_h_px * kMmPerPx;
      if (!std::isfinite(drawing.width_mm) || !std::isfinite(drawing.height_mm) ||
          std::max(std::fabs(drawing.width_mm), std::fabs(drawing.height_mm)) > limits.max_coordinate_mm) {
        throw ConvertError(name + ": the drawing's size " + number_text(drawing.width_mm) + " x " +
                           number_text(drawing.height_mm) + " mm is beyond the limit of " +
                           number_text(limits.max_coordinate_mm) + " mm");
      }
    } else {
      for (const auto& s : drawing.shapes)
        for (const auto& p : s.paths)
          for (Point q : p.points) {
            drawing.width_mm = std::max(drawing.width_mm, q.x);
            drawing.height_mm = std::max(drawing.height_mm, q.y);
          }
    }
  } catch (const ConvertError&) {
    throw;
  } catch (const std::exception& e) {
    throw ConvertError(name + ": " + shorten(e.what()));
  }
  return drawing;
}

}  // namespace atelier

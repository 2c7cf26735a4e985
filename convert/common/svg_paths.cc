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

class Collector {
 public:
  typedef svgpp::factory::length::unitless<> length_factory_type;

  Collector(const length_factory_type& lengths, double tolerance_mm)
      : lengths_(lengths), tolerance_mm_(tolerance_mm), stack_(1) {}

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

  // Path events, absolute coordinates only (policy::path::minimal).
  void path_move_to(double x, double y, tag::coordinate::absolute) {
    add(Segment::move, {Point{x, y}});
  }
  void path_line_to(double x, double y, tag::coordinate::absolute) {
    add(Segment::line, {Point{x, y}});
  }
  void path_cubic_bezier_to(double x1, double y1, double x2, double y2, double x, double y,
                            tag::coordinate::absolute) {
    add(Segment::cubic, {Point{x1, y1}, Point{x2, y2}, Point{x, y}});
  }
  void path_close_subpath() { add(Segment::close, {}); }
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
    Segment s{kind, {}};
    size_t i = 0;
    for (Point p : pts) s.p[i++] = p;
    top().segments.push_back(s);
  }

  static void push_point(laser::Path& path, Point p) {
    if (!path.points.empty()) {
      Point q = path.points.back();
      if (std::fabs(p.x - q.x) < 1e-9 && std::fabs(p.y - q.y) < 1e-9) return;
    }
    path.points.push_back(p);
  }

  // A subpath whose end meets its start encloses an area, Z or not (kerf needs to know).
  static void finish(laser::Path& path, std::vector<laser::Path>& out) {
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
          start = at = to_mm.apply(s.p[0]);
          path.points.push_back(at);
          break;
        case Segment::line:
          if (path.points.empty()) path.points.push_back(at);
          at = to_mm.apply(s.p[0]);
          push_point(path, at);
          break;
        case Segment::cubic: {
          if (path.points.empty()) path.points.push_back(at);
          std::vector<Point> flat;
          Point end = to_mm.apply(s.p[2]);
          laser::flatten_cubic(at, to_mm.apply(s.p[0]), to_mm.apply(s.p[1]), end,
                               tolerance_mm_, flat);
          for (Point p : flat) push_point(path, p);
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

}  // namespace

SvgDrawing read_svg(const fs::path& file, double tolerance_mm, uintmax_t max_bytes) {
  const std::string name = file.filename().string();
  std::vector<char> text = read_file(file, max_bytes);
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

    Collector collector(lengths, tolerance_mm);
    svgpp::document_traversal<
        svgpp::processed_elements<ProcessedElements>,
        svgpp::processed_attributes<ProcessedAttributes>,
        svgpp::viewport_policy<svgpp::policy::viewport::calculate>,
        svgpp::path_policy<svgpp::policy::path::minimal>,
        svgpp::length_policy<svgpp::policy::length::forward_to_method<Collector>>,
        svgpp::transform_events_policy<svgpp::policy::transform_events::forward_to_method<Collector>>,
        svgpp::error_policy<lenient_errors<Collector>>>::load_document(
        static_cast<const rapidxml_ns::xml_node<>*>(root), collector);

    drawing.shapes = std::move(collector.shapes);
    if (sized || probe.has_viewbox) {
      drawing.width_mm = collector.root_w_px * kMmPerPx;
      drawing.height_mm = collector.root_h_px * kMmPerPx;
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

// How deep and how large an XML document is, measured on its raw text before any parser
// builds a tree from it (rapidxml and SVG++ recurse once per nesting level and allocate a
// node per element and attribute, so a hostile file must be refused before they see it).
//
// The scan knows just enough XML to count correctly: comments, CDATA sections, processing
// instructions and the DOCTYPE (with an internal subset) are skipped, and a '>' or '<' inside
// a quoted attribute value does not end a tag. It does not check well-formedness (the parser
// does that afterwards); for malformed text the counts are a best effort.
//
// Pure; thread-safe.
#pragma once

#include <cstddef>
#include <string_view>

namespace atelier {

struct XmlExtent {
  size_t elements = 0;    // start tags, including self-closing ones
  size_t attributes = 0;  // name="value" pairs in start tags
  size_t max_depth = 0;   // deepest nesting; the document element alone is depth 1
};

// Scans `text`. Stops early, with the counts so far, as soon as one of them exceeds its
// `stop_*` value (so a 200 MB file of nested tags costs one pass at most).
XmlExtent measure_xml(std::string_view text, size_t stop_elements, size_t stop_attributes,
                      size_t stop_depth);

}  // namespace atelier

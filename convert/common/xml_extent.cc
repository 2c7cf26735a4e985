#include "convert/common/xml_extent.h"

namespace atelier {

XmlExtent measure_xml(std::string_view text, size_t stop_elements, size_t stop_attributes,
                      size_t stop_depth) {
  XmlExtent x;
  size_t depth = 0;
  const size_t n = text.size();
  auto skip_past = [&](size_t from, std::string_view end) {
    size_t at = text.find(end, from);
    return at == std::string_view::npos ? n : at + end.size();
  };
  size_t i = 0;
  while (i < n) {
    i = text.find('<', i);
    if (i == std::string_view::npos) break;
    std::string_view rest = text.substr(i);
    if (rest.starts_with("<!--")) {
      i = skip_past(i + 4, "-->");
    } else if (rest.starts_with("<![CDATA[")) {
      i = skip_past(i + 9, "]]>");
    } else if (rest.starts_with("<?")) {
      i = skip_past(i + 2, "?>");
    } else if (rest.starts_with("<!")) {
      // DOCTYPE or a declaration; an internal subset [...] may hold '>' of its own.
      size_t j = i + 2;
      int brackets = 0;
      for (; j < n; ++j) {
        char c = text[j];
        if (c == '[') ++brackets;
        else if (c == ']') --brackets;
        else if (c == '"' || c == '\'') {
          size_t close = text.find(c, j + 1);
          if (close == std::string_view::npos) break;
          j = close;
        }
        else if (c == '>' && brackets <= 0) break;
      }
      i = j + 1;
    } else if (rest.starts_with("</")) {
      if (depth > 0) --depth;
      i = skip_past(i + 2, ">");
    } else {
      // A start tag: attributes until '>' (or "/>"), quoted values skipped whole.
      ++x.elements;
      size_t j = i + 1;
      bool self_closing = false;
      for (; j < n; ++j) {
        char c = text[j];
        if (c == '"' || c == '\'') {
          size_t close = text.find(c, j + 1);
          j = close == std::string_view::npos ? n : close;
        } else if (c == '=') {
          ++x.attributes;
        } else if (c == '>') {
          self_closing = text[j - 1] == '/';
          break;
        }
      }
      i = j + 1;
      if (!self_closing) {
        ++depth;
        if (depth > x.max_depth) x.max_depth = depth;
      } else if (depth + 1 > x.max_depth) {
        x.max_depth = depth + 1;
      }
    }
    if (x.elements > stop_elements || x.attributes > stop_attributes || x.max_depth > stop_depth)
      break;
  }
  return x;
}

}  // namespace atelier

// measure_xml: depth, element and attribute counts of raw XML text, before any parser.
#include <gtest/gtest.h>

#include <string>

#include "convert/common/xml_extent.h"

namespace atelier {
namespace {

XmlExtent measure(const std::string& text) { return measure_xml(text, SIZE_MAX, SIZE_MAX, SIZE_MAX); }

TEST(XmlExtent, CountsElementsAttributesAndDepth) {
  const XmlExtent x = measure(R"(<?xml version="1.0"?><svg a="1" b='2'><g><path d="M0 0"/></g><g/></svg>)");
  EXPECT_EQ(x.elements, 4u);
  EXPECT_EQ(x.attributes, 3u);
  EXPECT_EQ(x.max_depth, 3u);
}

TEST(XmlExtent, CommentsCdataDoctypeAndQuotedBracketsAreNotTags) {
  const XmlExtent x = measure(
      "<!DOCTYPE svg [ <!ENTITY e \"<g>\"> ]><!-- <g><g><g> --><svg t=\"a>b<c\" u='x=\"y\"'>"
      "<![CDATA[<g><g>]]><?pi <g> ?><g></g></svg>");
  EXPECT_EQ(x.elements, 2u);
  EXPECT_EQ(x.attributes, 2u);
  EXPECT_EQ(x.max_depth, 2u);
}

TEST(XmlExtent, StopsAsSoonAsALimitIsPassed) {
  std::string deep;
  for (int i = 0; i < 100000; ++i) deep += "<g>";
  const XmlExtent x = measure_xml(deep, SIZE_MAX, SIZE_MAX, 256);
  EXPECT_EQ(x.max_depth, 257u);
  EXPECT_EQ(x.elements, 257u);
}

}  // namespace
}  // namespace atelier

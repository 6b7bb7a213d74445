// viz/xml_escape.h: the one XML escape of viz/ (SVG figures and reports, the .pvd index).
#include "viz/xml_escape.h"

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>
#include <vtkNew.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>

#include "viz/svg_plot.h"

namespace pneufem {
namespace {

TEST(XmlEscape, EscapesMarkupDropsForbiddenControlsKeepsUtf8) {
  EXPECT_EQ(xml_escape("a < b & \"c\" 'd' > e"), "a &lt; b &amp; &quot;c&quot; &apos;d&apos; &gt; e");
  EXPECT_EQ(xml_escape("x\ty\nz\r\x01\x1f"), "x\ty\nz\r");
  EXPECT_EQ(xml_escape("angle (\xC2\xB0)"), "angle (\xC2\xB0)");
  EXPECT_EQ(xml_escape(""), "");
  EXPECT_TRUE(has_xml_forbidden_char(std::string("a\x01")));
  EXPECT_TRUE(has_xml_forbidden_char(std::string("a\0b", 3)));
  EXPECT_FALSE(has_xml_forbidden_char("a\tb\nc\rd <&>"));
}

// The SVG writer and the .pvd writer share it: svg::escape is xml_escape.
TEST(XmlEscape, SvgEscapeIsTheSameFunction) {
  const std::vector<std::string> texts = {"a<b", "R&D \"fit\" 'x'", "t\x02u\tv", "\xC2\xB0"};
  for (const std::string& s : texts)
    EXPECT_EQ(svg::escape(s), xml_escape(s)) << s;
}

// What it escapes reads back as the text it was given, as an attribute value and as character data.
TEST(XmlEscape, RoundTripsThroughAnXmlParser) {
  const std::string text = "p < 5 & q > \"3\" 'kPa' \xC2\xB0";
  const std::string doc = "<?xml version=\"1.0\"?>\n<root name=\"" + xml_escape(text) + "\"><item>" + xml_escape(text) +
                          "</item></root>\n";
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("pneufem_xml_escape_" + std::to_string(::getpid()) + ".xml");
  {
    std::ofstream out(file);
    out << doc;
  }
  vtkNew<vtkXMLDataParser> parser;
  parser->SetFileName(file.c_str());
  const int parsed = parser->Parse();
  std::filesystem::remove(file);
  ASSERT_EQ(parsed, 1) << doc;
  vtkXMLDataElement* root = parser->GetRootElement();
  ASSERT_NE(root, nullptr);
  EXPECT_EQ(std::string(root->GetAttribute("name")), text);
  ASSERT_EQ(root->GetNumberOfNestedElements(), 1);
}

}  // namespace
}  // namespace pneufem

#pragma once
// XML text: the one escape of every XML file viz/ writes (the SVG figures and reports,
// viz/svg_plot.h; the ParaView .pvd index, viz/vtk_output.h).
#include <string>

namespace pneufem {

/// Text made safe for XML 1.0 character data and attribute values: & < > " ' become entities,
/// and the control characters XML 1.0 forbids (below 0x20 other than tab, newline and carriage
/// return) are dropped, since no escape can represent them. UTF-8 passes through unchanged.
std::string xml_escape(const std::string& text);

/// True when `text` holds a character xml_escape() drops (a control character XML 1.0 forbids).
bool has_xml_forbidden_char(const std::string& text);

}  // namespace pneufem

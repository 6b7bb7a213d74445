#include "viz/xml_escape.h"

namespace pneufem {

namespace {

bool forbidden(char c) { return static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n' && c != '\r'; }

}  // namespace

std::string xml_escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default:
        if (!forbidden(c)) out += c;
    }
  }
  return out;
}

bool has_xml_forbidden_char(const std::string& text) {
  for (char c : text)
    if (forbidden(c)) return true;
  return false;
}

}  // namespace pneufem

#include "core/message_text.h"

namespace pneufem {

std::string printable(std::string_view text, std::size_t max_chars) {
  const bool cut = text.size() > max_chars && max_chars >= 3;
  if (cut) text = text.substr(0, max_chars - 3);
  std::string out;
  out.reserve(text.size() + 3);
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if ((u < 0x20 && c != '\n') || u == 0x7F) {
      static const char* const kHex = "0123456789ABCDEF";
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 15];
    } else {
      out += c;
    }
  }
  return cut ? out + "..." : out;
}

}  // namespace pneufem

#include "core/number_text.h"

#include <sstream>

namespace pneufem {

std::string short_num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace pneufem

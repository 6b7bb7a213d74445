#pragma once
// Numbers in messages: the value a user gave or a check found, in an error or a note.
#include <string>

namespace pneufem {

/// `v` as an ostream prints it by default: 6 significant digits ("0.25", "1e+06", "nan"). For
/// messages only; files that are read back keep every digit (json::num in core/json_writer.h).
std::string short_num(double v);

}  // namespace pneufem

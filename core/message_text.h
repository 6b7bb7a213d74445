#pragma once
// Text of a user's file quoted in a message (an error or a note).
#include <cstddef>
#include <string>
#include <string_view>

namespace pneufem {

/// `text` with its control bytes but the line break (a NUL of a UTF-16 or binary file, a lone CR,
/// a terminal escape) written as \xHH, cut to `max_chars` characters of `text` with "..." when
/// longer. A message stays whole: InputError::what() is a C string that a NUL would cut short,
/// before the advice; and a terminal shows it as it is.
std::string printable(std::string_view text, std::size_t max_chars = std::string_view::npos);

}  // namespace pneufem

// core/message_text.h: a user's text as messages quote it.
#include "core/message_text.h"

#include <string>

#include <gtest/gtest.h>

namespace pneufem {
namespace {

// Control bytes but the line break become \xHH (DEL too); a long text is cut with "..." so that the
// whole stays max_chars long.
TEST(MessageText, PrintableEscapesControlBytesAndCuts) {
  EXPECT_EQ(printable("plain text"), "plain text");
  EXPECT_EQ(printable(std::string("a\0b\x1b[2J\tc\nd\x7f", 12)), "a\\x00b\\x1B[2J\\x09c\nd\\x7F");
  EXPECT_EQ(printable("abcdefghij", 6), "abc...");
  EXPECT_EQ(printable("abcdef", 6), "abcdef");
  EXPECT_EQ(printable("abcdef", 2), "abcdef");  // too short to cut with "...": left whole
  EXPECT_EQ(printable("\x01\x02xyz", 4), "\\x01...");  // max_chars counts the text, not the escapes
}

}  // namespace
}  // namespace pneufem

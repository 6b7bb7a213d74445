// version_string (core/version.h): the project version, then the git description in parentheses.
#include "core/version.h"

#include <string>

#include <gtest/gtest.h>

namespace {

TEST(Version, ProjectVersionThenGitDescription) {
  const std::string v = pneufem::version_string();
  const std::size_t open = v.find(" (");
  ASSERT_NE(open, std::string::npos) << v;
  EXPECT_GT(open, 0u);
  EXPECT_EQ(v.back(), ')') << v;
  EXPECT_GT(v.size(), open + 3) << "empty git description: " << v;
}

}  // namespace

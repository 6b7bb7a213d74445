// core/errors.h: the error tiers every library throws. An InputError is a std::runtime_error with
// the message as given; a PhysicsError also carries the element and the time where it happened.
#include "core/errors.h"

#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace pneufem {
namespace {

TEST(Errors, PhysicsErrorCarriesElementAndTime) {
  try {
    throw PhysicsError("J <= 0 in element 17", 17, 2.5);
  } catch (const std::runtime_error& e) {  // caught as what the commands catch
    EXPECT_EQ(std::string(e.what()), "J <= 0 in element 17");
    const auto* p = dynamic_cast<const PhysicsError*>(&e);
    ASSERT_NE(p, nullptr);
    EXPECT_EQ(p->element(), 17);
    EXPECT_EQ(p->time_s(), 2.5);
  }
}

TEST(Errors, PhysicsErrorDefaultsToNoElementAtTimeZero) {
  const PhysicsError e("NaN in the residual");
  EXPECT_EQ(e.element(), -1);
  EXPECT_EQ(e.time_s(), 0.0);
}

TEST(Errors, InputErrorIsNotAPhysicsError) {
  try {
    throw InputError("scene.toml:3: key 'mesh.h_mm': must be > 0");
  } catch (const PhysicsError&) {
    FAIL() << "an InputError was caught as a PhysicsError";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "scene.toml:3: key 'mesh.h_mm': must be > 0");
  }
}

}  // namespace
}  // namespace pneufem

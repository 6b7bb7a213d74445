#pragma once
// Test helper shared by the test programs: the message of the InputError a call throws.
#include <functional>
#include <string>

#include "core/errors.h"

namespace pneufem::test {

/// Runs `f` and returns the what() of the InputError it throws, or "(no error)" when it returns
/// normally (any other exception propagates and fails the test).
inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace pneufem::test

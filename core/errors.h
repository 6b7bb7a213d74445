#pragma once
// The three tiers of errors:
//  * InputError   - bad user input: says where (file, line, key or element) and what to do.
//  * PhysicsError - the simulation became invalid (J <= 0, NaN, unstable step): element, time, hint.
//  * programmer invariants use assert() in debug builds.
// They live in core/, the ground floor that every library may use.
#include <stdexcept>
#include <string>

namespace pneufem {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class PhysicsError : public std::runtime_error {
 public:
  PhysicsError(const std::string& what, int element = -1, double time_s = 0.0)
      : std::runtime_error(what), element_(element), time_s_(time_s) {}
  int element() const { return element_; }
  double time_s() const { return time_s_; }

 private:
  int element_;
  double time_s_;
};

}  // namespace pneufem

#pragma once
// With PNEUFEM_FUZZ_REPORT set, each fuzz target prints one line per input to stderr:
// "pneufem-fuzz: accepted" or "pneufem-fuzz: error <first line of the message>". Replaying a corpus
// (fuzz_<target> -runs=0 DIR) then counts how many inputs were refused and how many of those
// messages name where and what to do (RELIABILITY.md). Off while fuzzing: no cost.
#include <cstdio>
#include <cstdlib>
#include <string>

namespace pneufem::fuzz {

inline void report(const char* outcome, const std::string& message = {}) {
  static const bool on = std::getenv("PNEUFEM_FUZZ_REPORT") != nullptr;
  if (!on) return;
  const std::string first = message.substr(0, message.find('\n'));
  std::fprintf(stderr, "pneufem-fuzz: %s %s\n", outcome, first.c_str());
}

}  // namespace pneufem::fuzz

// Fuzz target: the canonical measurement CSV reader (analysis/measurements.h), in memory.
// InputError is the documented answer to bad input; anything else is a finding. A recording
// read without error must be well formed (trials sorted, each number once; each stream's time
// strictly increasing; every value finite) and must survive format -> parse unchanged.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "analysis/measurements.h"
#include "core/errors.h"
#include "fuzz/report.h"

namespace {

void check_series(const pneufem::Series& s) {
  if (s.t_s.size() != s.value.size()) std::abort();
  for (std::size_t i = 0; i < s.t_s.size(); ++i) {
    if (!std::isfinite(s.t_s[i]) || !std::isfinite(s.value[i])) std::abort();
    if (i > 0 && !(s.t_s[i] > s.t_s[i - 1])) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  pneufem::Recording rec;
  try {
    rec = pneufem::parse_measurements_csv(text, "fuzz.csv");
  } catch (const pneufem::InputError& e) {
    pneufem::fuzz::report("error", e.what());
    return 0;
  }
  for (std::size_t i = 0; i < rec.trials.size(); ++i) {
    if (i > 0 && !(rec.trials[i].trial > rec.trials[i - 1].trial)) std::abort();
    check_series(rec.trials[i].pressure_kPa);
    check_series(rec.trials[i].angle_deg);
  }
  // What the reader accepted, written and read again, is the same recording (measurements.h).
  // (An error reading it back is a finding too: not caught here.)
  const pneufem::Recording again = pneufem::parse_measurements_csv(pneufem::format_measurements_csv(rec), "again.csv");
  if (again.trials.size() != rec.trials.size()) std::abort();
  for (std::size_t i = 0; i < rec.trials.size(); ++i) {
    const pneufem::TrialRecording &a = rec.trials[i], &b = again.trials[i];
    if (a.trial != b.trial || a.pressure_kPa.t_s != b.pressure_kPa.t_s ||
        a.pressure_kPa.value != b.pressure_kPa.value || a.angle_deg.t_s != b.angle_deg.t_s ||
        a.angle_deg.value != b.angle_deg.value)
      std::abort();
  }
  pneufem::fuzz::report("accepted");
  return 0;
}

// Fuzz target: the DeepLabCut CSV reader (analysis/deeplabcut.h), in memory. The first byte picks
// one of a few mappings (the body parts of the seed files, the zero, the sense, the likelihood
// cut); the rest is the file. InputError is the documented answer to bad input; anything else is
// a finding, and so is an angle series that is not finite or not increasing in time.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "analysis/deeplabcut.h"
#include "core/errors.h"
#include "fuzz/report.h"

namespace {

pneufem::DlcMapping mapping(std::uint8_t choice) {
  pneufem::DlcMapping m;
  if (choice & 1) {
    m.fixed_parts = {"base1", "base2"};
    m.tip_parts = {"tip1", "tip2"};
  } else {
    m.fixed_parts = {"clamp_top", "clamp_mid", "clamp_low"};
    m.tip_parts = {"tip_a", "tip_b", "tip_c"};
  }
  if (choice & 2) m.positive = pneufem::AngleSense::clockwise;
  if (choice & 4) m.zero_raw_deg = 0.0;
  if (choice & 8) m.zero_frames = 1;
  if (choice & 16) m.likelihood_cut = 0.0;
  if (choice & 32) m.t0_s = 12.5;
  return m;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const pneufem::DlcMapping map = mapping(data[0]);
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    const pneufem::Recording rec = pneufem::parse_deeplabcut_csv(text, "fuzz_dlc.csv", map);
    for (const pneufem::TrialRecording& t : rec.trials) {
      const pneufem::Series& s = t.angle_deg;
      if (s.t_s.size() != s.value.size()) std::abort();
      for (std::size_t i = 0; i < s.t_s.size(); ++i) {
        if (!std::isfinite(s.t_s[i]) || !std::isfinite(s.value[i])) std::abort();
        if (i > 0 && !(s.t_s[i] > s.t_s[i - 1])) std::abort();
      }
    }
    pneufem::fuzz::report("accepted");
  } catch (const pneufem::InputError& e) {
    pneufem::fuzz::report("error", e.what());
  }
  return 0;
}

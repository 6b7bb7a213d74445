#pragma once
// A recording sampled from a scene's own load, like the seed paper's rig: inlet pressure at 400 Hz
// (exact, noise-free), video frames at 30 fps with angle 0 (tests fill in the angles they need).
#include <cmath>
#include <string>

#include "analysis/measurements.h"
#include "engine/load_history.h"

namespace pneufem::test {

inline Recording rig_sampled(const LoadHistory& load, const std::string& source = "model") {
  Recording rec;
  rec.source = source;
  for (std::size_t k = 0; k < load.trials.size(); ++k) {
    const TrialLoad& tl = load.trials[k];
    TrialRecording tr;
    tr.trial = static_cast<int>(k + 1);
    for (long i = 0; i <= std::lround(tl.duration() * 400); ++i) {
      tr.pressure_kPa.t_s.push_back(i / 400.0);
      tr.pressure_kPa.value.push_back(tl.pressure(i / 400.0) * 1e-3);
    }
    for (long j = 0; j / 30.0 <= tl.duration(); ++j) {
      tr.angle_deg.t_s.push_back(j / 30.0);
      tr.angle_deg.value.push_back(0.0);
    }
    rec.trials.push_back(tr);
  }
  return rec;
}

}  // namespace pneufem::test

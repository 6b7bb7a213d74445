#pragma once
// Shared by the diagnose tests on recordings made by other means: runs the diagnosis of a recording
// and prints what it chose, round by round (the numbers the tests' comments quote).
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "app/diagnose/command.h"
#include "scenes/scene.h"

namespace pneufem::test {

inline DiagnosisResult run_and_print_diagnosis(const std::string& name, const std::vector<std::string>& scene,
                                               const DiagnoseOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const DiagnosisResult r = run_diagnosis(Scene::load("", scene), o);
  std::printf("%s: baseline %.4f, floor %.4f, final %.4f (%.2fx); selected:", name.c_str(), r.baseline_nrmse,
              r.noise_floor_nrmse, r.final_nrmse, r.final_nrmse / r.baseline_nrmse);
  for (const std::string& s : r.selected) std::printf(" %s", s.c_str());
  std::printf("; %.1f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  for (const CandidateResult& c : r.candidates) {
    std::printf("  round %d %-27s NRMSE %.4f beyond static %.4f dAIC %8.1f%s", c.round, c.effect.c_str(), c.nrmse,
                c.nrmse_beyond_static, c.delta_aic, c.significant ? " sig" : "");
    for (std::size_t i = 0; i < c.params.size(); ++i) std::printf(" %s=%.4g", c.param_names[i].c_str(), c.params[i]);
    std::printf("\n");
  }
  return r;
}

}  // namespace pneufem::test

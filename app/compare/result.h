#pragma once
// What one `pneufem compare` run found (app/compare/command.h runs it and writes it; the figures of
// app/compare/report.h draw it): the comparison, the model run, and the region sensitivities. Apart
// from the command so that the report reads the result without depending on the command.
#include <string>
#include <vector>

#include "analysis/model_vs_measured.h"
#include "app/simulate/drive.h"

namespace pneufem {

struct RegionSensitivity {
  std::string region;
  long elements = 0;
  double best_scale = 1.0, variance_fraction = 0.0;
  double nrmse = 0.0;  ///< pooled NRMSE of the perturbed model
};

struct CompareRunResult {
  Comparison comparison;
  DriveResult drive;
  std::vector<RegionSensitivity> regions;
  std::vector<std::string> warnings;
  double wall_s = 0.0;
};

}  // namespace pneufem

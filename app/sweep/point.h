#pragma once
// The points of a sweep (app/sweep/command.h runs them; app/sweep/plot.h draws them): a swept
// parameter as given, and what one point's run gave. Types only, apart from the command so the
// plot reads them without depending on the command.
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace pneufem {

/// One --param KEY=LO:HI[:N][:log|lin].
struct ParamSpec {
  std::string text;  ///< as given, for messages
  std::string key;   ///< dotted scene key, e.g. materials.silicone.fatigue.tau_s
  double lo = 0.0, hi = 0.0;
  int n = 0;             ///< grid values (0 = not given, allowed with --lhs only)
  bool log = false;      ///< log spacing / log-uniform sampling (needs lo > 0)
  bool integer = false;  ///< the scene key is an integer: values are rounded
};

/// A point re-run with the full FEM (--fem-points) against its reduced run.
struct FemComparison {
  std::string status = "pending";  ///< "ok", "failed" or "pending"
  double final_nrmse = std::numeric_limits<double>::quiet_NaN();       ///< the FEM's final-trial NRMSE
  double max_abs_diff_deg = std::numeric_limits<double>::quiet_NaN();  ///< largest |reduced - FEM| angle of a report
  std::string error;
};

struct SweepPoint {
  int index = 0;                    ///< 1-based, = the NNNN of points/NNNN
  std::vector<double> values;       ///< one per parameter
  std::vector<std::string> texts;   ///< the values as given to the scene
  std::string status = "pending";   ///< "ok", "failed" or "pending"
  std::string model;                ///< what ran: "reduced", "full" or "full (fallback: <reason>)"; "" = unknown
  bool skipped = false;             ///< done by an earlier invocation
  double wall_s = 0.0;
  std::vector<double> nrmse;        ///< per trial, from metrics.json (empty without metrics)
  double final_angle_deg = 0.0;     ///< NaN when no angle was reported
  std::string error;
  std::optional<FemComparison> fem;  ///< set for the --fem-points
};

}  // namespace pneufem

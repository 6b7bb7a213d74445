#pragma once
// A single material point driven through a deformation and time history: the committed/trial
// protocol of the engine (read committed, write trial, commit on acceptance) for one point, for
// material-point tests, calibration scripts and the analysis tools. Not used in the hot loop.
#include <span>
#include <vector>

#include "materials/material.h"

namespace pneufem {

class MaterialPoint {
 public:
  /// Starts from the material's virgin state at time 0.
  explicit MaterialPoint(MaterialPtr material);

  /// Evaluates at F after the physical increment dt_s from the committed state; the trial state is
  /// kept (trial_state()) but not committed. May be called repeatedly (Newton iterations).
  PointResponse trial(const Mat3& F, double dt_s, bool tangent = true);
  /// Makes the last trial state the committed one and advances the time by its dt_s.
  void commit();
  /// trial() then commit().
  PointResponse advance(const Mat3& F, double dt_s, bool tangent = false);

  std::span<const double> committed_state() const { return committed_; }
  std::span<const double> trial_state() const { return trial_; }
  /// Overwrites the committed state (size material().state_size()), e.g. to test at a fixed history.
  void set_committed_state(std::span<const double> state);
  PointFields fields() const { return material_->fields(committed_); }
  double time_s() const { return time_s_; }
  const Material& material() const { return *material_; }

 private:
  MaterialPtr material_;
  std::vector<double> committed_, trial_;
  double time_s_ = 0.0, trial_dt_s_ = 0.0;
};

}  // namespace pneufem

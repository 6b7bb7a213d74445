#pragma once
// The reduced-model evaluator of `pneufem diagnose` (app/diagnose/command.h): replays a recording's
// pressure on any variant of a scene through the path model or the elastic FEM curves and returns
// the model angle at its frames. Separate from the diagnosis itself because the calibration and
// the selection only ever see angles per frame; how they are made (path model, static FEM sweeps,
// the calibration mesh's pressure map) is this class's business. Internal to app/diagnose*.cpp.
#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "analysis/measurements.h"
#include "app/simulate/drive.h"
#include "analysis/model_vs_measured.h"
#include "engine/load_history.h"
#include "engine/path_model.h"
#include "scenes/build_model.h"
#include "scenes/scene.h"

namespace pneufem::diagnose_detail {


/// Reduced-model replay of a recording for any variant of the base scene (same mesh).
///
/// Calibration mesh. With `mesh_scene` (the user's scene: the same model on a finer mesh) the
/// reduced model runs on `base` (a coarser mesh of the same geometry) driven by a mapped chamber
/// pressure phi(p) = p_c(theta_f(p)): the pressure at which the calibration mesh's elastic path
/// reaches the angle the scene's mesh reaches at p (theta_f from one static sweep of the scene's
/// mesh, p_c from the traced path). Why map the pressure and not add an angle offset: a coarse
/// mesh is too stiff (~7-10 % in angle from h = 2 to 4 mm on the default actuator, ~19 % from 2 to
/// 8 mm on a 3-chamber one), i.e. its error acts like a stiffness error, and a pressure map makes
/// the elastic baseline exact (up to interpolation) AND keeps a stiffness scale s exact when
/// p_c(theta) / p_f(theta) is constant: s p_c(theta) = p_c(theta_f(p)) gives p_f(theta) = p / s. An
/// additive angle offset theta_f(p) - theta_c(p) would not: on the 3-chamber case of
/// tests/app/diagnose/test_command.cpp (CalibrationMesh; theta ~ p^1.4, coarse 19 % stiffer) it biases a
/// calibrated scale by ~4 % (power-law estimate), the map by 1.9 % (measured). History effects
/// see the deformation the scene's mesh would have (same angle), so their strain-driven evolution
/// is alike. Without any correction the coarse mesh's stiffness is itself "a missing stiffness
/// effect". On the default actuator at 45 kPa the h = 6 mesh bends 55 deg, the h = 2 mesh 77 deg.
class PathModelEvaluator {
 public:
  /// `cache_dir` (may be empty: none): stores and reads the elastic path's trace, the scene mesh's
  /// sweep and the static FEM curves there (app/simulate/result_cache.h), so re-runs on one actuator skip them.
  PathModelEvaluator(const Scene& base, const Recording& rec, const std::vector<ComparedFrame>& frames, int rom_points,
               const Scene* mesh_scene = nullptr, const std::string& cache_dir = "");

  /// Where the elastic path and the scene mesh's sweep came from: "computed", "cache <file>", ...
  const std::string& path_source() const { return path_source_; }
  const std::string& fine_source() const { return fine_source_; }

  /// The peak pressure of the elastic work (elastic_reference_peak_Pa above; >= every recorded pressure).
  double reference_peak_Pa() const { return reference_peak_Pa_; }

  /// Static FEM curves (gravity's sweeps) of this run read from the cache directory / computed.
  int curves_from_cache() const { return curves_from_cache_; }
  int curves_computed() const { return curves_computed_; }

  /// The calibration mesh's pressure map (empty without one): static angles (deg) of the scene's
  /// mesh and of the calibration mesh at p = reference_peak_Pa() i / n, and phi(p) there (Pa).
  const std::vector<double>& fine_curve() const { return fine_curve_; }
  const std::vector<double>& coarse_curve() const { return coarse_curve_; }
  const std::vector<double>& pressure_map_Pa() const { return map_Pa_; }
  long fine_dofs() const { return fine_dofs_; }
  long dofs() const { return ref_->model.num_dofs(); }

  const PathModel& path() const { return *path_; }

  /// Model angle (deg) at every frame of `frames_` for the variant scene.
  std::vector<double> at_frames(const Scene& variant) const;

  /// Model angle series at every measured angle time of every trial.
  std::vector<Series> series(const Scene& variant) const;

  /// True when a run of `variant` costs a static FEM sweep (elastic with gravity), not the reduced model.
  bool uses_fem_sweeps(const Scene& variant) const;

  /// The pressure (Pa) that drives the calibration mesh for an inlet pressure p: p itself, or phi(p)
  /// with a calibration mesh (interpolated between the sweep's points; identity above the sweep's
  /// top is never needed: the sweep spans the reference peak, above every inlet pressure).
  double chamber(double p) const { return map_Pa_.empty() ? p : curve_at(map_Pa_, reference_peak_Pa_, p); }

 private:
  /// Per trial, the model angle at the kept frames (kept_only) or at every angle sample.
  std::vector<std::vector<double>> simulate(const Scene& variant, bool kept_only) const;
  /// simulate()'s parts. Engine times of the requested samples, per trial.
  std::vector<std::vector<double>> sample_times(bool kept_only) const;
  /// Without history: the angle as a function of the chamber pressure, one sweep then a lookup per sample.
  std::vector<std::vector<double>> simulate_elastic(const Scene& variant, const BuiltModel& bm, const LoadHistory& load,
                                                    const std::vector<std::vector<double>>& times) const;
  /// With history: the chamber pressures of one continuous replay of every trial and the rests
  /// between them; `start` gets each trial's start time in it.
  PathLoad continuous_replay(const LoadHistory& load, std::vector<double>& start) const;
  /// With gravity: the elastic FEM's gravity offset theta_g(p) - theta_0(p) at p = hi i / n.
  std::vector<double> gravity_offset(const Scene& variant, const BuiltModel& bm, double hi) const;

  static constexpr int kFemCurvePoints = 16;
  /// Sweep points of the scene mesh for the pressure map (one static continuation of that mesh;
  /// its cost dominates diagnose with --calibration-h). The map phi(p) is close to linear (a
  /// stiffness-like mesh error: phi(p)/p falls from 1.13 to 1.10 over 0-20 kPa on the 3-chamber
  /// case of tests/app/diagnose/test_command.cpp), so 12 points suffice: dropping every other point of a
  /// 24-point map moved it by 1e-4 kPa there, far below the reduced model's own error.
  static constexpr int kMeshCurvePoints = 12;


  static std::string fmt_kPa(double p_Pa);

  /// y(x) on samples (xs, ys) with xs increasing (not uniform): quadratic Lagrange interpolation on
  /// the three samples nearest x (linear extrapolation is not needed: callers stay inside).
  static double interpolate_quadratic(const std::vector<double>& xs, const std::vector<double>& ys, double x);

  /// A curve sampled at p = hi i / n (n = th.size() - 1) at pressure p (quadratic 3-point Lagrange
  /// interpolation on the nearest samples; p clamped to [0, hi]).
  static double curve_at(const std::vector<double>& th, double hi, double p);

  /// Angles (deg) of the static FEM equilibria at p = hi i / n, i = 0..n (cached by scene; `bm`
  /// is the variant's built model, or null to build it on a cache miss).
  std::vector<double> elastic_curve(const Scene& variant, const BuiltModel* bm_in, double hi, int n) const;

  /// static_angle_curve of a built elastic model, through the cache directory when there is one.
  std::vector<double> stored_curve(const Scene& variant, const BuiltModel& bm, double hi, int n,
                                   std::string* source = nullptr) const;

  std::string cache_dir_, path_source_ = "computed", fine_source_;
  mutable std::mutex cache_mu_;
  mutable std::map<std::string, std::vector<double>> curves_;
  mutable std::atomic<int> curves_from_cache_{0}, curves_computed_{0};
  const Recording& rec_;
  const std::vector<ComparedFrame>& frames_;
  std::unique_ptr<BuiltModel> ref_;
  std::unique_ptr<PathModel> path_;
  std::vector<double> fine_curve_, coarse_curve_, map_Pa_;
  long fine_dofs_ = 0;
  LoadHistory inlet_;
  std::vector<double> offset_;
  double rest_s_ = 0.0, p_max_Pa_ = 0.0, reference_peak_Pa_ = 0.0;
};

}  // namespace pneufem::diagnose_detail

#pragma once
// A one-degree-of-freedom Ritz model along the elastic loading path — the fast evaluator that
// calibration loops (pneufem diagnose) run hundreds of times instead of the full FEM.
//
// Idea. A pneu-net inflating under cavity pressure deforms along one dominant mode. The elastic
// FEM solution u_el(p) traces a curve through displacement space; parametrised by its bending
// angle theta it is the "path" u(theta). The reduced model keeps the deformation on this path
// and only asks, at every physical time, WHICH point of the path is in equilibrium with the
// current pressure, when the materials carry history (creep, Mullins, fatigue) or are scaled.
// Virtual work along the path gives one scalar equation (G = generalised force, V = cavity
// volume, S = sum_a m_a u_a the first mass moment of the displacement):
//
//     G_model(theta, history) = p V'(theta) + g . S'(theta)
//
// with G_model(theta) = sum_points w P(F(theta)) : F'(theta) evaluated with the scene's own
// Material objects (the same decorators as the FEM, so any registered effect works). For the
// reference (elastic) model the exact FEM identity G_ref(theta) = p_el(theta) V'(theta) holds,
// so we solve the equation in difference form, which is EXACT for the reference model whatever
// the quadrature of the reduced sum:
//
//     p_el(theta) + [G_model(theta) - G_ref(theta) - g . S'(theta)] / V'(theta) = p(t).
//
// Between samples the reference's pressure p_el(theta) is a monotone cubic and the reference force
// is cached at 64 sub-points per segment, so the elastic model stays on its FEM curve there too
// (0.004 % of the angle on the test actuator's steepest part, tests/engine/test_path_model.cpp).
// The path itself (F at every material point, V and S) is the cubic spline through the
// samples, not a polyline: a polyline's F'(theta) jumps at the samples, and so would the
// residual of every model but the reference, making its angle a step function of the material
// constants that calibration cannot descend (PathModel.AngleIsSmoothInTheConstants).
//
// Approximation: a model whose deformation leaves the elastic path (e.g. strongly localised
// damage) is represented by its best path point (Ritz/Galerkin: first order in the shape change
// for the angle, second order for the energy). Tests bound the angle error against the FEM for
// every built-in effect. Material points: all quadrature points of small meshes; above
// `max_points`, an importance sample of max_points / (points per element) elements (probability
// ~ half volume share + half strain-energy share at the top of the path, Horvitz-Thompson weights),
// each with all its quadrature points (not its centroid: the walls bend), deterministic.
//
// Units: SI; angles in degrees at the interface.
#include <vector>

#include <Eigen/Core>

#include "engine/model.h"
#include "engine/static_solver.h"

namespace pneufem {

class Assembler;

struct PathModelOptions {
  double p_top_Pa = 60e3;        ///< trace the elastic path up to this pressure (or the limit point)
  double dp_Pa = 1000.0;         ///< pressure spacing of the path samples
  int max_points = 6000;         ///< material points kept (importance-sampled above this)
  double max_dt_s = 0.25;        ///< largest physical sub-step of the history integration
  StaticOptions newton;          ///< for tracing the path
};

/// A pressure history to replay: chamber pressure p_Pa[i] at global time t_s[i] (strictly
/// increasing; linear in between); the model angle is returned at every t_s[i].
struct PathLoad {
  std::vector<double> t_s, p_Pa;
};

/// The traced elastic path itself: pressure (Pa) and displacement (m, all dofs) of each sample,
/// from the unloaded state on. Everything else the PathModel holds is computed from it, so a trace
/// stored with its exact bits (app/result_cache.h) rebuilds the identical model.
struct ElasticPathTrace {
  std::vector<double> p_Pa;
  std::vector<Eigen::VectorXd> u;
};

/// Step 1 of the PathModel: traces the elastic path of `reference` with Newton in load control, one
/// sample per options.dp_Pa up to options.p_top_Pa; ends quietly at a limit point. Throws
/// PhysicsError when fewer than three samples (the unloaded state included) could be traced.
ElasticPathTrace trace_elastic_path(const Model& reference, const PathModelOptions& options);

struct PathRunStats {
  long steps = 0;
  long evaluations = 0;
  bool beyond_path = false;  ///< the solution left the traced path (extrapolated): trust it less
};

class PathModel {
 public:
  /// Traces the elastic path of `reference` (materials without history, no gravity) with Newton.
  /// Stops early, without error, at a limit point (the path then ends there).
  PathModel(const Model& reference, const PathModelOptions& options);
  /// The same from a trace of this reference with these options (trace_elastic_path). Throws
  /// InputError when the trace does not fit the model (dof count, unloaded first sample, finite
  /// values, increasing pressure and angle): a stored trace that was damaged or belongs elsewhere.
  PathModel(const Model& reference, const PathModelOptions& options, const ElasticPathTrace& trace);

  /// Angle history (deg) of `model` — same mesh as the reference, any materials and gravity —
  /// under `load`. Throws InputError when the mesh differs, PhysicsError when no path point
  /// balances the load (e.g. the pressure exceeds what the softened actuator can carry).
  std::vector<double> run(const Model& model, const PathLoad& load, PathRunStats* stats = nullptr) const;

  /// The traced path: angle (deg) and pressure (Pa) of each sample.
  const std::vector<double>& path_angle_deg() const { return theta_; }
  const std::vector<double>& path_pressure_Pa() const { return p_; }
  int num_points() const { return static_cast<int>(pt_element_.size()); }

 private:
  int segment(double theta) const;  ///< path segment holding theta (clamped: linear extrapolation)
  // The constructor's three steps (path_model.cpp).
  /// 1. The trace checked against the reference (throws InputError) into theta_, p_, V_, S_.
  void take_trace(const Assembler& asmb, const ElasticPathTrace& trace);
  /// 2. The material points (all, or the importance sample above max_points): pt_element_, pt_qp_, pt_weight_.
  void choose_points(const Assembler& asmb, const Eigen::VectorXd& u_top);
  /// 3. F_ at the points of every sample, the spline slopes, dp_dtheta_ and the reference force Gref_.
  void precompute_path(const Assembler& asmb, const std::vector<Eigen::VectorXd>& us);
  /// One run() of a model through a load: its history, non-local drivers, residual and the scalar
  /// root finder (path_model.cpp).
  class Run;

  const Model& ref_;
  PathModelOptions opt_;
  std::vector<double> theta_, p_, V_;       ///< per path sample
  std::vector<Eigen::Vector3d> S_;          ///< first mass moment of u per sample (kg m)
  std::vector<int> pt_element_;             ///< element of each material point
  std::vector<int> pt_qp_;                  ///< its quadrature point
  std::vector<double> pt_weight_;           ///< quadrature weight (m^3)
  std::vector<Mat3> F_;                     ///< [sample][point]
  std::vector<Mat3> dF_;                    ///< dF/dtheta, [sample][point] (the C2 spline's slopes)
  std::vector<double> dV_;                  ///< dV/dtheta per sample
  std::vector<Eigen::Vector3d> dS_;         ///< dS/dtheta per sample
  std::vector<double> dp_dtheta_;           ///< monotone cubic slopes of p_el(theta) at the samples
  /// Cached reference force: sub-points per segment. 64, not 16: near the limit point the force
  /// along one segment is strongly nonlinear, and the reference residual is the difference of the
  /// exact G_model and this interpolant — with 16 sub-points it put the elastic model 0.6° (at 44
  /// kPa, 50°) off its own FEM curve; 64 cost a few thousand point evaluations once per trace.
  static constexpr int kRefSub = 64;
  std::vector<double> Gref_;                ///< [segment][kRefSub + 1]
};

}  // namespace pneufem

#pragma once
// Internal to engine/rom*.cpp: the quadrature points the reduced model keeps (every point of the
// ECSW-sampled elements) with the basis restricted to them, and the hyper-reduced Galerkin force
// and tangent they integrate. The offline build uses it with the reference's materials (to
// precompute G_hat_ref, K_hat_ref), the online model with the run's materials: the same arithmetic,
// so an elastic model equal to the reference cancels its reference exactly at the precomputed points.
//
// At a point: F(theta, q) = F_el(theta) + sum_j B_j q_j, F_el the C2 spline (in theta) of the path's
// deformation gradient at the point, B_j = dF/dq_j = sum_a Phi_aj (x) grad N_a (constant). The
// theta row is tested with w(theta) (engine/rom.h), whose gradient at the point T(theta) is splined
// like F_el. The force of the point is W [P : T ; B^T P] and its Jacobian W [D_test^T A D_trial] with
// D_trial = [dF/dtheta, B], D_test = [T, B], plus W P : dT/dtheta in the theta-theta entry
// (A = dP/dF; W = ECSW weight x quadrature weight).
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "engine/assembly.h"
#include "engine/model.h"
#include "engine/reduced_basis.h"
#include "materials/material.h"

namespace pneufem::rom_detail {

/// d(bending angle)/du at u (deg/m) by central differences over the tip nodes (engine/rom_basis.cpp).
Eigen::VectorXd angle_gradient(const Model& model, const Eigen::VectorXd& u);

class KeptPoints {
 public:
  /// Points of basis.elements with the materials of `model` (same mesh as the basis).
  KeptPoints(const Model& model, const ReducedBasis& basis);

  int size() const { return static_cast<int>(element_.size()); }
  int element(int i) const { return element_[i]; }
  std::size_t history_size() const { return history_size_; }
  std::vector<double> initial_history() const;
  /// Per point: (fatigue damage, viscous strain) from its committed history (2 values per point).
  std::vector<double> history_scalars(const std::vector<double>& history) const;
  /// The kept points' history (this class's layout) copied from a full history laid out as
  /// `full`'s (Assembler::element_state): point i of element e, quadrature point q.
  void gather_history(const Assembler& full, std::span<const double> full_state, std::span<double> kept) const;

  /// Hyper-reduced Galerkin force g (r + 1: theta, q) at (theta, q) and, with `jac`, its Jacobian
  /// (r + 1) x (r + 1). History: reads `old`, writes the trial state to `trial` (both may be empty
  /// for materials without history). Deterministic for any thread count (chunks summed in order).
  /// Throws PhysicsError naming the element of the first point (lowest index) that inverted or gave
  /// a non-finite stress.
  void force(double theta, const Eigen::VectorXd& q, const TimeStep& ts, std::span<const double> old,
             std::span<double> trial, Eigen::VectorXd& g, Eigen::MatrixXd* jac) const;

 private:
  struct Group {
    const Material* material;
    int begin, end;             ///< points [begin, end)
    std::size_t state_offset;   ///< into the history vector
    int state_size;             ///< per point
  };
  const ReducedBasis& basis_;
  int r_ = 0, ns_ = 0, nqp_ = 0;
  std::vector<int> element_;      ///< per point
  std::vector<double> weight_;    ///< per point: ECSW weight x quadrature weight (m^3)
  std::vector<Mat3> F_, dF_;      ///< [sample][point]: path F and its spline slope
  std::vector<Mat3> T_, dT_;      ///< [sample][point]: gradient of the theta row's test vector w, its slope
  std::vector<double> B_;         ///< [point][9][r]: dF/dq
  std::vector<Group> groups_;
  std::size_t history_size_ = 0;
  const Material* point_material(int i) const;
};

}  // namespace pneufem::rom_detail

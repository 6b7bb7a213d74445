#pragma once
// The cantilever the solver tests share (test_static_solver.cpp, test_relaxation.cpp,
// test_explicit.cpp): a neo-Hookean beam (nu = 0.3) clamped at x = 0 under gravity along -z.
#include <cmath>

#include <Eigen/Core>

#include "engine/model.h"
#include "tests/engine/test_meshes.h"

namespace pneufem::testing {

struct Beam {
  Model model;
  double L = 0.1, b = 0.01, h = 0.01, E, nu, q;
};
inline Beam cantilever(int nx, int nyz, ElementType type) {
  Beam beam;
  const double mu = 1e6, K = 2.1667e6;  // nu = (3K - 2mu) / (2 (3K + mu)) = 0.3000
  beam.E = 9 * K * mu / (3 * K + mu);
  beam.nu = (3 * K - 2 * mu) / (2 * (3 * K + mu));
  beam.model = single_part_model(box(beam.L, beam.b, beam.h, nx, nyz, nyz, type), neo_hookean(mu, K), 1000.0);
  fix(beam.model, nodes_on_plane(beam.model.mesh, 0, 0.0), {true, true, true});
  beam.model.gravity_m_s2 = Eigen::Vector3d(0, 0, -0.5);  // tip deflection ~ 1e-4 L: linear regime
  beam.q = 1000.0 * 0.5 * beam.b * beam.h;                // N/m
  return beam;
}
inline double tip_deflection(const Model& model, const Eigen::VectorXd& u, double L) {
  double sum = 0;
  int n = 0;
  for (int i = 0; i < model.mesh.num_nodes(); ++i)
    if (std::abs(model.mesh.X[i].x() - L) < 1e-12) {
      sum += u[3 * i + 2];
      ++n;
    }
  return -sum / n;
}

}  // namespace pneufem::testing

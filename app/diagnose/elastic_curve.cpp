#include "app/diagnose/elastic_curve.h"

#include <Eigen/Dense>
#include <cmath>

#include "engine/angle.h"
#include "engine/assembly.h"
#include "engine/static_solver.h"
#include "scenes/build_model.h"

namespace pneufem {

std::vector<double> static_angle_curve(const BuiltModel& bm, double hi_Pa, int n) {
  const Assembler A(bm.model);
  StaticSolver solver(A, bm.solver.quasi_static.newton);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(bm.model.num_dofs());
  std::vector<double> state;
  // Gravity alone (a long actuator on its side sags far: StaticSolver ramps the weight in when the
  // first solve fails).
  solver.advance(0.0, 0.0, 0.0, 0.0, state, u);
  std::vector<double> th = {bending_angle(bm.model, u).angle_deg};
  for (int i = 1; i <= n; ++i) {
    solver.advance(hi_Pa * (i - 1) / n, hi_Pa * i / n, 0.0, 0.0, state, u);
    th.push_back(unwrap_deg(bending_angle(bm.model, u).angle_deg, th.back()));
  }
  return th;
}

double rig_angle_node_rad(int j) { return j * 3.14159265358979323846 / 4.0; }

std::array<double, kRigAngleNodes> rig_angle_weights(double phi_rad) {
  auto basis = [](double a) {
    Eigen::Matrix<double, kRigAngleNodes, 1> b;
    b << 1.0, std::cos(a), std::sin(a), std::cos(2 * a), std::sin(2 * a);
    return b;
  };
  // Interpolation matrix M_jk = basis_k(phi_j): f(phi) = basis(phi)^T M^-1 f_nodes, so the weights
  // solve M^T w = basis(phi).
  Eigen::Matrix<double, kRigAngleNodes, kRigAngleNodes> M;
  for (int j = 0; j < kRigAngleNodes; ++j) M.row(j) = basis(rig_angle_node_rad(j)).transpose();
  const Eigen::Matrix<double, kRigAngleNodes, 1> w = M.transpose().partialPivLu().solve(basis(phi_rad));
  std::array<double, kRigAngleNodes> out;
  for (int j = 0; j < kRigAngleNodes; ++j) out[j] = w(j);
  return out;
}

double smooth_node(int j) { return 0.5 * (1.0 - std::cos(j * 3.14159265358979323846 / (kSmoothNodes - 1))); }

NodeRun longest_reachable_run(const std::vector<bool>& reachable, std::size_t min_count) {
  NodeRun best;
  for (std::size_t lo = 0; lo < reachable.size();) {
    std::size_t hi = lo;
    while (hi < reachable.size() && reachable[hi]) ++hi;
    if (hi - lo > best.count) best = {lo, hi - lo};
    lo = hi + 1;
  }
  return best.count >= min_count ? best : NodeRun{};
}

std::vector<double> lagrange_weights(const std::vector<double>& nodes, double x) {
  std::vector<double> w(nodes.size());
  for (std::size_t j = 0; j < nodes.size(); ++j) {
    double l = 1.0;
    for (std::size_t k = 0; k < nodes.size(); ++k)
      if (k != j) l *= (x - nodes[k]) / (nodes[j] - nodes[k]);
    w[j] = l;
  }
  return w;
}

std::array<double, kSmoothNodes> smooth_weights(double x) {
  std::vector<double> nodes;
  for (int j = 0; j < kSmoothNodes; ++j) nodes.push_back(smooth_node(j));
  const std::vector<double> w = lagrange_weights(nodes, x);
  std::array<double, kSmoothNodes> out;
  for (int j = 0; j < kSmoothNodes; ++j) out[j] = w[j];
  return out;
}

}  // namespace pneufem

#include "engine/relaxation.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "engine/static_solver.h"

namespace pneufem {

RelaxationReport relax(const Assembler& asmb, double p, const TimeStep& ts, std::span<const double> s_old,
                       std::span<double> s_new, Eigen::VectorXd& u, const RelaxationOptions& opt) {
  const int n = asmb.num_dofs();
  const auto& fixed = asmb.model().fixed;
  SparseMatrix K = asmb.tangent_pattern();
  Eigen::VectorXd f_int, f_ext(n), v = Eigen::VectorXd::Zero(n), minv(n);
  RelaxationReport rep;
  rep.reference_N = reference_force_floor(asmb);
  auto residual = [&](bool tangent) {
    f_ext.setZero();
    asmb.internal(u, ts, s_old, s_new, &f_int, tangent ? &K : nullptr, nullptr);
    asmb.add_pressure(u, p, f_ext, tangent ? &K : nullptr);
    asmb.add_gravity(f_ext);
    Eigen::VectorXd R = f_ext - f_int;  // out-of-balance force
    asmb.zero_fixed(R);
    rep.reference_N = std::max({rep.reference_N, f_ext.norm(), f_int.norm()});
    return R;
  };
  auto update_masses = [&] {
    const Eigen::VectorXd rows = asmb.row_abs_sums(K);
    for (int i = 0; i < n; ++i) minv[i] = fixed[i] ? 0.0 : 1.0 / (opt.mass_factor * rows[i] + 1e-300);
  };
  Eigen::VectorXd R = residual(true);
  update_masses();
  double KE_prev = 0.0;
  for (rep.iterations = 0; rep.iterations < opt.max_iterations; ++rep.iterations) {
    rep.residual_N = R.norm();
    if (!std::isfinite(rep.residual_N)) throw PhysicsError("dynamic relaxation diverged (non-finite residual)", -1, ts.time_s);
    if (rep.residual_N <= opt.rel_tol * rep.reference_N + opt.abs_tol_N) {
      rep.converged = true;
      return rep;
    }
    v += minv.cwiseProduct(R);  // dt = 1
    double KE = 0.0;
    for (int i = 0; i < n; ++i)
      if (minv[i] > 0) KE += 0.5 * v[i] * v[i] / minv[i];
    if (KE < KE_prev) {
      // Kinetic-energy peak passed: the configuration is near a local minimum of the energy
      // along the current path, so restart from rest there (kinetic damping).
      v.setZero();
      KE = 0.0;
      ++rep.kinetic_peaks;
    } else {
      u += v;
    }
    KE_prev = KE;
    const bool refresh = (rep.iterations + 1) % opt.mass_update_interval == 0;
    R = residual(refresh);
    if (refresh) update_masses();
  }
  return rep;
}

}  // namespace pneufem

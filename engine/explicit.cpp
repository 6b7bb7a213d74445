#include "engine/explicit.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/errors.h"

namespace pneufem {

double EnergyBalance::relative_error() const {
  const double scale = std::max({std::abs(external_work_J), kinetic_J, std::abs(internal_J), 1e-300});
  return std::abs(external_work_J - kinetic_J - internal_J - damping_J) / scale;
}

ExplicitIntegrator::ExplicitIntegrator(const Assembler& assembler, ExplicitOptions options)
    : asm_(assembler), opt_(options) {
  const int n = asm_.num_dofs();
  m_ = asm_.lumped_mass();
  stats_.physical_mass_kg = m_.sum();
  u_ = Eigen::VectorXd::Zero(n);
  v_ = Eigen::VectorXd::Zero(n);
  state_ = asm_.initial_state();
  trial_ = state_;
  K_ = asm_.tangent_pattern();
}

Eigen::VectorXd ExplicitIntegrator::external(double t, const PressureFn& pressure) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(asm_.num_dofs());
  asm_.add_pressure(u_, pressure(t), f, nullptr);
  asm_.add_gravity(f);
  return f;
}

double ExplicitIntegrator::estimate_stable_dt() {
  asm_.internal(u_, TimeStep{t_, 0.0}, state_, trial_, nullptr, &K_, nullptr);
  const Eigen::VectorXd rows = asm_.row_abs_sums(K_);
  const int nn = asm_.model().mesh.num_nodes();
  double w2max = 0.0;
  // Mass scaling: node i needs m_i >= rows_i * (dt_target / (2 safety))^2.
  const double need = opt_.target_dt_s > 0 ? std::pow(opt_.target_dt_s / (2.0 * opt_.dt_safety), 2) : 0.0;
  const Eigen::VectorXd& m_phys = asm_.lumped_mass();
  for (int i = 0; i < nn; ++i) {
    double r = 0.0;
    for (int k = 0; k < 3; ++k)
      if (!asm_.model().fixed[3 * i + k]) r = std::max(r, rows[3 * i + k]);
    if (need > 0.0) m_[i] = std::max(m_[i], std::max(m_phys[i], r * need));
    if (r > 0.0) w2max = std::max(w2max, r / m_[i]);
  }
  stats_.added_mass_kg = m_.sum() - stats_.physical_mass_kg;
  ++stats_.stability_estimates;
  return w2max > 0.0 ? opt_.dt_safety * 2.0 / std::sqrt(w2max) : 1.0;
}

double ExplicitIntegrator::added_mass_force_share() const {
  if (f_int_.size() == 0 || stats_.added_mass_kg <= 0.0) return 0.0;
  const auto& fixed = asm_.model().fixed;
  const Eigen::VectorXd& m_phys = asm_.lumped_mass();
  double fake2 = 0.0, ext2 = 0.0, int2 = 0.0;
  for (int i = 0; i < f_int_.size(); ++i) {
    if (fixed[i]) continue;
    const double share = (m_[i / 3] - m_phys[i / 3]) / m_[i / 3];
    const double r = share * (f_ext_[i] - f_int_[i]);
    fake2 += r * r;
    ext2 += f_ext_[i] * f_ext_[i];
    int2 += f_int_[i] * f_int_[i];
  }
  const double scale2 = std::max(ext2, int2);
  return scale2 > 0.0 ? std::sqrt(fake2 / scale2) : 0.0;
}

void ExplicitIntegrator::run(double t_end, const PressureFn& pressure, int observe_every,
                             const std::function<void(double, const Eigen::VectorXd&, const Eigen::VectorXd&)>& observer) {
  const int n = asm_.num_dofs();
  const auto& fixed = asm_.model().fixed;
  Eigen::VectorXd minv(n);
  auto refresh_mass = [&] {
    for (int i = 0; i < n; ++i) minv[i] = fixed[i] ? 0.0 : 1.0 / m_[i / 3];
  };
  auto new_dt = [&] {
    const double est = estimate_stable_dt();
    return opt_.fixed_dt_s > 0.0 ? opt_.fixed_dt_s : est;
  };
  if (dt_ == 0.0 || stats_.steps % std::max(1, opt_.stability_interval) == 0) dt_ = new_dt();
  refresh_mass();
  Eigen::VectorXd f_int, f_ext = external(t_, pressure);
  double IE = 0.0;
  asm_.internal(u_, TimeStep{t_, 0.0}, state_, trial_, &f_int, nullptr, &IE);
  double a = opt_.damping_alpha_1_s;
  long local_steps = 0;
  double KE0 = 0.0;  // energy present at the start (initial velocities)
  for (int i = 0; i < n; ++i) KE0 += 0.5 * m_[i / 3] * v_[i] * v_[i];
  const double E0 = KE0 + IE;
  while (t_ < t_end - 1e-15) {
    if (local_steps > 0 && local_steps % std::max(1, opt_.stability_interval) == 0) {
      dt_ = new_dt();
      refresh_mass();
    }
    const double dt = std::min(dt_, t_end - t_);
    stats_.dt_s = dt_;
    stats_.dt_min_s = stats_.dt_min_s == 0.0 ? dt_ : std::min(stats_.dt_min_s, dt_);
    // v^{n+1/2}
    const Eigen::VectorXd v_old = v_;
    v_ = ((1.0 - 0.5 * a * dt) * v_ + dt * minv.cwiseProduct(f_ext - f_int)) / (1.0 + 0.5 * a * dt);
    const Eigen::VectorXd du = dt * v_;
    // Energy: trapezoidal external work, damping work with the mid-step velocity.
    const Eigen::VectorXd f_ext_old = f_ext;
    const Eigen::VectorXd f_int_old = opt_.adaptive_damping ? f_int : Eigen::VectorXd();
    u_ += du;
    t_ += dt;
    f_ext = external(t_, pressure);
    try {
      asm_.internal(u_, TimeStep{t_, dt}, state_, trial_, &f_int, nullptr, &IE);
    } catch (const PhysicsError& e) {
      std::ostringstream s;
      s << "explicit step failed at t = " << t_ << " s with dt = " << dt << " s (the step may be unstable, or "
        << "the structure collapsed): " << e.what();
      throw PhysicsError(s.str(), e.element(), t_);
    }
    state_.swap(trial_);
    asm_.update_nonlocal(u_, state_);  // non-local drivers (a no-op without them)
    if (opt_.adaptive_damping) {
      double num = 0.0, den = 0.0;
      for (int i = 0; i < n; ++i)
        if (!fixed[i]) {
          num += du[i] * (f_int[i] - f_int_old[i]);
          den += du[i] * m_[i / 3] * du[i];
        }
      if (den > 0.0 && num > 0.0) a = 2.0 * std::sqrt(num / den);
    }
    energy_.external_work_J += 0.5 * du.dot(f_ext_old + f_ext);
    Eigen::VectorXd mv(n);
    for (int i = 0; i < n; ++i) mv[i] = m_[i / 3] * v_[i];
    energy_.damping_J += a * du.dot(mv);
    energy_.internal_J = IE;
    // Kinetic energy at the integer step (average of the half-step velocities).
    const Eigen::VectorXd vn = 0.5 * (v_old + v_);
    double KE = 0.0;
    for (int i = 0; i < n; ++i) KE += 0.5 * m_[i / 3] * vn[i] * vn[i];
    energy_.kinetic_J = KE;
    ++stats_.steps;
    ++local_steps;
    // Instability shows as kinetic energy far above all the work put in (energy balance).
    const double budget = std::max({std::abs(energy_.external_work_J) + E0, std::abs(IE), 1e-30});
    if (!v_.allFinite() || KE > 10.0 * budget) {
      int node = 0;
      double vmax = -1.0;
      for (int i = 0; i < n / 3; ++i)
        if (v_.segment<3>(3 * i).allFinite() && v_.segment<3>(3 * i).norm() > vmax) {
          vmax = v_.segment<3>(3 * i).norm();
          node = i;
        }
      std::ostringstream s;
      s << "explicit integration became unstable at t = " << t_ << " s (kinetic energy " << KE
        << " J exceeds the work done " << budget << " J; fastest node " << asm_.model().mesh.node_name(node)
        << "), dt = " << dt << " s. Hint: use the estimated stable step (remove solver.dt_s), lower "
        << "solver.dt_safety, or enable selective mass scaling (solver.target_dt_s).";
      throw PhysicsError(s.str(), -1, t_);
    }
    if (observer && (local_steps % std::max(1, observe_every) == 0 || t_ >= t_end - 1e-15)) observer(t_, u_, v_);
  }
  f_int_ = f_int;
  f_ext_ = f_ext;
}

}  // namespace pneufem

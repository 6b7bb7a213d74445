#include "engine/cycle_jump.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace pneufem {

namespace {
/// Calls f(material, p, offset, size) for every material point with history: p its index among all
/// points (element-major, as the quadrature weights), offset and size its slice of the state.
template <class F>
void for_each_point(const Assembler& asmb, F&& f) {
  const int ne = asmb.model().mesh.num_elements();
  const int nqp = asmb.geometry().nqp;
  std::size_t o = 0, p = 0;
  for (int e = 0; e < ne; ++e) {
    const Material& mat = asmb.model().material_of(e);
    const std::size_t ss = static_cast<std::size_t>(mat.state_size());
    for (int q = 0; q < nqp; ++q, o += ss, ++p)
      if (ss > 0) f(mat, p, o, ss);
  }
}
}  // namespace

bool model_jumps_cycles(const Assembler& asmb, std::string& law) {
  const int ne = asmb.model().mesh.num_elements();
  for (int e = 0; e < ne; ++e) {
    const Material& mat = asmb.model().material_of(e);
    if (!mat.jumps_cycles()) {
      law = mat.name();
      return false;
    }
  }
  return true;
}

std::vector<double> jump_history(const Assembler& asmb, std::span<const double> before, std::span<const double> after,
                                 double cycles) {
  std::vector<double> out(after.begin(), after.end());
  for_each_point(asmb, [&](const Material& mat, std::size_t, std::size_t o, std::size_t ss) {
    mat.jump_cycles(before.subspan(o, ss), after.subspan(o, ss), cycles, std::span<double>(out).subspan(o, ss));
  });
  return out;
}

void jump_point(const Material& mat, std::span<const double> first, std::span<const double> before,
                std::span<const double> after, double cycles, std::span<double> out) {
  if (!(cycles >= 0.0)) throw std::invalid_argument("jump_point: the number of cycles must be >= 0");
  if (first.size() != after.size() || before.size() != after.size() || out.size() != after.size())
    throw std::invalid_argument("jump_point: the three cycle ends and the output must be one point's state");
  // jump(x, y, c) = (1 + c) y - c x in z. P = jump(first, before, c1), then jump(P, after, c2) =
  // (1 + c2) z_k - c2 (1 + c1) z_(k-1) + c2 c1 z_(k-2); with c2 = N (N + 3) / 2, c1 = (N + 1) / (N + 3)
  // the weights are (N + 1)(N + 2) / 2, -N (N + 2), N (N + 1) / 2: (1') of cycle_jump.h.
  const double c1 = (cycles + 1.0) / (cycles + 3.0), c2 = 0.5 * cycles * (cycles + 3.0);
  std::vector<double> p(after.size());
  mat.jump_cycles(first, before, c1, p);
  mat.jump_cycles(p, after, c2, out);
}

std::vector<double> jump_history(const Assembler& asmb, std::span<const double> first, std::span<const double> before,
                                 std::span<const double> after, double cycles) {
  std::vector<double> out(after.begin(), after.end());
  for_each_point(asmb, [&](const Material& mat, std::size_t, std::size_t o, std::size_t ss) {
    jump_point(mat, first.subspan(o, ss), before.subspan(o, ss), after.subspan(o, ss), cycles,
               std::span<double>(out).subspan(o, ss));
  });
  return out;
}

std::vector<double> energy_shares(const Assembler& asmb, const Eigen::VectorXd& u, std::span<const double> state) {
  const int ne = asmb.model().mesh.num_elements();
  const int nqp = asmb.geometry().nqp;
  std::vector<double> share(static_cast<std::size_t>(ne) * nqp, 0.0);
  std::vector<Mat3> F(static_cast<std::size_t>(nqp));
  std::vector<PointResponse> r(static_cast<std::size_t>(nqp));
  double total = 0.0;
  for (int e = 0; e < ne; ++e) {
    asmb.point_responses(u, e, asmb.element_state(state, e), F, r);
    const bool history = asmb.model().material_of(e).state_size() > 0;
    for (int q = 0; q < nqp; ++q) {
      const double w = asmb.geometry().weight[static_cast<std::size_t>(e) * nqp + q];
      total += w * r[q].psi();
      if (history) share[static_cast<std::size_t>(e) * nqp + q] = w * std::max(0.0, r[q].psi_iso);
    }
  }
  if (!(total > 0.0)) return {};  // an unloaded structure: the caller weighs points by volume
  for (double& s : share) s /= total;
  return share;
}

double history_jump_error(const Assembler& asmb, const std::vector<double>& share, std::span<const double> predicted,
                          std::span<const double> computed) {
  double weighted = 0.0, volume = 0.0;
  for_each_point(asmb, [&](const Material& mat, std::size_t p, std::size_t o, std::size_t ss) {
    const double err = mat.jump_error(predicted.subspan(o, ss), computed.subspan(o, ss));
    const double w = share.empty() ? asmb.geometry().weight[p] : share[p];
    weighted += w * err;
    volume += w;
  });
  if (!share.empty()) return weighted;
  return volume > 0.0 ? weighted / volume : 0.0;
}

int cycles_to_jump(double e1, double c1, const CycleJumpOptions& opt, int max_cycles) {
  if (max_cycles < 1) return 0;
  double n = static_cast<double>(max_cycles);
  // e1 N (N + 1) / 2 <= tol: N <= (sqrt(1 + 8 tol / e1) - 1) / 2.
  if (e1 > 0.0) n = std::min(n, std::floor(0.5 * (std::sqrt(1.0 + 8.0 * opt.tol / e1) - 1.0)));
  if (c1 > 0.0) n = std::min(n, std::floor(opt.change / c1));
  return std::max(0, static_cast<int>(n));
}

}  // namespace pneufem

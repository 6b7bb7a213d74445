#pragma once
// Cycle jumping: skipping load cycles (trials) whose history can be extrapolated.
//
// Many repetitions of one load cycle change a structure's history slowly and smoothly from cycle to
// cycle, so that the history after cycle k + N follows from the last computed cycles; "cycle
// jumping" (Lemaitre & Doghri 1994; Van Paepegem, Degrieck & De Baets 2001, "Finite element
// approach for modelling fatigue damage in fibre-reinforced composite materials", Compos. B 32;
// Cojocaru & Karlsson 2006, "A simple numerical method of cycle jumps for cyclically loaded
// structures", Int. J. Fatigue 28; the damage extrapolation of Abaqus's direct cyclic low-cycle
// fatigue analysis) computes some cycles, extrapolates every integration point's history over the
// next N and carries on computing from there.
//
// Here a cycle is a trial of the load history, and its end (the state before the release to the
// next trial's rest) is where the history is compared and extrapolated. With H_k the committed
// history at the end of cycle k, each law extrapolates its variables linearly in a measure z that
// grows about linearly per cycle (Material::jump_cycles: the fatigue integrity's s^(1-n), the
// Mullins peak energy; the Prony branches are not extrapolated: the rest after the jump sets them):
//   z_(k+N) = z_k + N (z_k - z_(k-1))                                              (1)
// The displacement is the last computed cycle's end; the release and rest that follow it, and the
// cycle after the jump, are computed as usual from the extrapolated history.
//
// (1) misses the change of z's increment from cycle to cycle, and that change has one sign where it
// matters: near a threshold (the fatigue law's lambda_th, W_th) a softening structure strains its hot
// points a little more each cycle, which raises their small driver above the threshold by a much
// larger fraction, so their z accelerates; (1) under-predicts the damage at every such point, and
// every jump leaves the computed cycles after it stiffer by the same sign (on the h = 6 story each
// one-trial jump left the following trials ~0.2 deg low, and the offsets added up). The default rule
// is therefore the three-point (quadratic) one through the last three cycle ends,
//   z_(k+N) = z_k + N D_k + N (N + 1) / 2 (D_k - D_(k-1)),   D_k = z_k - z_(k-1),          (1')
// exact when z is quadratic in the cycle count (a steadily changing increment), built from two
// applications of each law's linear rule (1) (an affine combination in z composes; jump_point),
// and with each law's clips of (1) on both: damage never heals, so a settling history whose
// increment falls fast, D_k < (N + 1) / (N + 3) D_(k-1) (by more than half at N = 1), is held where it is.
// For increments that change geometrically, D_(k+m) = r^m D_k, the clipped (1') is closer than (1)
// for any r > 0 at N = 1 (error D_k (1 - r)^2 / r, or r D_k when clipped, against |1 - r| D_k), the
// case the control below allows.
//
// Error control (the cycle-space analogue of Milne's device in engine/quasi_static.h). (1) is exact
// when z is linear in the cycle count; when its increment changes by delta per cycle, the jump's
// error after N cycles is delta (1 + 2 + ... + N) = delta N (N + 1) / 2. delta is measured by the one-
// cycle jump from the two cycles before the last and compared with the last, computed one:
//   e_1 = sum over points of f_p jump_error_p(jump(H_(k-2), H_(k-1), 1), H_k)         (2)
// with the point errors in units of the isochoric stiffness fraction (Material::jump_error: fatigue
// |ds|; Mullins the largest change of eta its W_max difference can cause) and f_p the point's share
// of the structure's stored energy at the end of the last computed trial (its quadrature volume
// times psi_iso, over the whole structure's energy). Why: scaling the isochoric stiffness at a point
// by (1 - delta_p) changes the compliance of a structure under a given load, to first order, by
// sum_p f_p delta_p of itself (Clapeyron's theorem: the sensitivity of the compliance to a stiffness
// perturbation), and the angle at a given pressure with it. So e_1 estimates the relative error of
// the response a one-trial jump makes, and tol bounds a relative error of the angle. The largest
// point error would not do: it sits at a re-entrant chamber corner, whose singular field makes it a
// property of the mesh (on the 3-chamber pneu-net it refused every jump while the angles moved by
// hundredths of a degree), and points that carry no energy do not move the angle.
// The same second difference of what is reported, the angles a_r of the last three trials at each
// report r, is a direct check that needs no model of how the history acts on the response:
//   e_a = max_r |a_r,k - 2 a_r,(k-1) + a_r,(k-2)| / max(max_r |a_r,k|, 1 deg)         (2')
// (it is also the error of the skipped trials' reports, which are extrapolated linearly in the trial
// count). It matters near a limit point, where a small change of compliance moves the angle much
// more: on the h = 6 story (52 -> 75 deg over ten trials) the jump that e_1 allowed after trial 3
// reported trial 4's angle at the 45 kPa mark 0.43 deg off (e_a = 0.7 %), and the history
// extrapolated over one trial put the next computed trials 0.2 deg off.
// A jump by N from (H_(k-1), H_k) is taken with the largest N such that
//   max(e_1, e_a) N (N + 1) / 2 <= tol,       c_1 N <= change,       N <= cycles left - 1,    (3)
// where c_1 = sum_p f_p jump_error_p(H_(k-1), H_k) is the last cycle's change: (2) is an
// estimate from three cycles and the history's effect on the stress is nonlinear, so the total
// change a jump may add is bounded as well (the "maximum damage increment" of Abaqus's and Van
// Paepegem's jump rules). The last cycle is always computed. A jump needs three consecutive computed
// cycle ends, so at least two cycles are computed after each jump (the one-cycle estimate (2) then
// checks the extrapolated start, as Cojocaru and Karlsson's control cycles do).
// With (1'), (2) still measures the error of the linear rule (1), so (3) bounds the error of the
// lower-order rule while the run advances with the higher-order one: the "local extrapolation" of
// embedded Runge-Kutta pairs (Hairer, Norsett & Wanner, Solving Ordinary Differential Equations I,
// 2nd ed., Sec. II.4), a conservative control. The skipped cycles' reports stay linear in the trial
// count, since (2') is their error: reported angles mix effects whose increments change with
// opposite signs while the trials settle, and on the story a three-point rule on the angles was
// worse than the linear one up to trial 8.
#include <span>
#include <string>
#include <vector>

#include "engine/assembly.h"

namespace pneufem {

struct CycleJumpOptions {
  bool on = false;      ///< off: every cycle is computed
  double tol = 0.005;  ///< bound of the estimated extrapolation error (3), relative compliance (~ angle)
  double change = 0.1; ///< bound of the history change one jump adds (3), relative compliance
  int order = 2;        ///< the history's rule: 1 the linear (1), 2 the three-point (1')
};

/// True when every material of the model says how its history extrapolates (Material::jumps_cycles);
/// otherwise `law` gets the first one that does not.
bool model_jumps_cycles(const Assembler& asmb, std::string& law);

/// (1) for every point: the history `cycles` cycles after `after`, from the cycle ends before and after.
std::vector<double> jump_history(const Assembler& asmb, std::span<const double> before, std::span<const double> after,
                                 double cycles);

/// (1') for one point of `mat`: the state `cycles` cycles after `after`, from its states at the ends
/// of three consecutive cycles (first, before, after), by two applications of mat.jump_cycles (1):
/// P = jump(first, before, (N + 1) / (N + 3)), then jump(P, after, N (N + 3) / 2), which is (1') for
/// a law linear in its measure z (material.h's contract) wherever the law's clips do not act.
void jump_point(const Material& mat, std::span<const double> first, std::span<const double> before,
                std::span<const double> after, double cycles, std::span<double> out);

/// (1') for every point: the history `cycles` cycles after `after`, from three consecutive cycle ends.
std::vector<double> jump_history(const Assembler& asmb, std::span<const double> first, std::span<const double> before,
                                 std::span<const double> after, double cycles);

/// f_p of (2): per material point (history_scalars' order), its share of the stored energy at (u, state);
/// empty when the structure stores no energy (unloaded).
std::vector<double> energy_shares(const Assembler& asmb, const Eigen::VectorXd& u, std::span<const double> state);

/// (2): sum_p f_p Material::jump_error(predicted, computed) with f = energy_shares (empty: the volume
/// mean of the point errors over the points with history).
double history_jump_error(const Assembler& asmb, const std::vector<double>& share, std::span<const double> predicted,
                          std::span<const double> computed);

/// The largest N of (3) for a one-cycle error estimate e1 and last change c1, at most max_cycles (>= 0).
int cycles_to_jump(double e1, double c1, const CycleJumpOptions& opt, int max_cycles);

}  // namespace pneufem

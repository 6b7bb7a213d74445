#pragma once
// Chamber pressure lagging the inlet (load.pressure_lag_s, load.pressure_lag2_s).
//
// FIRST ORDER (load.pressure_lag_s = tau, load.pressure_lag2_s = 0): the tubing and the valve's
// flow resistance make the chamber pressure p_c follow the inlet pressure p_in as
//     tau dp_c/dt = p_in - p_c.
// For a piecewise-linear inlet, p_in = a + b (t - t_a) on a segment [t_a, t_b], the exact solution is
//     p_c(t) = p_in(t) - b tau + C exp(-(t - t_a) / tau),   C = p_c(t_a) - a + b tau,        (1)
// smooth within the segment. The lagged history is again piecewise linear, with breakpoints placed
// so that its linear interpolation is within `tolerance_Pa` of (1) everywhere:
//   * between breakpoints h apart, the interpolation error of a C2 function is <= h^2/8 max|p_c''|,
//     with p_c'' = C/tau^2 exp(-s/tau) largest at the interval's start s, so h = tau sqrt(8 tol e^{s/tau}/|C|);
//   * once |C| exp(-s/tau) <= tol the transient is below tol and p_c is the straight line
//     p_in - b tau to within tol: the segment's end is the next breakpoint.
//
// SECOND ORDER (load.pressure_lag2_s = tau2 > 0): the lumped pneumatic line, the standard
// resistance-inertance-capacitance model of a fluid line feeding a volume (e.g. Doebelin, System
// Dynamics, 1998, fluid systems; the first mode of a distributed line model such as Richer &
// Hurmuzlu's, ASME J. Dyn. Syst. Meas. Control 122, 2000): the tube's flow q obeys
// L dq/dt = p_in - p_c - R q (inertance L = rho l / A of the air in a tube of length l and bore A,
// resistance R), the chamber C dp_c/dt = q (compliance C = dV/dp + V/(kappa p), large for a soft
// chamber), so
//     tau2^2 p_c'' + tau p_c' + p_c = p_in,        tau = R C,  tau2 = sqrt(L C).                (2)
// Why this form and not two first-order lags in series: (2) holds both. Its damping ratio is
// zeta = tau / (2 tau2) and natural frequency f_n = 1 / (2 pi tau2):
//   * tau2 <= tau/2 (zeta >= 1): two RC stages in series, time constants T1,2 = (tau +- sqrt(tau^2 -
//     4 tau2^2)) / 2 (T1 + T2 = tau, T1 T2 = tau2^2) -- a narrow tube, resistance dominating;
//   * tau2 > tau/2 (zeta < 1): under-damped, the chamber overshoots the inlet -- a wide or long tube
//     whose air column's inertia rings against the chamber's compliance (a 4 mm bore, 2 m tube into
//     a 20 mL chamber gives f_n ~ 1 Hz, lower for a compliant one); two RC stages cannot overshoot,
//     and the recording tests/data/othermeans/lag_second_order.csv (f_n 0.6 Hz, zeta 0.45) does.
// tau keeps its first-order meaning for every tau2: it is the mean delay of the impulse response
// (-H'(0) of H = 1 / (1 + tau s + tau2^2 s^2)), the distance by which the chamber trails a ramp; tau2
// is the "inertial" time, and tau2 -> 0 is the first-order lag (tau2 = 0 runs the first-order code,
// bit for bit).
//
// Exact solution of (2) on a segment p_in = a + b s (s = t - t_a), from p_c(t_a) = x0, p_c'(t_a) = v0:
// the particular solution is the line a + b (s - tau), and the transient e = p_c - a - b (s - tau)
// solves tau2^2 e'' + tau e' + e = 0 with e0 = x0 - a + b tau, e0' = v0 - b. With sigma = tau / (2
// tau2^2) and q = sigma^2 - 1/tau2^2 = (tau^2 - 4 tau2^2) / (4 tau2^4),
//     e(s)  = e0 E(s) + (e0' + sigma e0) F(s),
//     e'(s) = e0' E(s) - (e0 / tau2^2 + sigma e0') F(s),                                         (3)
// E = exp(-sigma s) cos(w s), F = exp(-sigma s) sin(w s) / w with w = sqrt(-q) (under-damped), and
// E = exp(-k s) (1 + exp(-2 g s)) / 2, F = exp(-k s) (1 - exp(-2 g s)) / (2 g) with g = sqrt(q),
// k = sigma - g = 1 / T1 otherwise (F = s exp(-k s) at critical damping): written so, neither form
// cancels near zeta = 1 nor overflows for tau2 << tau. (Check: E(0) = 1, F(0) = 0, E' = -sigma E + q F,
// F' = E - sigma F, hence (3) and e(0) = e0, e'(0) = e0'.) p_c and p_c' carry over the breakpoints.
// Breakpoints: y = e'' solves the same equation, so its energy y^2 + tau2^2 y'^2 never grows
// (d/ds = -2 tau y'^2); max|p_c''| over [s, infinity) is <= sqrt(e''(s)^2 + tau2^2 e'''(s)^2) =: M(s)
// (e'' and e''' from the equation), and h = sqrt(8 tol / M(s)) as above; once sqrt(e^2 + tau2^2
// e'^2) <= tol/2 the transient stays below tol/2 and, oscillating, a chord is within tol of p_c:
// the segment's end is the next breakpoint.
//
// Each trial starts in equilibrium (p_c(0) = p_in(0), p_c'(0) = 0): trials are separated by venting
// and rest. Only time_s / pressure_Pa change: report times, steps and marks keep referring to the
// inlet command times.
#include "engine/load_history.h"

namespace pneufem {

class Scene;

/// The lag (2): tau_s = 0 is none; tau2_s = 0 is the first-order lag (1).
struct PressureLag {
  double tau_s = 0.0;   ///< load.pressure_lag_s: the mean delay (the first-order time constant)
  double tau2_s = 0.0;  ///< load.pressure_lag2_s: sqrt(inertance x compliance); 0 = first order
  bool on() const { return tau_s > 0.0; }
};

/// The scene's lag, validated: a negative or non-finite value, or tau2 > 0 without tau, is an
/// InputError naming the key (Scene::fail).
PressureLag scene_pressure_lag(const Scene& scene);

/// The chamber history of `inlet` through the first-order lag tau_s (> 0), within tolerance_Pa (> 0).
LoadHistory apply_pressure_lag(const LoadHistory& inlet, double tau_s, double tolerance_Pa);

/// The chamber history of `inlet` through the lag (2) (tau_s > 0, tau2_s >= 0), within
/// tolerance_Pa (> 0); tau2_s = 0 is the first-order overload, bit for bit. A history that would
/// need more than 64 breakpoints per inlet point (+ 10^5) per trial (a tau2_s many decades below
/// the inlet's sampling) is a PhysicsError naming both keys, not a runaway allocation.
LoadHistory apply_pressure_lag(const LoadHistory& inlet, const PressureLag& lag, double tolerance_Pa);

/// Exact chamber pressure (1) of one trial at time t (for tests and synthetic data).
double lagged_pressure(const TrialLoad& inlet, double tau_s, double t);

/// Exact chamber pressure (3) of one trial at time t; tau2_s = 0 is (1).
double lagged_pressure(const TrialLoad& inlet, const PressureLag& lag, double t);

}  // namespace pneufem

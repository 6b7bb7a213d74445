#pragma once
// Chamber pressure lagging the inlet (load.pressure_lag_s): the tubing and the valve's flow
// resistance make the chamber pressure p_c follow the inlet pressure p_in as a first-order filter
//     tau dp_c/dt = p_in - p_c.
// For a piecewise-linear inlet, p_in = a + b (t - t_a) on a segment [t_a, t_b], the exact solution is
//     p_c(t) = p_in(t) - b tau + C exp(-(t - t_a) / tau),   C = p_c(t_a) - a + b tau,        (1)
// smooth within the segment. The lagged history is again piecewise linear, with breakpoints placed
// so that its linear interpolation is within `tolerance_Pa` of (1) everywhere:
//   * between breakpoints h apart, the interpolation error of a C2 function is <= h^2/8 max|p_c''|,
//     with p_c'' = C/tau^2 exp(-s/tau) largest at the interval's start s, so h = tau sqrt(8 tol e^{s/tau}/|C|);
//   * once |C| exp(-s/tau) <= tol the transient is below tol and p_c is the straight line
//     p_in - b tau to within tol: the segment's end is the next breakpoint.
// Each trial starts in equilibrium (p_c(0) = p_in(0)): trials are separated by venting and rest.
// Only time_s / pressure_Pa change: report times, steps and marks keep referring to the inlet
// command times.
#include "engine/load_history.h"

namespace pneufem {

/// The chamber history of `inlet` through the first-order lag tau_s (> 0), within tolerance_Pa (> 0).
LoadHistory apply_pressure_lag(const LoadHistory& inlet, double tau_s, double tolerance_Pa);

/// Exact chamber pressure (1) of one trial at time t (for tests and synthetic data).
double lagged_pressure(const TrialLoad& inlet, double tau_s, double t);

}  // namespace pneufem

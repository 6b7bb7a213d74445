#pragma once
// The physical time step control shared by the full and the reduced quasi-static runs
// (engine/quasi_static.cpp, engine/rom.cpp).
#include <vector>

#include "materials/material.h"

namespace pneufem {

// One physical step's history measures over points (history_scalars layout: 2 values per point):
// the largest change |d' - d| + |e' - e| (cur -> next), and, with the previous step (prev non-empty,
// r = h / h_prev), the largest local-error estimate: the change minus the previous change
// extrapolated at constant rate, times r / (1 + r) (Milne's device for a first-order update).
struct HistoryStep {
  double change = 0.0, error = 0.0;
  int change_point = -1, error_point = -1;  ///< where they are largest (-1: nothing changed)
};
HistoryStep history_step(const std::vector<double>& prev, const std::vector<double>& cur, const std::vector<double>& next,
                         double r);

// The linear-drive error of the exponential (Prony) update (time_control = "drive",
// engine/quasi_static.h). The update Q' = exp(-x) Q + a k(x) (S0' - S0), x = h / tau, is the exact
// solution of dQ/dt + Q / tau = a dS0/dt when S0 is linear in time over the step; for a smooth S0 the
// exact solution differs by a int_0^h exp(-(h - s) / tau) (dS0/dt(s) - (S0' - S0) / h) ds, and with
// dS0/dt(s) = (S0' - S0) / h + S0'' (s - h / 2) + O(h^2) that is, to leading order,
//   a S0'' tau^2 G(x),   G(x) = (x/2 - 1)(1 - exp(-x)) + x exp(-x)
//                             = x^3/12 - x^4/24 + ...  (h << tau),   ~ x/2 - 1  (h >> tau).
// G is increasing (G'(x) = (1 - (1 + x) exp(-x)) / 2 > 0), so the error grows with h at any x: like
// h^3 / tau for short steps (the exponential update is then third-order locally in the drive's
// curvature, not first-order as a backward-Euler rate law), like tau h / 2 for long ones (the branch
// then follows the drive with lag tau, whose error is tau S0'' h / 2).
double prony_interpolation_G(double x);
/// The error of a point with Material::LinearDrive `d` over a step h where |D''| = c:
/// c sum_i a_i tau_i^2 G(h / tau_i).
double linear_drive_error(const Material::LinearDrive& d, double c, double h);

}  // namespace pneufem

#pragma once
// The physical time step control shared by the full and the reduced quasi-static runs
// (engine/quasi_static.cpp, engine/rom.cpp).
#include <vector>

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

}  // namespace pneufem

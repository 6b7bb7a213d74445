#pragma once
// Integral-type non-local averaging of a quantity known at material points (Pijaudier-Cabot &
// Bazant 1987, "Nonlocal damage theory", J. Eng. Mech. 113(10), eq. 5; the weight of Bazant &
// Jirasek 2002, "Nonlocal integral formulations of plasticity and damage", J. Eng. Mech. 128(11),
// eq. 7):
//
//   X_bar_i = sum_j V_j a(|X_i - X_j|) X_j / sum_j V_j a(|X_i - X_j|),   a(r) = (1 - r^2 / R^2)^2, r < R,
//
// over the points j of the same group within the interaction radius R, in the reference
// configuration, V_j being the point's integration volume (m^3). The truncated quartic
// ("bell-shaped") weight has compact support, so a point has a short neighbour list. The
// normalisation makes a constant field its own average, also near boundaries.
//
// Why: a damage law driven by a local quantity (the fatigue law's stretch or energy) is ill-posed
// where that quantity is singular, e.g. at the re-entrant corners of a pneu-net's chambers: its
// damage there grows without bound as the mesh is refined, and so does the structure's drift over
// repeated use (BENCHMARKS.md §7). Averaging the driver over a material length R makes the damage
// field, and the drift, converge under refinement once the elements are well below R.
//
// Neighbour lists are built once (a uniform grid of cell size R) and stored sorted with their
// normalised weights, so every average sums its terms in one fixed order: the result does not
// depend on the number of threads.
#include <cstddef>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace pneufem {

class NonlocalAverage {
 public:
  struct Point {
    Eigen::Vector3d X = Eigen::Vector3d::Zero();  ///< reference position (m)
    double volume_m3 = 0.0;                       ///< integration volume (> 0)
    int group = -1;                               ///< points of one group are averaged together; < 0: not averaged
  };

  /// `radius_m[g]` > 0 is the interaction radius of group g. Throws InputError when the neighbour
  /// lists would exceed `max_pairs` (the radius is many elements wide: memory grows as (R/h)^3).
  NonlocalAverage(std::span<const Point> points, std::span<const double> radius_m, std::size_t max_pairs = 400'000'000);

  /// out[i] = the average of `value` around point i; value[i] itself for a point of no group.
  void average(std::span<const double> value, std::span<double> out) const;

  std::size_t num_points() const { return ptr_.size() - 1; }
  /// Stored (point, neighbour) pairs, the point itself included.
  std::size_t num_pairs() const { return idx_.size(); }

 private:
  std::vector<std::size_t> ptr_;  ///< CSR row pointers (size points + 1)
  std::vector<int> idx_;          ///< neighbours, ascending
  std::vector<double> w_;         ///< normalised weights V_j a_ij / sum_k V_k a_ik
};

}  // namespace pneufem

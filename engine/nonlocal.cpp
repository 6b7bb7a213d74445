#include "engine/nonlocal.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <sstream>
#include <utility>

#include <tbb/parallel_for.h>

#include "core/errors.h"

namespace pneufem {

namespace {

/// The points of one group binned into a uniform grid of cell size R: (cell key, point) sorted by
/// key, so a cell's points are one contiguous run found by binary search.
struct Grid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double cell = 1.0;
  std::int64_t nx = 1, ny = 1, nz = 1;
  std::vector<std::pair<std::int64_t, int>> entries;

  std::array<std::int64_t, 3> coords(const Eigen::Vector3d& X) const {
    std::array<std::int64_t, 3> c{};
    for (int d = 0; d < 3; ++d) c[d] = static_cast<std::int64_t>(std::floor((X[d] - origin[d]) / cell));
    return c;
  }
  std::int64_t key(std::int64_t x, std::int64_t y, std::int64_t z) const { return x + nx * (y + ny * z); }

  /// Calls f(j) for every point j in the 27 cells around X (a superset of the ball of radius cell).
  template <class F>
  void for_near(const Eigen::Vector3d& X, F&& f) const {
    const auto c = coords(X);
    for (std::int64_t z = std::max<std::int64_t>(0, c[2] - 1); z <= std::min(nz - 1, c[2] + 1); ++z)
      for (std::int64_t y = std::max<std::int64_t>(0, c[1] - 1); y <= std::min(ny - 1, c[1] + 1); ++y)
        for (std::int64_t x = std::max<std::int64_t>(0, c[0] - 1); x <= std::min(nx - 1, c[0] + 1); ++x) {
          const std::int64_t k = key(x, y, z);
          auto it = std::lower_bound(entries.begin(), entries.end(), std::make_pair(k, -1));
          for (; it != entries.end() && it->first == k; ++it) f(it->second);
        }
  }
};

Grid make_grid(std::span<const NonlocalAverage::Point> points, const std::vector<int>& members, double R) {
  Grid g;
  g.cell = R;
  Eigen::Vector3d lo = points[members.front()].X, hi = lo;
  for (int i : members) {
    lo = lo.cwiseMin(points[i].X);
    hi = hi.cwiseMax(points[i].X);
  }
  g.origin = lo;
  g.nx = static_cast<std::int64_t>(std::floor((hi.x() - lo.x()) / R)) + 1;
  g.ny = static_cast<std::int64_t>(std::floor((hi.y() - lo.y()) / R)) + 1;
  g.nz = static_cast<std::int64_t>(std::floor((hi.z() - lo.z()) / R)) + 1;
  g.entries.reserve(members.size());
  for (int i : members) {
    const auto c = g.coords(points[i].X);
    g.entries.emplace_back(g.key(c[0], c[1], c[2]), i);
  }
  std::sort(g.entries.begin(), g.entries.end());
  return g;
}

/// Bazant-Jirasek bell-shaped weight a(r) = (1 - r^2/R^2)^2 from r^2 (0 at and beyond R).
double bell(double r2, double R2) {
  const double x = 1.0 - r2 / R2;
  return x > 0.0 ? x * x : 0.0;
}

}  // namespace

NonlocalAverage::NonlocalAverage(std::span<const Point> points, std::span<const double> radius_m, std::size_t max_pairs) {
  const std::size_t n = points.size();
  std::vector<std::vector<int>> members(radius_m.size());
  for (std::size_t i = 0; i < n; ++i) {
    const int g = points[i].group;
    if (g < 0) continue;
    if (static_cast<std::size_t>(g) >= radius_m.size() || !(radius_m[g] > 0.0) || !std::isfinite(radius_m[g]))
      throw InputError("non-local averaging: point " + std::to_string(i) + " is in group " + std::to_string(g) +
                       " without a positive radius");
    if (!(points[i].volume_m3 > 0.0)) throw InputError("non-local averaging: point " + std::to_string(i) + " has no volume");
    members[g].push_back(static_cast<int>(i));
  }
  std::vector<Grid> grids(radius_m.size());
  for (std::size_t g = 0; g < members.size(); ++g)
    if (!members[g].empty()) grids[g] = make_grid(points, members[g], radius_m[g]);

  auto neighbours = [&](std::size_t i, auto&& f) {
    const int g = points[i].group;
    if (g < 0) {
      f(static_cast<int>(i), 1.0);
      return;
    }
    const double R2 = radius_m[g] * radius_m[g];
    grids[g].for_near(points[i].X, [&](int j) {
      const double a = bell((points[i].X - points[j].X).squaredNorm(), R2);
      if (a > 0.0 || j == static_cast<int>(i)) f(j, points[j].volume_m3 * a);
    });
  };
  // Pass 1: list lengths; pass 2: fill each point's own range (no sharing between threads), sort it
  // by neighbour index (a fixed summation order) and normalise.
  std::vector<std::size_t> count(n, 0);
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
    std::size_t c = 0;
    neighbours(i, [&](int, double) { ++c; });
    count[i] = c;
  });
  ptr_.assign(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ptr_[i + 1] = ptr_[i] + count[i];
  if (ptr_[n] > max_pairs) {
    std::ostringstream m;
    m << "non-local averaging: " << ptr_[n] << " neighbour pairs (" << ptr_[n] / std::max<std::size_t>(1, n)
      << " per point) exceed the limit of " << max_pairs
      << ": the interaction radius spans too many elements; choose a smaller nonlocal_radius_mm or a coarser mesh";
    throw InputError(m.str());
  }
  idx_.resize(ptr_[n]);
  w_.resize(ptr_[n]);
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
    std::vector<std::pair<int, double>> row;
    row.reserve(count[i]);
    neighbours(i, [&](int j, double w) { row.emplace_back(j, w); });
    std::sort(row.begin(), row.end());
    double sum = 0.0;
    for (const auto& [j, w] : row) sum += w;
    // sum >= the point's own volume (a(0) = 1), so it is positive.
    for (std::size_t k = 0; k < row.size(); ++k) {
      idx_[ptr_[i] + k] = row[k].first;
      w_[ptr_[i] + k] = row[k].second / sum;
    }
  });
}

void NonlocalAverage::average(std::span<const double> value, std::span<double> out) const {
  const std::size_t n = num_points();
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
    double s = 0.0;
    for (std::size_t k = ptr_[i]; k < ptr_[i + 1]; ++k) s += w_[k] * value[idx_[k]];
    out[i] = s;
  });
}

}  // namespace pneufem

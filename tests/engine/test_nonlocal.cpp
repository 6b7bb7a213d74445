// Non-local averaging (engine/nonlocal.h) and the non-local fatigue driver in the engine: the
// average against a brute-force evaluation of its defining sum, constants preserved, thread-count
// independence; and the reason it exists: at a re-entrant corner the local driver is singular, so
// the damage of a local fatigue law there grows without bound under mesh refinement, while the
// non-local law's converges.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <tbb/global_control.h>

#include "damage/effects.h"
#include "engine/assembly.h"
#include "engine/nonlocal.h"
#include "engine/quasi_static.h"
#include "core/errors.h"
#include "test_meshes.h"

namespace pneufem {
namespace {

using testing::ecoflex;
using testing::faces_where;
using testing::fix;
using testing::mapped_grid;
using testing::nodes_on_plane;
using testing::single_part_model;

std::vector<NonlocalAverage::Point> random_points(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<NonlocalAverage::Point> pts(n);
  for (int i = 0; i < n; ++i) {
    pts[i].X = Eigen::Vector3d(U(rng), U(rng), 0.3 * U(rng));
    pts[i].volume_m3 = 0.5 + U(rng);
    pts[i].group = i % 7 == 0 ? -1 : i % 3 == 0 ? 1 : 0;  // two groups and some points of none
  }
  return pts;
}

// The stored weights reproduce the defining sum X_bar_i = sum_j V_j a_ij X_j / sum_j V_j a_ij,
// a(r) = (1 - r^2/R^2)^2 (r < R), over the points of i's group, evaluated here by brute force over
// all pairs. Only the summation order differs (the normalisation is applied per weight), so they
// agree to a few ulps of the values (tolerance 1e-13 relative).
TEST(NonlocalAverage, MatchesTheBruteForceSumOfItsDefinition) {
  const std::vector<NonlocalAverage::Point> pts = random_points(600, 11);
  const std::vector<double> R = {0.21, 0.13};
  const NonlocalAverage avg(pts, R);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> U(-1.0, 3.0);
  std::vector<double> x(pts.size()), out(pts.size());
  for (double& v : x) v = U(rng);
  avg.average(x, out);
  int neighbours_seen = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const int g = pts[i].group;
    if (g < 0) {
      EXPECT_EQ(out[i], x[i]) << i;
      continue;
    }
    double num = 0.0, den = 0.0;
    int count = 0;
    for (std::size_t j = 0; j < pts.size(); ++j) {
      if (pts[j].group != g) continue;
      const double r2 = (pts[i].X - pts[j].X).squaredNorm(), q = 1.0 - r2 / (R[g] * R[g]);
      if (q <= 0.0) continue;
      num += pts[j].volume_m3 * q * q * x[j];
      den += pts[j].volume_m3 * q * q;
      ++count;
    }
    neighbours_seen = std::max(neighbours_seen, count);
    EXPECT_NEAR(out[i], num / den, 1e-13 * 3.0) << i;
  }
  EXPECT_GT(neighbours_seen, 20);  // the radius spans many points: a real average, not the point itself
}

// A constant field is its own average everywhere, boundaries included (the normalisation), and the
// result is the same to the bit for 1 and 2 threads (fixed neighbour order per point).
TEST(NonlocalAverage, KeepsConstantsAndIsIndependentOfTheThreadCount) {
  const std::vector<NonlocalAverage::Point> pts = random_points(800, 5);
  const NonlocalAverage avg(pts, std::vector<double>{0.2, 0.1});
  std::vector<double> c(pts.size(), 2.75), out(pts.size());
  avg.average(c, out);
  for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_NEAR(out[i], 2.75, 4e-15) << i;
  std::vector<double> x(pts.size()), a1(pts.size()), a2(pts.size());
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::sin(0.37 * i);
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
    NonlocalAverage(pts, std::vector<double>{0.2, 0.1}).average(x, a1);
  }
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 2);
    NonlocalAverage(pts, std::vector<double>{0.2, 0.1}).average(x, a2);
  }
  EXPECT_EQ(a1, a2);
}

TEST(NonlocalAverage, TooWideARadiusIsAnInputErrorWithTheFix) {
  const std::vector<NonlocalAverage::Point> pts = random_points(300, 3);
  try {
    NonlocalAverage(pts, std::vector<double>{5.0, 5.0}, 1000);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("choose a smaller nonlocal_radius_mm"), std::string::npos) << e.what();
  }
}

// ---- The re-entrant corner -----------------------------------------------------------------
// An L-shaped silicone bracket (two 10 mm arms, 4 mm thick in z: an in-plane corner along z),
// clamped at x = 0 and pressed down (follower pressure) on the top face of its lower arm, held for
// a while with a fatigue law driven by the largest principal stretch. The stretch is singular at
// the inner corner (x = y = 10 mm).

struct CornerRun {
  double max_damage = 0.0;
  double tip_angle_deg = 0.0;
  int elements = 0;
};

Mesh l_bracket(int n) {
  // The 20 x 20 mm square in 2n x 2n cells, one cell through the 4 mm thickness, without the upper
  // right quadrant (cells with both centre coordinates above 10 mm).
  Mesh full = mapped_grid(2 * n, 2 * n, 1, ElementType::Tet10, [](const Eigen::Vector3d& s) {
    return Eigen::Vector3d(20e-3 * s.x(), 20e-3 * s.y(), 4e-3 * s.z());
  });
  Mesh m;
  m.type = full.type;
  std::vector<int> remap(full.num_nodes(), -1);
  for (int e = 0; e < full.num_elements(); ++e) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int a = 0; a < 4; ++a) c += full.X[full.element(e)[a]] / 4.0;
    if (c.x() > 10e-3 && c.y() > 10e-3) continue;
    for (int a = 0; a < full.npe(); ++a) {
      int& r = remap[full.element(e)[a]];
      if (r < 0) {
        r = m.num_nodes();
        m.X.push_back(full.X[full.element(e)[a]]);
      }
      m.conn.push_back(r);
    }
  }
  m.ensure_ids();
  return m;
}

CornerRun run_corner(int n, double radius_mm) {
  FatigueParams f;
  f.driver = FatigueDriver::max_principal_stretch;
  f.lambda_th = 1.05;
  f.tau_s = 20.0;
  f.q = 1.0;
  f.n = 1.0;
  f.d_fail = 0.95;
  f.nonlocal_radius_m = radius_mm * 1e-3;
  Model model = single_part_model(l_bracket(n), make_fatigue(ecoflex(), f));
  fix(model, nodes_on_plane(model.mesh, 0, 0.0), {true, true, true});
  fix(model, nodes_on_plane(model.mesh, 2, 0.0), {false, false, true});  // plane strain-like: no z motion
  fix(model, nodes_on_plane(model.mesh, 2, 4e-3), {false, false, true});
  // The top face of the lower arm (y = 10 mm, x > 10 mm); the follower pressure pushes into the solid.
  model.pressure_faces = faces_where(model.mesh, [](const Eigen::Vector3d& X) {
    return std::abs(X.y() - 10e-3) < 1e-9 && X.x() > 10e-3 - 1e-9;
  });
  model.angle.tip_nodes = nodes_on_plane(model.mesh, 0, 20e-3);
  model.angle.fixed_normal_out = Eigen::Vector3d(-1, 0, 0);
  model.angle.bend_direction = Eigen::Vector3d(0, -1, 0);
  const Assembler A(model);
  QuasiStaticOptions opt;
  opt.time_tol = 0.02;
  opt.time_control = TimeControl::Error;
  QuasiStaticRun run(A, opt);
  // 4 kPa, ramped in 0.5 s and held 20 s.
  const LoadHistory load = staircase(4e3, 4e3, 20.0, 0.5, 1, 2.5, 0.0);
  CornerRun r;
  run.run(load, [&](const StateRecord& rec, const Eigen::VectorXd&, const std::vector<double>&) {
    r.tip_angle_deg = rec.angle_deg;
  });
  const std::vector<double> h = A.history_scalars(run.state());
  for (std::size_t i = 0; i < h.size(); i += 2) r.max_damage = std::max(r.max_damage, h[i]);
  r.elements = model.mesh.num_elements();
  return r;
}

// Meshes of 4, 8 and 16 cells per 10 mm arm. The local law's largest damage grows at a steady rate
// under refinement: its driver at the quadrature point nearest the corner follows the elastic
// corner singularity, stretch excess ~ r^-0.455 at a 270 deg corner, i.e. x1.37 per halving of h,
// and the damage with it (q = 1, first order) - measured 0.109, 0.178, 0.267: the ratio is asserted
// above 1.3, and it does not shrink. With the driver averaged over R = 2.5 mm (1 to 4 elements) it
// converges: measured 0.0571, 0.0640, 0.0669, increments 0.0069 then 0.0029 (ratio 0.42, the rate
// of a smooth field under second-order elements); asserted below 0.6, the finest step within 6 %,
// and several times smaller than the local law's step. The tip angle converges in both (elastic
// discretisation: 10.13 -> 10.68 deg local, 10.06 -> 10.57 deg non-local).
TEST(NonlocalFatigue, DamageAtAReentrantCornerConvergesUnderRefinementOnlyWhenNonlocal) {
  std::vector<CornerRun> local, nonlocal;
  for (int n : {4, 8, 16}) {
    local.push_back(run_corner(n, 0.0));
    nonlocal.push_back(run_corner(n, 2.5));
  }
  for (int k = 0; k < 3; ++k) {
    SCOPED_TRACE(k);
    EXPECT_GT(local[k].max_damage, 0.05);  // the hold damages the corner: a real test
    EXPECT_LT(local[k].max_damage, 0.9);
    EXPECT_GT(nonlocal[k].max_damage, 0.02);
    EXPECT_LT(nonlocal[k].max_damage, local[k].max_damage);  // the hot spot is capped at its neighbourhood's level
  }
  EXPECT_GT(local[1].max_damage, 1.3 * local[0].max_damage);
  EXPECT_GT(local[2].max_damage, 1.3 * local[1].max_damage);
  const double d1 = nonlocal[1].max_damage - nonlocal[0].max_damage, d2 = nonlocal[2].max_damage - nonlocal[1].max_damage;
  EXPECT_LT(std::abs(d2), 0.6 * std::abs(d1));
  EXPECT_LT(std::abs(d2), 0.06 * nonlocal[2].max_damage);
  EXPECT_LT(4.0 * std::abs(d2), local[2].max_damage - local[1].max_damage);
}

}  // namespace
}  // namespace pneufem

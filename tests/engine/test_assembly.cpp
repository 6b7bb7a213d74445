// Assembly-level checks: mass, tangent and pressure load stiffness against finite differences,
// pressure resultants, cavity volume, thread-count independence, bending angle.
#include <cstring>
#include <random>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <Eigen/Geometry>

#include "damage/effects.h"
#include "core/errors.h"
#include "engine/assembly.h"
#include "materials/hyperelastic.h"
#include "tests/engine/test_meshes.h"

namespace pneufem {
namespace {

using testing::box;
using testing::ecoflex;
using testing::faces_where;
using testing::single_part_model;

Eigen::VectorXd random_displacement(const Mesh& m, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  Eigen::VectorXd u(3 * m.num_nodes());
  // smooth bending-like field plus noise, so elements stay valid but are strongly deformed
  for (int i = 0; i < m.num_nodes(); ++i) {
    const Eigen::Vector3d& X = m.X[i];
    u.segment<3>(3 * i) = Eigen::Vector3d(0.3 * X.y() * X.z(), 0.2 * X.x() - 0.1 * X.z(), 0.25 * X.x() * X.x()) * 10.0 +
                          amplitude * Eigen::Vector3d(U(rng), U(rng), U(rng));
  }
  return u;
}

class AssemblyTest : public ::testing::TestWithParam<ElementType> {};

TEST_P(AssemblyTest, LumpedMassSumsToTotalMass) {
  Model model = single_part_model(box(0.02, 0.03, 0.01, 2, 3, 1, GetParam()), ecoflex(), 1070.0);
  model.fixed[0] = 1;
  Assembler A(model);
  // exact: straight-sided elements, mass fractions sum to one per element
  EXPECT_NEAR(A.lumped_mass().sum(), 1070.0 * 0.02 * 0.03 * 0.01, 1e-12 * 1070 * 6e-6);
  EXPECT_GT(A.lumped_mass().minCoeff(), 0.0);
}

TEST_P(AssemblyTest, TangentMatchesFiniteDifferenceOfInternalForce) {
  Model model = single_part_model(box(0.1, 0.1, 0.1, 2, 2, 2, GetParam()), ecoflex());
  model.fixed[0] = 1;
  Assembler A(model);
  const Eigen::VectorXd u = random_displacement(model.mesh, 1e-3, 7);
  SparseMatrix K;
  Eigen::VectorXd f;
  A.internal(u, {}, {}, {}, &f, &K, nullptr);
  std::mt19937 rng(3);
  std::normal_distribution<double> N;
  Eigen::VectorXd w(u.size());
  for (int i = 0; i < w.size(); ++i) w[i] = N(rng);
  w *= 1e-3 / w.norm();
  // Central difference along w: error O(h^2 f''') ~ 1e-6 relative for h = 1e-3*|w| on a field
  // whose natural length scale is ~0.05 m; round-off O(eps |f| / h) is negligible.
  const double h = 1e-3;
  Eigen::VectorXd fp, fm;
  A.internal(u + h * w / 1e-3 * 1e-3, {}, {}, {}, &fp, nullptr, nullptr);
  A.internal(u - h * w / 1e-3 * 1e-3, {}, {}, {}, &fm, nullptr, nullptr);
  const Eigen::VectorXd fd = (fp - fm) / (2 * h);
  const Eigen::VectorXd an = K * w;
  ASSERT_GT(an.norm(), 1e-3 * f.norm() / u.norm() * w.norm());  // not vacuous
  EXPECT_LT((fd - an).norm(), 1e-5 * an.norm());
}

TEST_P(AssemblyTest, PressureLoadStiffnessOfClosedSurfaceMatchesFiniteDifference) {
  // All boundary faces loaded: a closed surface, whose assembled load stiffness is symmetric,
  // so the symmetrised tangent must equal the exact derivative.
  Model model = single_part_model(box(0.1, 0.1, 0.1, 2, 2, 2, GetParam()), ecoflex());
  model.pressure_faces = boundary_faces(model.mesh);
  Assembler A(model);
  const Eigen::VectorXd u = random_displacement(model.mesh, 1e-3, 11);
  const double p = 2e4;
  SparseMatrix K = A.tangent_pattern();
  Eigen::VectorXd f = Eigen::VectorXd::Zero(u.size());
  A.add_pressure(u, p, f, &K);  // K = -d f_ext / du (symmetrised)
  std::mt19937 rng(5);
  std::normal_distribution<double> N;
  Eigen::VectorXd w(u.size());
  for (int i = 0; i < w.size(); ++i) w[i] = N(rng);
  const double h = 1e-6;  // f_ext is a cubic polynomial in u for Tri6 (quadratic for Tri3): FD error ~ h^2
  Eigen::VectorXd fp = Eigen::VectorXd::Zero(u.size()), fm = fp;
  A.add_pressure(u + h * w, p, fp, nullptr);
  A.add_pressure(u - h * w, p, fm, nullptr);
  const Eigen::VectorXd fd = -(fp - fm) / (2 * h);
  const Eigen::VectorXd an = K * w;
  ASSERT_GT(an.norm(), 0.0);
  EXPECT_LT((fd - an).norm(), 1e-7 * an.norm());
}

TEST_P(AssemblyTest, PressureResultantsAndCavityVolume) {
  Model model = single_part_model(box(0.1, 0.2, 0.3, 2, 2, 2, GetParam()), ecoflex());
  Assembler A0(model);
  // Closed surface: zero net force under any deformation (check one), and the enclosed volume is
  // minus the box volume (the "cavity" normal points into the solid).
  model.pressure_faces = boundary_faces(model.mesh);
  Assembler A(model);
  const Eigen::VectorXd u = random_displacement(model.mesh, 1e-4, 13);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(u.size());
  A.add_pressure(u, 1e4, f, nullptr);
  Eigen::Vector3d net = Eigen::Vector3d::Zero();
  for (int i = 0; i < model.mesh.num_nodes(); ++i) net += f.segment<3>(3 * i);
  EXPECT_LT(net.norm(), 1e-10 * 1e4 * 0.2);
  EXPECT_NEAR(A.cavity_volume(Eigen::VectorXd::Zero(u.size())), -0.1 * 0.2 * 0.3, 1e-14);
  // One flat face z = 0.3: resultant = -p A e_z exactly.
  model.pressure_faces = faces_where(model.mesh, [](const Eigen::Vector3d& X) { return std::abs(X.z() - 0.3) < 1e-12; });
  Assembler Atop(model);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(u.size());
  Atop.add_pressure(Eigen::VectorXd::Zero(u.size()), 1e4, g, nullptr);
  Eigen::Vector3d res = Eigen::Vector3d::Zero();
  for (int i = 0; i < model.mesh.num_nodes(); ++i) res += g.segment<3>(3 * i);
  EXPECT_NEAR(res.z(), -1e4 * 0.1 * 0.2, 1e-9);
  EXPECT_NEAR(res.head<2>().norm(), 0.0, 1e-9);
}

TEST_P(AssemblyTest, ResultsIndependentOfThreadCount) {
  Model model = single_part_model(box(0.1, 0.1, 0.1, 4, 4, 4, GetParam()), ecoflex());
  model.pressure_faces = faces_where(model.mesh, [](const Eigen::Vector3d& X) { return X.z() > 0.1 - 1e-12; });
  Assembler A(model);
  ASSERT_GT(A.num_colours(), 1);
  const Eigen::VectorXd u = random_displacement(model.mesh, 2e-4, 17);
  auto eval = [&](int threads) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
    SparseMatrix K;
    Eigen::VectorXd f;
    double W = 0;
    A.internal(u, {}, {}, {}, &f, &K, &W);
    A.add_pressure(u, 3e4, f, &K);
    return std::make_tuple(f, Eigen::VectorXd(Eigen::Map<Eigen::VectorXd>(K.valuePtr(), K.nonZeros())), W);
  };
  const auto [f1, k1, w1] = eval(1);
  const auto [f2, k2, w2] = eval(2);
  // bit-for-bit: exact equality, not a tolerance
  EXPECT_TRUE((f1.array() == f2.array()).all());
  EXPECT_TRUE((k1.array() == k2.array()).all());
  EXPECT_EQ(w1, w2);
}

// The force-only path (batched stress, engine/assembly.cpp) and the force of the force + tangent
// path are the same arithmetic: f_int, the energy and the trial state agree bit for bit, with 1 or
// 2 threads, for a model mixing a law without history (batched), a stiff St Venant-Kirchhoff layer
// and a decorated law with history (evaluated element by element).
TEST_P(AssemblyTest, ForceOnlyPathMatchesTangentPathBitForBit) {
  Model model = single_part_model(box(0.1, 0.1, 0.1, 4, 4, 4, GetParam()), ecoflex());
  model.parts.push_back(Part{"fabric", std::make_shared<SaintVenantKirchhoff>(6.5e9, 0.2), 1000.0});
  model.parts.push_back(Part{"mullins", make_mullins(ecoflex(), MullinsParams{2.0, 20e3, 0.3}), 1000.0});
  for (int e = 0; e < model.mesh.num_elements(); ++e) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int a = 0; a < 4; ++a) c += model.mesh.X[model.mesh.element(e)[a]] / 4.0;
    model.element_part[e] = c.z() < 0.025 ? 1 : c.x() < 0.05 ? 2 : 0;
  }
  Assembler A(model);
  const Eigen::VectorXd u = random_displacement(model.mesh, 2e-4, 19);
  const std::vector<double> state_old = A.initial_state();
  ASSERT_GT(state_old.size(), 0u);
  auto eval = [&](int threads, bool tangent) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
    SparseMatrix K;
    Eigen::VectorXd f;
    double W = 0;
    std::vector<double> state_new(state_old.size());
    A.internal(u, TimeStep{1.0, 0.0}, state_old, state_new, &f, tangent ? &K : nullptr, &W);
    return std::make_tuple(f, W, state_new);
  };
  const auto [f_t, w_t, s_t] = eval(1, true);
  ASSERT_GT(f_t.norm(), 0.0);
  for (int threads : {1, 2}) {
    SCOPED_TRACE(threads);
    const auto [f, w, s] = eval(threads, false);
    EXPECT_EQ(std::memcmp(f.data(), f_t.data(), sizeof(double) * f.size()), 0);  // bit for bit
    EXPECT_EQ(w, w_t);
    EXPECT_EQ(s, s_t);
  }
}

TEST_P(AssemblyTest, InvertedElementIsReportedWithIdAndTime) {
  Model model = single_part_model(box(0.1, 0.1, 0.1, 1, 1, 1, GetParam()), ecoflex());
  Assembler A(model);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * model.mesh.num_nodes());
  // Push one corner node through the opposite face.
  for (int i = 0; i < model.mesh.num_nodes(); ++i)
    if (model.mesh.X[i].norm() < 1e-12) u.segment<3>(3 * i) = Eigen::Vector3d(0.3, 0.3, 0.3);
  Eigen::VectorXd f;
  try {
    A.internal(u, TimeStep{1.25, 0.0}, {}, {}, &f, nullptr, nullptr);
    FAIL() << "expected a PhysicsError";
  } catch (const PhysicsError& e) {
    EXPECT_GE(e.element(), 0);
    EXPECT_DOUBLE_EQ(e.time_s(), 1.25);
    EXPECT_NE(std::string(e.what()).find("element"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("t = 1.25"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("Hint"), std::string::npos);
  }
}

INSTANTIATE_TEST_SUITE_P(Tets, AssemblyTest, ::testing::Values(ElementType::Tet4, ElementType::Tet10),
                         [](const auto& p) { return p.param == ElementType::Tet4 ? "Tet4" : "Tet10"; });

}  // namespace
}  // namespace pneufem

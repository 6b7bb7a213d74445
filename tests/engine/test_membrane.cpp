// Membrane elements (engine/membrane.h): the plane-stress law, force = dW/du and tangent = df/du
// by central differences, a homogeneous stretch against the analytic plane-stress St
// Venant-Kirchhoff stress, rigid rotation, the assembled tangent/mass/gravity, and a soft block
// with a membrane face under plane-strain uniaxial stretch against the analytic reaction.
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>

#include "engine/assembly.h"
#include "engine/membrane.h"
#include "core/errors.h"
#include "tests/engine/test_meshes.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

using testing::box;
using testing::faces_where;
using testing::fix;
using testing::neo_hookean;
using testing::nodes_on_plane;
using testing::single_part_model;

constexpr double kE = 2.0e8, kNu = 0.3, kT = 2e-4;  // a stiff sheet (Pa, -, m)

/// A mesh holding only nodes: a patch of nx x ny cells on a surface X(s, r), s, r in [0, 1],
/// cut into triangles (Tri3, or Tri6 with mid-edge nodes on the surface), as a MembraneSet.
struct Patch {
  Mesh mesh;
  MembraneSet set;
};

Patch make_patch(ElementType type, int nx, int ny, const std::function<Eigen::Vector3d(double, double)>& X) {
  Patch p;
  p.mesh.type = type;
  const int f = type == ElementType::Tet10 ? 2 : 1;
  const int Nx = f * nx + 1, Ny = f * ny + 1;
  auto id = [&](int i, int j) { return i + Nx * j; };
  for (int j = 0; j < Ny; ++j)
    for (int i = 0; i < Nx; ++i) p.mesh.X.push_back(X(double(i) / (Nx - 1), double(j) / (Ny - 1)));
  p.mesh.ensure_ids();
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int i0 = f * i, j0 = f * j;
      // corners (fine-grid indices) of the two triangles of the cell, counter-clockwise
      const int tris[2][3][2] = {{{i0, j0}, {i0 + f, j0}, {i0 + f, j0 + f}}, {{i0, j0}, {i0 + f, j0 + f}, {i0, j0 + f}}};
      for (const auto& t : tris) {
        for (const auto& c : t) p.set.nodes.push_back(id(c[0], c[1]));
        if (f == 2)
          for (int k = 0; k < 3; ++k) {
            const auto& a = t[k];
            const auto& b = t[(k + 1) % 3];
            p.set.nodes.push_back(id((a[0] + b[0]) / 2, (a[1] + b[1]) / 2));
          }
      }
    }
  p.set.name = "patch";
  p.set.thickness_m = kT;
  p.set.law = PlaneStressSVK(kE, kNu);
  p.set.density_kg_m3 = 1500.0;
  return p;
}

/// Energy, force and dense tangent of a whole membrane set (test-only serial assembly).
double evaluate(const Patch& p, const MembraneGeometry& g, const Eigen::VectorXd& u, Eigen::VectorXd* f,
                Eigen::MatrixXd* K) {
  const int n = 3 * p.mesh.num_nodes();
  if (f) f->setZero(n);
  if (K) K->setZero(n, n);
  double W = 0.0;
  auto run = [&]<int NPF>() {
    Eigen::Matrix<double, 3, NPF> ue, fe;
    Eigen::Matrix<double, 3 * NPF, 3 * NPF> Ke;
    for (int t = 0; t < g.num_triangles(); ++t) {
      const int* nd = p.set.nodes.data() + t * NPF;
      for (int a = 0; a < NPF; ++a) ue.col(a) = u.segment<3>(3 * nd[a]);
      double We = 0.0;
      EXPECT_TRUE(membrane_triangle<NPF>(p.set, g, t, ue, We, fe, K ? &Ke : nullptr));
      W += We;
      for (int a = 0; a < NPF; ++a) {
        if (f) f->segment<3>(3 * nd[a]) += fe.col(a);
        if (K)
          for (int b = 0; b < NPF; ++b) K->block<3, 3>(3 * nd[a], 3 * nd[b]) += Ke.template block<3, 3>(3 * a, 3 * b);
      }
    }
  };
  if (g.npf == 3)
    run.template operator()<3>();
  else
    run.template operator()<6>();
  return W;
}

using pneufem::test::error_of;

TEST(PlaneStressSVK, MatchesTheClosedFormAndRejectsBadConstants) {
  const PlaneStressSVK law(kE, kNu);
  Eigen::Matrix2d E;
  E << 1e-3, 4e-4, 4e-4, -2e-3;
  const Eigen::Matrix2d S = law.S(E);
  const double c = kE / (1 - kNu * kNu);
  // Plane stress: S11 = E/(1 - nu^2) (E11 + nu E22), S12 = E/(1 + nu) E12. Round-off only.
  EXPECT_NEAR(S(0, 0), c * (E(0, 0) + kNu * E(1, 1)), 1e-14 * c);
  EXPECT_NEAR(S(1, 1), c * (E(1, 1) + kNu * E(0, 0)), 1e-14 * c);
  EXPECT_NEAR(S(0, 1), kE / (1 + kNu) * E(0, 1), 1e-14 * c);
  const Eigen::Vector3d Sv = law.D() * Eigen::Vector3d(E(0, 0), E(1, 1), 2 * E(0, 1));
  EXPECT_NEAR((Sv - Eigen::Vector3d(S(0, 0), S(1, 1), S(0, 1))).norm(), 0.0, 1e-14 * c);
  EXPECT_NEAR(law.psi(E), 0.5 * (S.cwiseProduct(E)).sum(), 1e-14 * c * 1e-6);  // psi = S:E/2 (quadratic)
  EXPECT_NE(error_of([] { PlaneStressSVK(0.0, 0.2); }).find("Young's modulus"), std::string::npos);
  EXPECT_NE(error_of([] { PlaneStressSVK(1e6, 0.5); }).find("Poisson ratio"), std::string::npos);
  EXPECT_NE(error_of([] { PlaneStressSVK(1e6, -1.0); }).find("Poisson ratio"), std::string::npos);
}

class MembraneTest : public ::testing::TestWithParam<ElementType> {};

// A curved, tilted reference patch (so T differs between points and from the global axes).
Patch curved_patch(ElementType type) {
  return make_patch(type, 2, 2, [](double s, double r) {
    return Eigen::Vector3d(0.010 * s + 0.002 * r, 0.008 * r, 0.003 * s * s + 0.002 * s * r);
  });
}

Eigen::VectorXd random_field(int n_nodes, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  Eigen::VectorXd u(3 * n_nodes);
  for (int i = 0; i < u.size(); ++i) u[i] = amplitude * U(rng);
  return u;
}

TEST_P(MembraneTest, ForceIsEnergyGradientAndTangentIsForceDerivative) {
  const Patch p = curved_patch(GetParam());
  const MembraneGeometry g = compute_membrane_geometry(p.mesh, p.set);
  // Displacements of ~4e-4 m on 5 mm triangles: strains of ~10 %, compression and tension.
  const Eigen::VectorXd u = random_field(p.mesh.num_nodes(), 4e-4, 5);
  const Eigen::VectorXd w = random_field(p.mesh.num_nodes(), 1.0, 9).normalized() * 1e-3;  // |w| ~ size of a node move
  Eigen::VectorXd f, fp, fm;
  Eigen::MatrixXd K;
  const double W = evaluate(p, g, u, &f, &K);
  ASSERT_GT(W, 0.0);
  ASSERT_GT(f.norm(), 0.0);
  // Along a line W(u + h w) is a polynomial of degree 4 in h (E is quadratic in u), so the central
  // difference errs by h^2/6 W'''[w,w,w] ~ (h |w| / strain length)^2 ~ 1e-10 relative for
  // h = 1e-5 (~cbrt(eps)); round-off eps |W| / (h |W' w|) ~ 1e-10. 1e-7 leaves a 1000x margin.
  const double h = 1e-5;
  const double Wp = evaluate(p, g, u + h * w, &fp, nullptr);
  const double Wm = evaluate(p, g, u - h * w, &fm, nullptr);
  const double dW = (Wp - Wm) / (2 * h);
  EXPECT_NEAR(dW, f.dot(w), 1e-7 * std::abs(f.dot(w)));
  ASSERT_GT(std::abs(f.dot(w)), 1e-3 * f.norm() * w.norm());  // not vacuous
  const Eigen::VectorXd df = (fp - fm) / (2 * h);
  const Eigen::VectorXd Kw = K * w;
  ASSERT_GT(Kw.norm(), 0.0);
  EXPECT_LT((df - Kw).norm(), 1e-7 * Kw.norm());
  EXPECT_LT((K - K.transpose()).norm(), 1e-13 * K.norm());  // hyperelastic: symmetric tangent
}

// In-plane orthonormal axes of a tilted flat patch and a rigid rotation.
const Eigen::Vector3d kA1 = Eigen::Vector3d(1, 2, 2).normalized();
const Eigen::Vector3d kA2 = kA1.cross(Eigen::Vector3d(0, 0, 1)).normalized();
const Eigen::Matrix3d kR = Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, -1, 0.5).normalized()).toRotationMatrix();
constexpr double kLa = 0.012, kLb = 0.007;  // patch side lengths along kA1, kA2 (m)

Patch flat_patch(ElementType type) {
  return make_patch(type, 3, 2, [](double s, double r) -> Eigen::Vector3d {  // not an expression template
    return Eigen::Vector3d(0.001, -0.002, 0.003) + kLa * s * kA1 + kLb * r * kA2;
  });
}

TEST_P(MembraneTest, HomogeneousStretchGivesTheAnalyticPlaneStressResponse) {
  const Patch p = flat_patch(GetParam());
  const MembraneGeometry g = compute_membrane_geometry(p.mesh, p.set);
  const Eigen::Vector3d X0 = p.mesh.X[0];
  const double l1 = 1.08, l2 = 0.97;  // stretches along kA1, kA2, then the rigid rotation kR
  Eigen::VectorXd u(3 * p.mesh.num_nodes());
  for (int i = 0; i < p.mesh.num_nodes(); ++i) {
    const Eigen::Vector3d d = p.mesh.X[i] - X0;
    const Eigen::Vector3d x = X0 + kR * (l1 * kA1.dot(d) * kA1 + l2 * kA2.dot(d) * kA2);
    u.segment<3>(3 * i) = x - p.mesh.X[i];
  }
  Eigen::VectorXd f;
  const double W = evaluate(p, g, u, &f, nullptr);
  // Analytic: E = diag(l1^2 - 1, l2^2 - 1)/2 in (kA1, kA2); plane-stress S; P = F S.
  const double E11 = 0.5 * (l1 * l1 - 1), E22 = 0.5 * (l2 * l2 - 1);
  const double c = kE / (1 - kNu * kNu);
  const double S11 = c * (E11 + kNu * E22), S22 = c * (E22 + kNu * E11);
  const double psi = 0.5 * (S11 * E11 + S22 * E22);
  // The field is linear in X, so it is exact in both element types, and the rule integrates the
  // constant integrand exactly: only round-off remains (~1e-15 relative per term).
  EXPECT_NEAR(W, kT * kLa * kLb * psi, 1e-12 * kT * kLa * kLb * psi);
  // Edge resultants: the nodes of the edge s = 1 carry t * kLb * P N = t kLb F S e1, F = kR [l1 kA1, l2 kA2]
  // (the corner nodes' shares of the other edges are tangential stresses S12 = 0). Interior
  // nodes are in equilibrium and all forces sum to zero.
  Eigen::Vector3d edge_s1 = Eigen::Vector3d::Zero(), edge_r1 = Eigen::Vector3d::Zero(), total = Eigen::Vector3d::Zero();
  double interior = 0.0;
  for (int i = 0; i < p.mesh.num_nodes(); ++i) {
    const Eigen::Vector3d d = p.mesh.X[i] - X0;
    const double s = kA1.dot(d) / kLa, r = kA2.dot(d) / kLb;
    const Eigen::Vector3d fi = f.segment<3>(3 * i);
    if (std::abs(s - 1) < 1e-9) edge_s1 += fi;
    if (std::abs(r - 1) < 1e-9) edge_r1 += fi;
    if (s > 1e-9 && s < 1 - 1e-9 && r > 1e-9 && r < 1 - 1e-9) interior = std::max(interior, fi.norm());
    total += fi;
  }
  const Eigen::Vector3d expected_s1 = kT * kLb * l1 * S11 * (kR * kA1);
  const Eigen::Vector3d expected_r1 = kT * kLa * l2 * S22 * (kR * kA2);
  const double scale = kT * kLb * c * std::abs(E11);
  EXPECT_LT((edge_s1 - expected_s1).norm(), 1e-11 * scale) << edge_s1.transpose() << " vs " << expected_s1.transpose();
  EXPECT_LT((edge_r1 - expected_r1).norm(), 1e-11 * scale) << edge_r1.transpose() << " vs " << expected_r1.transpose();
  EXPECT_LT(interior, 1e-11 * scale) << "interior nodes must be in equilibrium";
  EXPECT_LT(total.norm(), 1e-11 * scale) << "internal forces are self-equilibrated";
}

TEST_P(MembraneTest, RigidRotationGivesNoForceAndNoEnergy) {
  const Patch p = curved_patch(GetParam());
  const MembraneGeometry g = compute_membrane_geometry(p.mesh, p.set);
  Eigen::VectorXd u(3 * p.mesh.num_nodes());
  for (int i = 0; i < p.mesh.num_nodes(); ++i)
    u.segment<3>(3 * i) = (kR - Eigen::Matrix3d::Identity()) * p.mesh.X[i] + Eigen::Vector3d(0.01, -0.02, 0.005);
  Eigen::VectorXd f;
  const double W = evaluate(p, g, u, &f, nullptr);
  // Round-off strain ~ 1e-15 (rotation of O(1) displacement gradients): forces ~ E t L * 1e-15.
  const double scale = kE * kT * 0.01;
  EXPECT_LT(f.lpNorm<Eigen::Infinity>(), 1e-12 * scale);
  EXPECT_LT(std::abs(W), 1e-20 * scale * 0.01);
}

/// A soft cube with the membrane on its top face z = L (faces of the tets: no new matrix pairs).
Model block_with_membrane(ElementType type, double L, bool with_membrane) {
  Model model = single_part_model(box(L, L, L, 2, 2, 2, type), neo_hookean(1e5, 1e6));
  if (with_membrane) {
    const auto faces = faces_where(model.mesh, [&](const Eigen::Vector3d& X) { return std::abs(X.z() - L) < 1e-12; });
    MembraneSet ms;
    ms.name = "top";
    ms.nodes = membrane_nodes_of_faces(model.mesh, faces);
    ms.thickness_m = kT;
    ms.law = PlaneStressSVK(kE, kNu);
    ms.density_kg_m3 = 1500.0;
    model.membranes.push_back(ms);
  }
  return model;
}

TEST_P(MembraneTest, AssembledTangentMassAndGravityIncludeTheMembrane) {
  const double L = 0.01;
  Model with = block_with_membrane(GetParam(), L, true), without = block_with_membrane(GetParam(), L, false);
  // A triangle through non-neighbouring nodes too: the Assembler must extend the matrix pattern.
  const auto bottom = nodes_on_plane(with.mesh, 2, 0.0);
  const int npf = nodes_per_face(GetParam());
  MembraneSet extra = with.membranes[0];
  extra.name = "extra";
  extra.nodes.assign(with.membranes[0].nodes.begin(), with.membranes[0].nodes.begin() + npf);
  extra.nodes[0] = bottom[0];  // a bottom node with a top-face triangle: a skewed, non-face triangle
  with.membranes.push_back(extra);
  with.fixed[0] = without.fixed[0] = 1;
  Assembler Aw(with), Ao(without);
  // Lumped mass: solid + rho t A of the top face + the extra triangle.
  const double extra_area = compute_membrane_geometry(with.mesh, extra).area[0];
  EXPECT_NEAR(Aw.lumped_mass().sum() - Ao.lumped_mass().sum(), 1500.0 * kT * (L * L + extra_area), 1e-12 * 1500 * kT * L * L);
  with.gravity_m_s2 = without.gravity_m_s2 = Eigen::Vector3d(0, 0, -9.81);
  Eigen::VectorXd gw = Eigen::VectorXd::Zero(with.num_dofs()), go = gw;
  Aw.add_gravity(gw);
  Ao.add_gravity(go);
  EXPECT_NEAR((gw - go).sum(), -9.81 * 1500.0 * kT * (L * L + extra_area), 1e-12 * 9.81 * 1500 * kT * L * L);

  // Tangent of the membrane part by central differences of the assembled force difference.
  const Eigen::VectorXd u = random_field(with.mesh.num_nodes(), 2e-4, 21);
  const Eigen::VectorXd w = random_field(with.mesh.num_nodes(), 1.0, 22).normalized() * 1e-3;
  SparseMatrix Kw, Ko;
  Eigen::VectorXd fw, fo;
  double Ww = 0, Wo = 0;
  Aw.internal(u, {}, {}, {}, &fw, &Kw, &Ww);
  Ao.internal(u, {}, {}, {}, &fo, &Ko, &Wo);
  const double h = 1e-5;  // as above: truncation and round-off ~1e-10 relative
  Eigen::VectorXd fwp, fwm, fop, fom;
  Aw.internal(u + h * w, {}, {}, {}, &fwp, nullptr, nullptr);
  Aw.internal(u - h * w, {}, {}, {}, &fwm, nullptr, nullptr);
  Ao.internal(u + h * w, {}, {}, {}, &fop, nullptr, nullptr);
  Ao.internal(u - h * w, {}, {}, {}, &fom, nullptr, nullptr);
  const Eigen::VectorXd fd = ((fwp - fop) - (fwm - fom)) / (2 * h);
  const Eigen::VectorXd an = Kw * w - Ko * w;
  ASSERT_GT(an.norm(), 0.1 * (Ko * w).norm());  // the membrane part is not negligible: not vacuous
  EXPECT_LT((fd - an).norm(), 1e-6 * an.norm());
  EXPECT_GT(Ww, Wo);
}

TEST_P(MembraneTest, BlockWithMembraneUnderUniaxialStretchGivesTheAnalyticReaction) {
  // Soft neo-Hookean cube (mu = 0.1 MPa, K = 1 MPa) with the stiff membrane on its top face,
  // stretched along x by eps with u_y = 0 everywhere (plane strain), bottom u_z = 0, top free.
  // The homogeneous deformation diag(1 + eps, 1, lambda_z) is then the exact solution of the
  // combined problem (the uniform membrane stress only loads the face's edges, which are
  // constrained in x and y) and lies in the finite-element space, so the reaction is
  //   R = [E_s/(1 - nu_s^2) L^2 + E_m/(1 - nu_m^2) t L] eps + O(eps^2)
  // with no discretisation error. At eps = 1e-4 the O(eps^2) terms (e.g. 3/2 eps in SVK's
  // P11 = E (eps + 3/2 eps^2)) are ~1.5e-4 relative: tolerance 1e-3.
  const double L = 0.01, eps = 1e-4;
  const double mu = 1e5, K = 1e6;
  const double Es = 9 * K * mu / (3 * K + mu), nus = (3 * K - 2 * mu) / (2 * (3 * K + mu));
  auto reaction = [&](bool with_membrane) {
    Model model = block_with_membrane(GetParam(), L, with_membrane);
    const Mesh& m = model.mesh;
    Eigen::VectorXd u = Eigen::VectorXd::Zero(model.num_dofs());
    for (int i = 0; i < m.num_nodes(); ++i) {
      model.fixed[3 * i + 1] = 1;
      if (std::abs(m.X[i].x()) < 1e-12) model.fixed[3 * i] = 1;
      if (std::abs(m.X[i].x() - L) < 1e-12) model.fixed[3 * i] = 1;
      if (std::abs(m.X[i].z()) < 1e-12) model.fixed[3 * i + 2] = 1;
      u[3 * i] = eps * m.X[i].x();  // exact in x; Newton finds the lateral contraction
    }
    Assembler A(model);
    SparseMatrix Kt;
    Eigen::VectorXd f;
    double R0 = 0.0;
    for (int it = 0; it < 20; ++it) {
      A.internal(u, {}, {}, {}, &f, &Kt, nullptr);
      Eigen::VectorXd R = f;
      A.zero_fixed(R);
      if (it == 0) R0 = f.norm();
      if (R.norm() < 1e-13 * R0) break;
      A.apply_constraints(Kt, 1.0);
      Eigen::SimplicialLDLT<SparseMatrix> solver(Kt);
      EXPECT_EQ(solver.info(), Eigen::Success);
      u -= solver.solve(R);
    }
    Eigen::VectorXd R = f;
    A.zero_fixed(R);
    EXPECT_LT(R.norm(), 1e-12 * R0) << "Newton did not converge";
    double Rx = 0.0;
    for (int i : nodes_on_plane(m, 0, L)) Rx += f[3 * i];
    return Rx;
  };
  const double solid = Es / (1 - nus * nus) * L * L * eps;
  const double membrane = kE / (1 - kNu * kNu) * kT * L * eps;
  const double with = reaction(true), without = reaction(false);
  EXPECT_NEAR(without, solid, 1e-3 * solid);
  EXPECT_NEAR(with, solid + membrane, 1e-3 * (solid + membrane));
  EXPECT_NEAR(with - without, membrane, 1e-3 * membrane);
  ASSERT_GT(membrane, 0.5 * solid);  // both matter in the check
}

TEST(Membrane, BadSetsAreRejectedWithTheirName) {
  Model model = block_with_membrane(ElementType::Tet4, 0.01, true);
  model.fixed[0] = 1;
  model.membranes[0].thickness_m = 0.0;
  EXPECT_NE(error_of([&] { validate(model); }).find("membrane 'top': thickness"), std::string::npos);
  model.membranes[0].thickness_m = kT;
  model.membranes[0].nodes.pop_back();
  EXPECT_NE(error_of([&] { validate(model); }).find("whole number of triangles"), std::string::npos);
  MembraneSet flat;
  flat.name = "flat";
  flat.nodes = {0, 1, 1};  // zero area
  EXPECT_NE(error_of([&] { (void)compute_membrane_geometry(model.mesh, flat); }).find("degenerate"), std::string::npos);
}

std::string triangle_name(const ::testing::TestParamInfo<ElementType>& p) {
  return p.param == ElementType::Tet4 ? "Tri3" : "Tri6";
}
INSTANTIATE_TEST_SUITE_P(Types, MembraneTest, ::testing::Values(ElementType::Tet4, ElementType::Tet10), triangle_name);

}  // namespace
}  // namespace pneufem

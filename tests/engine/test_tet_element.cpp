// engine/tet_element.h: the element's reference data against exact truths - the shape functions are
// 1 at their node and 0 at the others (Abaqus node order), sum to 1, and their derivatives are the
// derivatives; the rules integrate the monomials of their degree exactly; the lumped masses sum to 1;
// the geometry of a mesh gives its volume; and the Tet10 distortion measure is 1 for a straight-sided
// element and falls to 0 when a mid-node is a quarter of its edge off its midpoint.
#include "engine/tet_element.h"

#include <array>
#include <cmath>
#include <numeric>

#include <gtest/gtest.h>

#include "tests/engine/test_meshes.h"

namespace pneufem {
namespace {

// Reference coordinates of the nodes in Abaqus order: corners, then mid-edges 0-1, 1-2, 2-0, 0-3, 1-3, 2-3.
const std::array<Eigen::Vector3d, 10> kNodes = {
    Eigen::Vector3d(0, 0, 0),     Eigen::Vector3d(1, 0, 0),   Eigen::Vector3d(0, 1, 0),
    Eigen::Vector3d(0, 0, 1),     Eigen::Vector3d(0.5, 0, 0), Eigen::Vector3d(0.5, 0.5, 0),
    Eigen::Vector3d(0, 0.5, 0),   Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d(0.5, 0, 0.5),
    Eigen::Vector3d(0, 0.5, 0.5)};

double factorial(int n) { return n <= 1 ? 1.0 : n * factorial(n - 1); }

TEST(TetElement, ShapeFunctionsAreKroneckerAtTheNodes) {
  for (ElementType t : {ElementType::Tet4, ElementType::Tet10}) {
    const int n = nodes_per_element(t);
    double N[10], dN[30];
    for (int j = 0; j < n; ++j) {
      tet_shape(t, kNodes[j].x(), kNodes[j].y(), kNodes[j].z(), N, dN);
      for (int i = 0; i < n; ++i) EXPECT_NEAR(N[i], i == j ? 1.0 : 0.0, 1e-15) << n << " nodes, N" << i << " at node " << j;
    }
  }
}

TEST(TetElement, PartitionOfUnityAndDerivativesByCentralDifferences) {
  const double h = 1e-6;
  for (ElementType t : {ElementType::Tet4, ElementType::Tet10}) {
    const int n = nodes_per_element(t);
    for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(0.6, 0.15, 0.05)}) {
      double N[10], dN[30];
      tet_shape(t, p.x(), p.y(), p.z(), N, dN);
      double sum = 0.0;
      for (int i = 0; i < n; ++i) sum += N[i];
      EXPECT_NEAR(sum, 1.0, 1e-15);
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d a = p, b = p;
        a[k] += h;
        b[k] -= h;
        double Na[10], Nb[10], scratch[30];
        tet_shape(t, a.x(), a.y(), a.z(), Na, scratch);
        tet_shape(t, b.x(), b.y(), b.z(), Nb, scratch);
        double dsum = 0.0;
        for (int i = 0; i < n; ++i) {
          // N is at most quadratic: central differences are exact but for rounding, ~1e-16 / h.
          EXPECT_NEAR(dN[3 * i + k], (Na[i] - Nb[i]) / (2.0 * h), 1e-9) << n << " nodes, dN" << i << "/dxi" << k;
          dsum += dN[3 * i + k];
        }
        EXPECT_NEAR(dsum, 0.0, 1e-14);
      }
    }
  }
}

TEST(TetElement, RulesIntegrateTheirDegreeExactly) {
  // Over the reference tetrahedron, the integral of xi^a eta^b zeta^c is a! b! c! / (a + b + c + 3)!;
  // over the reference triangle, of xi^a eta^b, a! b! / (a + b + 2)!.
  const auto tet = [](ElementType t, int a, int b, int c) {
    double s = 0.0;
    for (const QuadPoint& q : tet_rule(t)) s += q.w * std::pow(q.xi, a) * std::pow(q.eta, b) * std::pow(q.zeta, c);
    return s;
  };
  const auto exact = [](int a, int b, int c) { return factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3); };
  for (ElementType t : {ElementType::Tet4, ElementType::Tet10}) {
    EXPECT_NEAR(tet(t, 0, 0, 0), 1.0 / 6.0, 1e-15);
    EXPECT_NEAR(tet(t, 1, 0, 0), exact(1, 0, 0), 1e-15);
    EXPECT_NEAR(tet(t, 0, 0, 1), exact(0, 0, 1), 1e-15);
  }
  // Degree 2 for Tet10 (the stiffness of a straight-sided element).
  EXPECT_NEAR(tet(ElementType::Tet10, 2, 0, 0), exact(2, 0, 0), 1e-15);
  EXPECT_NEAR(tet(ElementType::Tet10, 1, 1, 0), exact(1, 1, 0), 1e-15);
  EXPECT_NEAR(tet(ElementType::Tet10, 0, 1, 1), exact(0, 1, 1), 1e-15);
  // Degree 4 on faces; degree 5 is beyond the rule (shows the test can tell).
  const auto tri = [](int a, int b) {
    double s = 0.0;
    for (const QuadPoint& q : tri_rule()) s += q.w * std::pow(q.xi, a) * std::pow(q.eta, b);
    return s;
  };
  const auto tri_exact = [](int a, int b) { return factorial(a) * factorial(b) / factorial(a + b + 2); };
  for (int a = 0; a <= 4; ++a)
    for (int b = 0; a + b <= 4; ++b) EXPECT_NEAR(tri(a, b), tri_exact(a, b), 1e-15) << a << " " << b;
  EXPECT_GT(std::abs(tri(5, 0) - tri_exact(5, 0)), 1e-8);
}

TEST(TetElement, LumpedMassFractionsSumToOne) {
  for (ElementType t : {ElementType::Tet4, ElementType::Tet10}) {
    const auto f = lumped_mass_fractions(t);
    ASSERT_EQ(static_cast<int>(f.size()), nodes_per_element(t));
    EXPECT_NEAR(std::accumulate(f.begin(), f.end(), 0.0), 1.0, 1e-15);
    for (double x : f) EXPECT_GT(x, 0.0);  // HRZ: no negative corner mass for Tet10
  }
  EXPECT_NEAR(lumped_mass_fractions(ElementType::Tet10)[0], 1.0 / 36.0, 1e-16);
  EXPECT_NEAR(lumped_mass_fractions(ElementType::Tet10)[4], 4.0 / 27.0, 1e-16);
}

TEST(TetElement, GeometryOfABoxIsItsVolume) {
  for (ElementType t : {ElementType::Tet4, ElementType::Tet10}) {
    const Mesh m = testing::box(0.02, 0.01, 0.005, 2, 2, 1, t);
    const ElementGeometry g = compute_geometry(m);
    double volume = 0.0;
    for (int e = 0; e < m.num_elements(); ++e) {
      double w = 0.0;
      for (int q = 0; q < g.nqp; ++q) {
        w += g.w(e, q);
        for (int k = 0; k < 3; ++k) {
          double s = 0.0;
          for (int a = 0; a < g.npe; ++a) s += g.grad(e, q)[3 * a + k];
          EXPECT_NEAR(s, 0.0, 1e-9);  // sum dN/dX = 0 (1/m scale ~1e3: rounding ~1e-13)
        }
      }
      EXPECT_NEAR(w, g.volume[e], 1e-20);  // m^3 of ~1e-8: rounding
      volume += g.volume[e];
    }
    EXPECT_NEAR(volume, 0.02 * 0.01 * 0.005, 1e-18);
  }
}

TEST(TetElement, Tet10DistortionOfAMidNodeOffItsEdge) {
  Mesh m = testing::box(0.01, 0.01, 0.01, 1, 1, 1, ElementType::Tet10);
  const Tet10Distortion straight = tet10_distortion(m, 0);
  EXPECT_NEAR(straight.min_scaled_jacobian, 1.0, 1e-12);
  EXPECT_NEAR(straight.mid_node_offset, 0.0, 1e-12);
  // Move mid-node 4 (edge 0-1) along its edge by a fraction f of the edge's length.
  const int* c = m.conn.data();
  const Eigen::Vector3d X0 = m.X[c[0]], X1 = m.X[c[1]], mid = 0.5 * (X0 + X1);
  for (double f : {0.1, 0.25, 0.3}) {
    m.X[c[4]] = mid + f * (X1 - X0);
    const Tet10Distortion d = tet10_distortion(m, 0);
    EXPECT_EQ(d.farthest_mid_node, 4);
    EXPECT_NEAR(d.mid_node_offset, f, 1e-12);
    if (f < 0.25) {
      EXPECT_GT(d.min_scaled_jacobian, 0.0) << f;
    } else if (f == 0.25) {
      EXPECT_NEAR(d.min_scaled_jacobian, 0.0, 1e-12);  // folds at a quarter, as documented
    } else {
      EXPECT_LT(d.min_scaled_jacobian, 0.0) << f;
    }
    EXPECT_LT(d.min_scaled_jacobian, 1.0);
  }
}

}  // namespace
}  // namespace pneufem

#pragma once
// Small structured meshes for engine tests: a box and a (mapped) quarter thick-walled cylinder.
// Hex cells are split into 6 tetrahedra along the main diagonal (Kuhn), which is conforming.
#include <array>
#include <cmath>
#include <functional>
#include <memory>

#include "engine/model.h"
#include "materials/hyperelastic.h"

namespace pneufem::testing {

/// Structured grid of (nx, ny, nz) cells on [0,1]^3 mapped through `map` (reference -> physical).
inline Mesh mapped_grid(int nx, int ny, int nz, ElementType type,
                        const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& map) {
  Mesh m;
  m.type = type;
  // For Tet10 build a grid with twice the resolution so mid-edge nodes lie on the mapped
  // (possibly curved) geometry: isoparametric elements.
  const int f = type == ElementType::Tet10 ? 2 : 1;
  const int Nx = f * nx + 1, Ny = f * ny + 1, Nz = f * nz + 1;
  auto id = [&](int i, int j, int k) { return i + Nx * (j + Ny * k); };
  m.X.resize(static_cast<std::size_t>(Nx) * Ny * Nz);
  for (int k = 0; k < Nz; ++k)
    for (int j = 0; j < Ny; ++j)
      for (int i = 0; i < Nx; ++i)
        m.X[id(i, j, k)] = map(Eigen::Vector3d(double(i) / (Nx - 1), double(j) / (Ny - 1), double(k) / (Nz - 1)));
  const std::array<std::array<int, 3>, 6> perms = {{{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  std::vector<char> used(m.X.size(), 0);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& p : perms) {
          // corners in fine-grid index space
          std::array<std::array<int, 3>, 4> c;
          std::array<int, 3> cur = {f * i, f * j, f * k};
          c[0] = cur;
          for (int s = 0; s < 3; ++s) {
            cur[p[s]] += f;
            c[s + 1] = cur;
          }
          // orientation: swap two corners if the reference tet is negative
          auto vec = [&](int a) { return Eigen::Vector3d(c[a][0], c[a][1], c[a][2]); };
          if ((vec(1) - vec(0)).cross(vec(2) - vec(0)).dot(vec(3) - vec(0)) < 0) std::swap(c[1], c[2]);
          std::array<int, 10> n{};
          for (int a = 0; a < 4; ++a) n[a] = id(c[a][0], c[a][1], c[a][2]);
          if (type == ElementType::Tet10) {
            static constexpr int E[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
            for (int e = 0; e < 6; ++e) {
              const auto& a = c[E[e][0]];
              const auto& b = c[E[e][1]];
              n[4 + e] = id((a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2);
            }
          }
          for (int a = 0; a < m.npe(); ++a) {
            m.conn.push_back(n[a]);
            used[n[a]] = 1;
          }
        }
  // Drop unused nodes (fine-grid face/cell centres).
  std::vector<int> remap(m.X.size(), -1);
  std::vector<Eigen::Vector3d> X;
  for (std::size_t i = 0; i < m.X.size(); ++i)
    if (used[i]) {
      remap[i] = static_cast<int>(X.size());
      X.push_back(m.X[i]);
    }
  for (int& v : m.conn) v = remap[v];
  m.X.swap(X);
  m.ensure_ids();
  return m;
}

inline Mesh box(double Lx, double Ly, double Lz, int nx, int ny, int nz, ElementType type) {
  return mapped_grid(nx, ny, nz, type, [=](const Eigen::Vector3d& s) {
    return Eigen::Vector3d(Lx * s.x(), Ly * s.y(), Lz * s.z());
  });
}

/// Nodes with coordinate `axis` equal to `value` (within tol).
inline std::vector<int> nodes_on_plane(const Mesh& m, int axis, double value, double tol = 1e-12) {
  std::vector<int> out;
  for (int i = 0; i < m.num_nodes(); ++i)
    if (std::abs(m.X[i][axis] - value) <= tol) out.push_back(i);
  return out;
}

/// Boundary faces whose corner nodes all satisfy `pred`.
inline std::vector<FaceRef> faces_where(const Mesh& m, const std::function<bool(const Eigen::Vector3d&)>& pred) {
  std::vector<FaceRef> out;
  for (const FaceRef& f : boundary_faces(m)) {
    const int* ln = face_local_nodes(m.type, f.local_face);
    const int* n = m.element(f.element);
    if (pred(m.X[n[ln[0]]]) && pred(m.X[n[ln[1]]]) && pred(m.X[n[ln[2]]])) out.push_back(f);
  }
  return out;
}

/// A one-part model with nothing fixed yet.
inline Model single_part_model(Mesh mesh, MaterialPtr mat, double density = 1000.0) {
  Model model;
  model.mesh = std::move(mesh);
  model.parts.push_back(Part{"solid", std::move(mat), density});
  model.element_part.assign(model.mesh.num_elements(), 0);
  model.fixed.assign(3 * model.mesh.num_nodes(), 0);
  return model;
}

inline void fix(Model& model, const std::vector<int>& nodes, std::array<bool, 3> dofs) {
  for (int n : nodes)
    for (int d = 0; d < 3; ++d)
      if (dofs[d]) model.fixed[3 * n + d] = 1;
}

inline MaterialPtr neo_hookean(double mu, double K) {
  return std::make_shared<InvariantMaterial<NeoHookean>>(NeoHookean(0.5 * mu, K));
}
inline MaterialPtr ecoflex(double K_over_mu = 100.0) {
  const double C10 = 0.019e6;
  return std::make_shared<InvariantMaterial<Yeoh>>(Yeoh(C10, 9.0e2, -4.75, K_over_mu * 2 * C10));
}

}  // namespace pneufem::testing

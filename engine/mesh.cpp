#include "engine/mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <unordered_map>

#include <Eigen/Geometry>

namespace pneufem {

namespace {
// Abaqus faces S1..S4 (0-based): corners then mid-edges, see mesh.h.
constexpr int kFaces4[4][3] = {{0, 1, 2}, {0, 3, 1}, {1, 3, 2}, {2, 3, 0}};
constexpr int kFaces10[4][6] = {
    {0, 1, 2, 4, 5, 6}, {0, 3, 1, 7, 8, 4}, {1, 3, 2, 8, 9, 5}, {2, 3, 0, 9, 7, 6}};
// Tet10 mid-edge node k (4..9) sits between these corners.
constexpr int kEdges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
}  // namespace

const int* face_local_nodes(ElementType type, int local_face) {
  return type == ElementType::Tet4 ? kFaces4[local_face] : kFaces10[local_face];
}

std::uint16_t Mesh::region_id(const std::string& name) {
  int r = find_region(name);
  if (r >= 0) return static_cast<std::uint16_t>(r);
  region_names.push_back(name);
  return static_cast<std::uint16_t>(region_names.size() - 1);
}

int Mesh::find_region(const std::string& name) const {
  for (std::size_t i = 0; i < region_names.size(); ++i)
    if (region_names[i] == name) return static_cast<int>(i);
  return -1;
}

namespace {
/// "<scope>.<id - offset>" when entity i belongs to an id scope, else "<id>".
std::string scoped_name(long id, std::size_t i, const std::vector<std::uint16_t>& scope,
                        const std::vector<Mesh::IdScope>& scopes, long Mesh::IdScope::*offset) {
  if (i >= scope.size() || scope[i] >= scopes.size()) return std::to_string(id);
  const Mesh::IdScope& s = scopes[scope[i]];
  return s.name + "." + std::to_string(id - s.*offset);
}

/// The external id of entity i (index + 1 without ids).
long external_id(std::size_t i, const std::vector<long>& ids) {
  return i < ids.size() ? ids[i] : static_cast<long>(i) + 1;
}
}  // namespace

std::string Mesh::node_name(int n) const {
  const std::size_t i = static_cast<std::size_t>(n);
  return scoped_name(external_id(i, node_ids), i, node_scope, id_scopes, &IdScope::node_id_offset);
}

std::string Mesh::element_name(int e) const {
  const std::size_t i = static_cast<std::size_t>(e);
  return scoped_name(external_id(i, element_ids), i, element_scope, id_scopes, &IdScope::element_id_offset);
}

std::string Mesh::element_label(int e) const {
  const std::size_t i = static_cast<std::size_t>(e);
  std::string detail;
  if (element_sources.size() == static_cast<std::size_t>(num_elements()) && element_sources[i].piece > 0) {
    // The deck element it was split from shares its id scope.
    const ElementSource& src = element_sources[i];
    detail = "tet " + std::to_string(src.piece) + " of " + std::string(src.type.data()) + " " +
             scoped_name(src.id, i, element_scope, id_scopes, &IdScope::element_id_offset);
  }
  if (i < region.size() && region[i] < region_names.size())
    detail += (detail.empty() ? "region '" : ", region '") + region_names[region[i]] + "'";
  const std::string s = "element " + element_name(e);
  return detail.empty() ? s : s + " (" + detail + ")";
}

void Mesh::ensure_ids() {
  if (node_ids.size() != X.size()) {
    node_ids.resize(X.size());
    for (std::size_t i = 0; i < X.size(); ++i) node_ids[i] = static_cast<long>(i) + 1;
  }
  const auto ne = static_cast<std::size_t>(num_elements());
  if (element_ids.size() != ne) {
    element_ids.resize(ne);
    for (std::size_t i = 0; i < ne; ++i) element_ids[i] = static_cast<long>(i) + 1;
  }
  if (region.size() != ne) {
    std::uint16_t r = region_id("default");
    region.assign(ne, r);
  }
}

double corner_volume(const Mesh& mesh, int e) {
  const int* n = mesh.element(e);
  const Eigen::Vector3d a = mesh.X[n[1]] - mesh.X[n[0]];
  const Eigen::Vector3d b = mesh.X[n[2]] - mesh.X[n[0]];
  const Eigen::Vector3d c = mesh.X[n[3]] - mesh.X[n[0]];
  return a.cross(b).dot(c) / 6.0;
}

MeshStats compute_stats(const Mesh& mesh) {
  MeshStats s;
  s.nodes = mesh.num_nodes();
  s.elements = mesh.num_elements();
  s.element_type = mesh.type == ElementType::Tet4 ? "C3D4" : "C3D10";
  if (s.nodes == 0) return s;
  s.bbox_min = s.bbox_max = mesh.X[0];
  for (const auto& x : mesh.X) {
    s.bbox_min = s.bbox_min.cwiseMin(x);
    s.bbox_max = s.bbox_max.cwiseMax(x);
  }
  for (std::size_t r = 0; r < mesh.region_names.size(); ++r) s.elements_per_region[mesh.region_names[r]] = 0;
  s.min_edge_m = std::numeric_limits<double>::infinity();
  s.min_quality = 1.0;
  double qsum = 0.0;
  for (int e = 0; e < s.elements; ++e) {
    if (static_cast<std::size_t>(e) < mesh.region.size() && mesh.region[e] < mesh.region_names.size())
      ++s.elements_per_region[mesh.region_names[mesh.region[e]]];
    const int* n = mesh.element(e);
    const double V = corner_volume(mesh, e);
    s.volume_m3 += V;
    // Radius-ratio quality q = 3 r_in / r_circ (1 for the regular tetrahedron).
    std::array<Eigen::Vector3d, 4> p = {mesh.X[n[0]], mesh.X[n[1]], mesh.X[n[2]], mesh.X[n[3]]};
    double area = 0.0;
    for (int f = 0; f < 4; ++f) {
      const int* fn = kFaces4[f];
      area += 0.5 * (p[fn[1]] - p[fn[0]]).cross(p[fn[2]] - p[fn[0]]).norm();
    }
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        const double l = (p[i] - p[j]).norm();
        s.min_edge_m = std::min(s.min_edge_m, l);
        s.max_edge_m = std::max(s.max_edge_m, l);
      }
    const Eigen::Vector3d a = p[1] - p[0], b = p[2] - p[0], c = p[3] - p[0];
    const Eigen::Vector3d num = a.squaredNorm() * b.cross(c) + b.squaredNorm() * c.cross(a) + c.squaredNorm() * a.cross(b);
    const double r_circ = num.norm() / (12.0 * std::abs(V) + 1e-300);
    const double r_in = 3.0 * std::abs(V) / (area + 1e-300);
    const double q = std::clamp(3.0 * r_in / (r_circ + 1e-300), 0.0, 1.0);
    s.min_quality = std::min(s.min_quality, q);
    qsum += q;
  }
  s.mean_quality = s.elements ? qsum / s.elements : 0.0;
  return s;
}

Mesh promote_to_tet10(const Mesh& m4) {
  if (m4.type == ElementType::Tet10) return m4;
  Mesh m = m4;
  m.type = ElementType::Tet10;
  m.conn.clear();
  const int ne = m4.num_elements();
  m.conn.reserve(static_cast<std::size_t>(ne) * 10);
  std::unordered_map<std::uint64_t, int> edge_node;
  long next_id = 0;
  for (long id : m.node_ids) next_id = std::max(next_id, id);
  for (int e = 0; e < ne; ++e) {
    const int* n = m4.element(e);
    for (int k = 0; k < 4; ++k) m.conn.push_back(n[k]);
    for (const auto& ed : kEdges) {
      const int a = std::min(n[ed[0]], n[ed[1]]), b = std::max(n[ed[0]], n[ed[1]]);
      const std::uint64_t key = (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
      auto [it, inserted] = edge_node.try_emplace(key, static_cast<int>(m.X.size()));
      if (inserted) {
        m.X.push_back(0.5 * (m.X[a] + m.X[b]));
        if (!m.node_ids.empty()) m.node_ids.push_back(++next_id);
      }
      m.conn.push_back(it->second);
    }
  }
  // Node sets: add a mid-edge node when both its corners are in the set.
  for (auto& [name, nodes] : m.node_sets) {
    std::vector<char> in(m.X.size(), 0);
    for (int i : nodes) in[i] = 1;
    for (const auto& [key, mid] : edge_node) {
      const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
      if (in[a] && in[b]) in[mid] = 1;
    }
    nodes.clear();
    for (std::size_t i = 0; i < in.size(); ++i)
      if (in[i]) nodes.push_back(static_cast<int>(i));
  }
  return m;
}

std::vector<FaceRef> boundary_faces(const Mesh& mesh) {
  // A face is identified by its sorted corner triple.
  struct Key {
    int a, b, c;
    bool operator==(const Key&) const = default;
  };
  struct Hash {
    std::size_t operator()(const Key& k) const {
      return std::hash<long long>()((static_cast<long long>(k.a) * 73856093LL) ^ (static_cast<long long>(k.b) * 19349663LL) ^
                                    (static_cast<long long>(k.c) * 83492791LL));
    }
  };
  std::unordered_map<Key, int, Hash> count;
  const int ne = mesh.num_elements();
  auto key_of = [&](int e, int f) {
    const int* n = mesh.element(e);
    std::array<int, 3> c = {n[kFaces4[f][0]], n[kFaces4[f][1]], n[kFaces4[f][2]]};
    std::sort(c.begin(), c.end());
    return Key{c[0], c[1], c[2]};
  };
  for (int e = 0; e < ne; ++e)
    for (int f = 0; f < 4; ++f) ++count[key_of(e, f)];
  std::vector<FaceRef> out;
  for (int e = 0; e < ne; ++e)
    for (int f = 0; f < 4; ++f)
      if (count[key_of(e, f)] == 1) out.push_back({e, f});
  return out;
}

void renumber_nodes_by_first_use(Mesh& m) {
  std::vector<int> new_id(m.X.size(), -1);
  int next = 0;
  for (int& v : m.conn) {
    if (new_id[v] < 0) new_id[v] = next++;
    v = new_id[v];
  }
  std::vector<Eigen::Vector3d> X(static_cast<std::size_t>(next));
  for (std::size_t i = 0; i < m.X.size(); ++i)
    if (new_id[i] >= 0) X[new_id[i]] = m.X[i];
  m.X = std::move(X);
  for (auto& [name, nodes] : m.node_sets) {
    std::vector<int> out;
    out.reserve(nodes.size());
    for (int i : nodes)
      if (new_id[i] >= 0) out.push_back(new_id[i]);
    std::sort(out.begin(), out.end());
    nodes = std::move(out);
  }
  m.node_ids.clear();
}

}  // namespace pneufem

#pragma once
// Tetrahedral mesh with named sets, surfaces and region tags.
//
// Node numbering and face numbering follow Abaqus/CalculiX (C3D4, C3D10), so decks round-trip:
//   corners 0..3, mid-edge nodes 4:(0,1) 5:(1,2) 6:(2,0) 7:(0,3) 8:(1,3) 9:(2,3)   (0-based)
//   faces S1:(0,1,2) S2:(0,3,1) S3:(1,3,2) S4:(2,3,0)  -- local_face 0..3 here.
// Coordinates are in metres (SI); importers convert.
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace pneufem {

enum class ElementType : std::uint8_t { Tet4, Tet10 };

constexpr int nodes_per_element(ElementType t) { return t == ElementType::Tet4 ? 4 : 10; }
constexpr int nodes_per_face(ElementType t) { return t == ElementType::Tet4 ? 3 : 6; }

/// One element face: element index and Abaqus face number minus one (0..3).
struct FaceRef {
  int element = 0;
  int local_face = 0;
  friend bool operator==(const FaceRef&, const FaceRef&) = default;
};

/// Canonical region names of a pneu-net; diagnosis asks which region explains an error.
/// Meshes from other sources may carry any region names (scene maps element sets to them).
namespace regions {
inline constexpr const char* kInteriorWall = "interior_wall";
inline constexpr const char* kRoof = "roof";
inline constexpr const char* kSideWall = "side_wall";
inline constexpr const char* kEndCap = "end_cap";
inline constexpr const char* kBase = "base";
inline constexpr const char* kFabric = "fabric";
}  // namespace regions

/// Where an element of a mesh read from a deck of hexahedra, wedges or pyramids came from: the
/// deck's elements are split into tetrahedra (scenes/solid_split.h), and messages should still lead
/// the user to the element of their mesh file.
struct ElementSource {
  long id = 0;                ///< the deck's element id, as element_ids (offset by its id scope)
  std::uint8_t piece = 0;     ///< 1-based tetrahedron of that element; 0 = the deck's own tetrahedron
  std::uint8_t pieces = 0;    ///< tetrahedra it was split into
  std::array<char, 6> type{};  ///< its type, NUL-terminated ("C3D8", "C3D20")
};

struct Mesh {
  ElementType type = ElementType::Tet10;
  std::vector<Eigen::Vector3d> X;  ///< reference node coordinates (m)
  std::vector<int> conn;           ///< num_elements() * nodes_per_element(type), 0-based node ids

  std::vector<std::string> region_names;   ///< region id -> name
  std::vector<std::uint16_t> region;       ///< per element region id (index into region_names)

  std::vector<long> node_ids;     ///< external (1-based, as in a deck) id of each node
  std::vector<long> element_ids;  ///< external id of each element
  std::vector<ElementSource> element_sources;  ///< per element, or empty when nothing was split

  /// A deck of several Abaqus instances numbers each instance's nodes and elements on its own.
  /// Then node_ids / element_ids are the deck's ids plus an offset per instance (distinct ids,
  /// as a flat deck needs) and messages name an entity "<instance>.<deck id>", as the user knows
  /// it. Empty (plain ids) for every other mesh, a deck with one instance among them.
  struct IdScope {
    std::string name;  ///< instance name as written in the deck (the assembly's for its own nodes)
    long node_id_offset = 0;
    long element_id_offset = 0;
  };
  std::vector<IdScope> id_scopes;
  std::vector<std::uint16_t> node_scope;     ///< per node: index into id_scopes (nodes added later: none)
  std::vector<std::uint16_t> element_scope;  ///< per element: index into id_scopes

  std::map<std::string, std::vector<int>> node_sets;     ///< name -> sorted node indices
  std::map<std::string, std::vector<int>> element_sets;  ///< name -> sorted element indices
  std::map<std::string, std::vector<FaceRef>> surfaces;  ///< name -> element faces

  int num_nodes() const { return static_cast<int>(X.size()); }
  int npe() const { return nodes_per_element(type); }
  int num_elements() const { return static_cast<int>(conn.size()) / npe(); }
  const int* element(int e) const { return conn.data() + static_cast<std::size_t>(e) * npe(); }

  /// Region id of `name`, adding it if new.
  std::uint16_t region_id(const std::string& name);
  /// Region id of `name` or -1 when absent.
  int find_region(const std::string& name) const;

  /// Fills node_ids / element_ids with 1..n when they are empty.
  void ensure_ids();

  /// The id of node n / element e as the user's mesh file writes it: "123", or "Actuator-1.123"
  /// for a deck of several instances (id_scopes); the 1-based index when the mesh has no ids.
  std::string node_name(int n) const;
  std::string element_name(int e) const;

  /// "element <element_name> (region '<tag>')" for messages, the region when the mesh is tagged;
  /// for a tetrahedron split from a deck's element also that element, named in the same id scope:
  /// "element 1043 (tet 3 of C3D8 57, region '<tag>')", "element Actuator-1.1043 (tet 3 of C3D8
  /// Actuator-1.57, region '<tag>')". Every message that names an element of a mesh uses it.
  std::string element_label(int e) const;
};

/// Local node indices (0-based, in the element) of face `local_face`: corners first, then the
/// mid-edge nodes for Tet10. The order is the Abaqus order, whose right-hand normal points
/// INTO the element; callers wanting the outward normal reverse the orientation.
const int* face_local_nodes(ElementType type, int local_face);

/// Signed volume of the straight-sided tetrahedron spanned by the element corners (m^3).
double corner_volume(const Mesh& mesh, int e);

/// Summary statistics recorded in every output.
struct MeshStats {
  int nodes = 0;
  int elements = 0;
  std::string element_type;
  std::map<std::string, int> elements_per_region;
  double volume_m3 = 0.0;
  double min_edge_m = 0.0;
  double max_edge_m = 0.0;
  double min_quality = 0.0;  ///< min over elements of the normalised radius ratio in (0, 1]
  double mean_quality = 0.0;
  Eigen::Vector3d bbox_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d bbox_max = Eigen::Vector3d::Zero();
};
MeshStats compute_stats(const Mesh& mesh);

/// Converts a Tet4 mesh into a Tet10 mesh with straight mid-edge nodes (sets and surfaces kept).
Mesh promote_to_tet10(const Mesh& tet4);

/// All boundary faces (faces with no neighbour), in element order. Used for the surface of the
/// actuator and to check user surfaces.
std::vector<FaceRef> boundary_faces(const Mesh& mesh);

/// Renumbers nodes by first use in the connectivity and drops unused ones (node sets follow,
/// node_ids are cleared). Meshers that emit elements slab by slab along the actuator keep the
/// matrix bandwidth ~ one slab of nodes this way (scenes/pneunet.cpp, scenes/stl/mesher.cpp).
void renumber_nodes_by_first_use(Mesh& m);

}  // namespace pneufem

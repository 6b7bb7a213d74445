// Tests of viz/vtk_output: element fields against closed-form neo-Hookean values under a
// homogeneous deformation, VTU round trip through VTK's own reader, the PVD index, and the
// atomic-write failure paths.
#include "viz/vtk_output.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkQuadraticTetra.h>
#include <vtkStringArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>
#include <vtkXMLUnstructuredGridReader.h>

#include "core/errors.h"
#include "materials/hyperelastic.h"

namespace pneufem {

// Readable parameter names in gtest's messages (found by ADL, hence outside the anonymous namespace).
void PrintTo(ElementType t, std::ostream* os) { *os << (t == ElementType::Tet4 ? "Tet4" : "Tet10"); }

namespace {

namespace fs = std::filesystem;

constexpr double kC10 = 1e5;  // Pa
constexpr double kK = 1e7;    // Pa
constexpr double kEdge = 0.02;  // m, cube edge

/// Neo-Hookean with a dummy 3-double history that fields() reports verbatim, so the test can
/// check that every quadrature point receives its own slice of the state.
class TaggedNeoHookean final : public Material {
 public:
  std::string name() const override { return "tagged(neo_hookean)"; }
  int state_size() const override { return 3; }
  void init_state(std::span<double> s) const override { std::fill(s.begin(), s.end(), 0.0); }
  void evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                std::span<double> state_new, std::span<PointResponse> out, bool tangent) const override {
    base_.evaluate(F, step, {}, {}, out, tangent);
    std::copy(state_old.begin(), state_old.end(), state_new.begin());
  }
  PointFields fields(std::span<const double> s) const override { return {s[0], s[1], s[2]}; }
  double initial_shear_modulus() const override { return base_.initial_shear_modulus(); }
  double initial_bulk_modulus() const override { return base_.initial_bulk_modulus(); }

 private:
  InvariantMaterial<NeoHookean> base_{NeoHookean(kC10, kK)};
};

/// Cube [0, kEdge]^3 split into the 6 Kuhn tetrahedra around its diagonal. For Tet10 the
/// mid-edge nodes are moved off the edges (curved elements, unequal quadrature weights).
/// Elements 0-2 use a plain neo-Hookean part, 3-5 the tagged one; regions alternate.
Model cube_model(ElementType type) {
  Model m;
  Mesh& mesh = m.mesh;
  mesh.type = ElementType::Tet4;
  for (int b = 0; b < 8; ++b) mesh.X.emplace_back(kEdge * (b & 1), kEdge * ((b >> 1) & 1), kEdge * ((b >> 2) & 1));
  const std::array<std::array<int, 3>, 6> perms = {{{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  for (const auto& p : perms) {
    std::array<int, 4> n = {0, 1 << p[0], (1 << p[0]) | (1 << p[1]), 7};
    if ((mesh.X[n[1]] - mesh.X[n[0]]).cross(mesh.X[n[2]] - mesh.X[n[0]]).dot(mesh.X[n[3]] - mesh.X[n[0]]) < 0)
      std::swap(n[1], n[2]);
    mesh.conn.insert(mesh.conn.end(), n.begin(), n.end());
  }
  if (type == ElementType::Tet10) {
    mesh = promote_to_tet10(mesh);
    for (int i = 8; i < mesh.num_nodes(); ++i)
      mesh.X[i] += 0.03 * kEdge * Eigen::Vector3d(std::sin(i), std::cos(1.3 * i), std::sin(2.1 * i + 0.5));
  }
  const int roof = mesh.region_id(regions::kRoof), base = mesh.region_id(regions::kBase);
  for (int e = 0; e < 6; ++e) mesh.region.push_back(static_cast<std::uint16_t>(e % 2 ? base : roof));
  mesh.ensure_ids();
  m.parts = {Part{"elastomer", std::make_shared<InvariantMaterial<NeoHookean>>(NeoHookean(kC10, kK))},
             Part{"tagged", std::make_shared<TaggedNeoHookean>()}};
  m.element_part = {0, 0, 0, 1, 1, 1};
  m.fixed.assign(3 * mesh.num_nodes(), 0);
  m.fixed[0] = m.fixed[1] = m.fixed[2] = 1;
  validate(m);
  return m;
}

/// u = (F0 - I) X at every node: a linear field, which Tet4 and (isoparametric, even curved)
/// Tet10 interpolate exactly, so F = F0 at every quadrature point up to rounding.
Eigen::VectorXd homogeneous_u(const Mesh& mesh, const Mat3& F0) {
  Eigen::VectorXd u(3 * mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) u.segment<3>(3 * i) = (F0 - Mat3::Identity()) * mesh.X[i];
  return u;
}

/// State of the tagged elements: point q of element e holds (0.01 (e+1), 100 (e+1), q + 1).
std::vector<double> tagged_state(const Assembler& assembler) {
  std::vector<double> s = assembler.initial_state();
  for (int e = 0; e < assembler.model().mesh.num_elements(); ++e) {
    const std::span<const double> se = assembler.element_state(s, e);
    const std::size_t off = static_cast<std::size_t>(se.data() - s.data());
    for (std::size_t q = 0; q < se.size() / 3; ++q) {
      s[off + 3 * q] = 0.01 * (e + 1);
      s[off + 3 * q + 1] = 100.0 * (e + 1);
      s[off + 3 * q + 2] = static_cast<double>(q + 1);
    }
  }
  return s;
}

/// Closed-form neo-Hookean (Abaqus form, hyperelastic.h) at a homogeneous F:
///   sigma = (2 C10 / J) dev(Bbar) + K (J - 1) I,  Bbar = J^{-2/3} F F^T,
///   psi = C10 (I1b - 3) + K/2 (J - 1)^2 (per reference volume).
struct Exact {
  Mat3 sigma;
  double psi;
};
Exact neo_hookean_exact(const Mat3& F) {
  const double J = F.determinant();
  const Mat3 Bbar = std::pow(J, -2.0 / 3.0) * F * F.transpose();
  const Mat3 devBbar = Bbar - Bbar.trace() / 3.0 * Mat3::Identity();
  return {2.0 * kC10 / J * devBbar + kK * (J - 1.0) * Mat3::Identity(),
          kC10 * (Bbar.trace() - 3.0) + 0.5 * kK * (J - 1.0) * (J - 1.0)};
}

/// Von Mises in component form (independent of the implementation's deviator norm).
double von_mises_components(const Mat3& s) {
  const double d = std::pow(s(0, 0) - s(1, 1), 2) + std::pow(s(1, 1) - s(2, 2), 2) + std::pow(s(2, 2) - s(0, 0), 2);
  const double t = s(0, 1) * s(0, 1) + s(1, 2) * s(1, 2) + s(2, 0) * s(2, 0);
  return std::sqrt(0.5 * d + 3.0 * t);
}

/// A fresh directory under the system temp dir, removed at the end of the test.
struct TempDir {
  fs::path path;
  TempDir() {
    std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::replace(name.begin(), name.end(), '/', '_');
    path = fs::temp_directory_path() / ("pneufem_viz_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

const Mat3 kStretch = Eigen::Vector3d(1.2, 0.9, 1.1).asDiagonal();

class VtkOutput : public ::testing::TestWithParam<ElementType> {};

// Rounding: F carries ~10 eps relative error; sigma's sensitivity to F is ~K/|sigma| ~ 5, so
// the expected error is ~1e-14 relative. 1e-10 leaves a wide margin yet catches any real
// mistake (a missing 1/J or a wrong average is an O(1) error).
TEST_P(VtkOutput, HomogeneousFieldsMatchClosedForm) {
  const Model model = cube_model(GetParam());
  const Assembler assembler(model);
  const std::vector<double> state = tagged_state(assembler);
  Mat3 sheared = kStretch;
  sheared(0, 1) = 0.15;
  sheared(2, 0) = -0.05;
  for (const Mat3& F0 : {kStretch, sheared}) {
    const StateFields f = compute_fields(assembler, homogeneous_u(model.mesh, F0), state);
    const Exact exact = neo_hookean_exact(F0);
    ASSERT_GT(exact.sigma.norm(), 1e5);  // guards against a vacuous pass on zero stress
    ASSERT_GT(von_mises_components(exact.sigma), 1e4);

    // The closed form must agree with the material itself (sigma = P F^T / J).
    std::array<PointResponse, 1> r;
    const Mat3 F_arr[1] = {F0};
    model.material_of(0).evaluate(F_arr, {}, {}, {}, r, false);
    ASSERT_LT((r[0].P() * F0.transpose() / F0.determinant() - exact.sigma).norm(), 1e-10 * exact.sigma.norm());

    const double stretch = Eigen::JacobiSVD<Mat3>(F0).singularValues()(0);
    if (F0 == kStretch) {
      ASSERT_DOUBLE_EQ(stretch, 1.2);
    }
    ASSERT_EQ(f.cauchy_Pa.size(), 6u);
    for (int e = 0; e < 6; ++e) {
      SCOPED_TRACE("element " + std::to_string(e));
      EXPECT_LT((f.cauchy_Pa[e] - exact.sigma).norm(), 1e-10 * exact.sigma.norm());
      EXPECT_NEAR(f.von_mises_Pa[e], von_mises_components(exact.sigma), 1e-10 * exact.sigma.norm());
      EXPECT_NEAR(f.max_principal_stretch[e], stretch, 1e-12);
      EXPECT_NEAR(f.energy_density_J_m3[e], exact.psi, 1e-10 * exact.psi);
    }
  }
  const StateFields f = compute_fields(assembler, homogeneous_u(model.mesh, kStretch), state);
  ASSERT_EQ(f.displacement_m.size(), static_cast<std::size_t>(model.mesh.num_nodes()));
  for (int i = 0; i < model.mesh.num_nodes(); ++i)
    EXPECT_EQ((f.displacement_m[i] - (kStretch - Mat3::Identity()) * model.mesh.X[i]).norm(), 0.0);
}

TEST_P(VtkOutput, MaterialFieldsComeFromEachPointsState) {
  const Model model = cube_model(GetParam());
  const Assembler assembler(model);
  const StateFields f = compute_fields(assembler, homogeneous_u(model.mesh, kStretch), tagged_state(assembler));
  const ElementGeometry& g = assembler.geometry();
  for (int e = 0; e < 6; ++e) {
    SCOPED_TRACE("element " + std::to_string(e));
    const bool tagged = model.element_part[e] == 1;
    // viscous_strain is q + 1 at point q: its mean is weighted by the quadrature weights.
    double V = 0.0, mean_q1 = 0.0;
    for (int q = 0; q < g.nqp; ++q) {
      V += g.w(e, q);
      mean_q1 += g.w(e, q) * (q + 1);
    }
    EXPECT_NEAR(f.damage[e], tagged ? 0.01 * (e + 1) : 0.0, 1e-15);
    EXPECT_NEAR(f.W_max_J_m3[e], tagged ? 100.0 * (e + 1) : 0.0, 1e-12);
    EXPECT_NEAR(f.viscous_strain[e], tagged ? mean_q1 / V : 0.0, 1e-14);
  }
}

TEST_P(VtkOutput, RejectsBadInputAndInvertedElements) {
  const Model model = cube_model(GetParam());
  const Assembler assembler(model);
  const std::vector<double> state = tagged_state(assembler);
  EXPECT_THROW(compute_fields(assembler, Eigen::VectorXd::Zero(5), state), std::invalid_argument);
  const Mat3 mirror = Eigen::Vector3d(-1.0, 1.0, 1.0).asDiagonal();
  try {
    compute_fields(assembler, homogeneous_u(model.mesh, mirror), state);
    FAIL() << "an inverted state must be rejected";
  } catch (const PhysicsError& err) {
    EXPECT_EQ(err.element(), 0);  // the lowest inverted element, whatever the thread schedule
    EXPECT_NE(std::string(err.what()).find("element 1 "), std::string::npos) << err.what();
  }
}

TEST_P(VtkOutput, VtuRoundTripThroughVtkReader) {
  const Model model = cube_model(GetParam());
  const Assembler assembler(model);
  const StateFields f = compute_fields(assembler, homogeneous_u(model.mesh, kStretch), tagged_state(assembler));
  const TempDir dir;
  const fs::path file = dir.path / "state_0001.vtu";
  write_vtu(file.string(), model, f, 1.25, 3, 35.5, 87.25);
  EXPECT_FALSE(fs::exists(file.string() + ".tmp"));

  const std::string text = read_text(file);
  EXPECT_NE(text.find("compressor=\"vtkZLibDataCompressor\""), std::string::npos);
  EXPECT_NE(text.find("<AppendedData encoding=\"raw\">"), std::string::npos);

  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(file.c_str());
  reader->Update();
  vtkUnstructuredGrid* grid = reader->GetOutput();
  const int nn = model.mesh.num_nodes(), npe = model.mesh.npe();
  ASSERT_EQ(grid->GetNumberOfPoints(), nn);
  ASSERT_EQ(grid->GetNumberOfCells(), 6);
  const int vtk_type = GetParam() == ElementType::Tet4 ? VTK_TETRA : VTK_QUADRATIC_TETRA;
  vtkNew<vtkIdList> ids;
  for (int e = 0; e < 6; ++e) {
    EXPECT_EQ(grid->GetCellType(e), vtk_type);
    grid->GetCellPoints(e, ids);
    ASSERT_EQ(ids->GetNumberOfIds(), npe);
    for (int a = 0; a < npe; ++a) EXPECT_EQ(ids->GetId(a), model.mesh.element(e)[a]);
  }
  // The connectivity is copied unchanged, so VTK's mid-edge order must be Abaqus's (mesh.h).
  const int abaqus_edges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  for (int k = 0; k < 6; ++k) {
    const vtkIdType* edge = vtkQuadraticTetra::GetEdgeArray(k);
    EXPECT_EQ(edge[0], abaqus_edges[k][0]);
    EXPECT_EQ(edge[1], abaqus_edges[k][1]);
    EXPECT_EQ(edge[2], 4 + k);
  }

  // Binary appended data with lossless compression: values come back bit for bit.
  vtkDataArray* u = grid->GetPointData()->GetArray("displacement_m");
  ASSERT_NE(u, nullptr);
  ASSERT_EQ(u->GetNumberOfComponents(), 3);
  for (int i = 0; i < nn; ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(u->GetComponent(i, c), f.displacement_m[i](c));
  EXPECT_GT(f.displacement_m[7].norm(), 1e-3);  // the far corner really moved

  vtkCellData* cd = grid->GetCellData();
  vtkDataArray* sigma = cd->GetArray("cauchy_stress_Pa");
  ASSERT_NE(sigma, nullptr);
  ASSERT_EQ(sigma->GetNumberOfComponents(), 9);
  for (int e = 0; e < 6; ++e)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) EXPECT_EQ(sigma->GetComponent(e, 3 * i + j), f.cauchy_Pa[e](i, j));
  const std::pair<const char*, const std::vector<double>*> scalars[] = {
      {"von_mises_Pa", &f.von_mises_Pa},      {"max_principal_stretch", &f.max_principal_stretch},
      {"strain_energy_density_J_m3", &f.energy_density_J_m3}, {"damage", &f.damage},
      {"W_max_J_m3", &f.W_max_J_m3},          {"viscous_strain", &f.viscous_strain}};
  for (const auto& [name, values] : scalars) {
    vtkDataArray* a = cd->GetArray(name);
    ASSERT_NE(a, nullptr) << name;
    for (int e = 0; e < 6; ++e) EXPECT_EQ(a->GetTuple1(e), (*values)[e]) << name;
  }
  EXPECT_GT(f.von_mises_Pa[0], 1e4);
  vtkDataArray* region = cd->GetArray("region_id");
  vtkDataArray* material = cd->GetArray("material_id");
  ASSERT_TRUE(region && material);
  for (int e = 0; e < 6; ++e) {
    EXPECT_EQ(region->GetTuple1(e), model.mesh.region[e]);
    EXPECT_EQ(material->GetTuple1(e), model.element_part[e]);
  }

  vtkFieldData* fd = grid->GetFieldData();
  const std::pair<const char*, double> scalars_fd[] = {
      {"time_s", 1.25}, {"trial", 3.0}, {"pressure_kPa", 35.5}, {"angle_deg", 87.25}};
  for (const auto& [name, value] : scalars_fd) {
    vtkDataArray* a = fd->GetArray(name);
    ASSERT_NE(a, nullptr) << name;
    EXPECT_EQ(a->GetTuple1(0), value) << name;
  }
  auto* names = vtkStringArray::SafeDownCast(fd->GetAbstractArray("region_names"));
  ASSERT_NE(names, nullptr);
  ASSERT_EQ(names->GetNumberOfValues(), 2);
  EXPECT_EQ(names->GetValue(model.mesh.region[0]), regions::kRoof);
  EXPECT_EQ(names->GetValue(model.mesh.region[1]), regions::kBase);
  auto* parts = vtkStringArray::SafeDownCast(fd->GetAbstractArray("material_names"));
  ASSERT_NE(parts, nullptr);
  ASSERT_EQ(parts->GetNumberOfValues(), 2);
  EXPECT_EQ(parts->GetValue(1), "tagged");
}

// The fabric's stress is ~1000x the silicone's: it gets its own von Mises field (NaN in the
// silicone's, and the other way round) so that colouring by von_mises_Pa shows the silicone, and
// stress is also point data, averaged over each layer's own elements (never across the two).
// Here elements 3-5 are made 1000x stiffer than 0-2, the ratio of the fabric to the silicone.
TEST_P(VtkOutput, StiffLayerHasItsOwnFieldsAndPointDataAveragesEachLayer) {
  Model model = cube_model(GetParam());
  model.parts[1] = Part{"fabric", std::make_shared<InvariantMaterial<NeoHookean>>(NeoHookean(1000 * kC10, 1000 * kK))};
  const Assembler assembler(model);
  const StateFields f = compute_fields(assembler, homogeneous_u(model.mesh, kStretch), assembler.initial_state());
  const double vm_soft = von_mises_components(neo_hookean_exact(kStretch).sigma);
  ASSERT_GT(vm_soft, 1e4);
  const TempDir dir;
  const fs::path file = dir.path / "stiff.vtu";
  write_vtu(file.string(), model, f, 0.0, 1, 0.0, 0.0);
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(file.c_str());
  reader->Update();
  vtkUnstructuredGrid* grid = reader->GetOutput();

  vtkDataArray* soft_cells = grid->GetCellData()->GetArray("von_mises_Pa");
  vtkDataArray* stiff_cells = grid->GetCellData()->GetArray("fabric_von_mises_Pa");
  ASSERT_TRUE(soft_cells && stiff_cells);
  for (int e = 0; e < 6; ++e) {
    const bool stiff = model.element_part[e] == 1;
    EXPECT_EQ(std::isnan(soft_cells->GetTuple1(e)), stiff) << e;
    EXPECT_EQ(std::isnan(stiff_cells->GetTuple1(e)), !stiff) << e;
    EXPECT_EQ(stiff ? stiff_cells->GetTuple1(e) : soft_cells->GetTuple1(e), f.von_mises_Pa[e]) << e;
  }
  EXPECT_GT(f.von_mises_Pa[3], 500 * vm_soft);  // the layer really is the 1000x stiffer one

  // Points: the homogeneous state gives every soft element the closed-form stress, so every node
  // of a soft element carries exactly it (to rounding) and a node of stiff elements only, NaN.
  std::vector<int> soft_node(model.mesh.num_nodes(), 0), stiff_node(model.mesh.num_nodes(), 0);
  for (int e = 0; e < 6; ++e)
    for (int a = 0; a < model.mesh.npe(); ++a) (model.element_part[e] == 1 ? stiff_node : soft_node)[model.mesh.element(e)[a]] = 1;
  vtkDataArray* vm = grid->GetPointData()->GetArray("von_mises_Pa");
  vtkDataArray* vm_fabric = grid->GetPointData()->GetArray("fabric_von_mises_Pa");
  vtkDataArray* sigma = grid->GetPointData()->GetArray("cauchy_stress_Pa");
  ASSERT_TRUE(vm && vm_fabric && sigma);
  ASSERT_EQ(sigma->GetNumberOfComponents(), 9);
  const Mat3 exact = neo_hookean_exact(kStretch).sigma;
  int soft_only = 0, stiff_only = 0;
  for (int n = 0; n < model.mesh.num_nodes(); ++n) {
    SCOPED_TRACE("node " + std::to_string(n));
    if (soft_node[n]) {
      EXPECT_NEAR(vm->GetTuple1(n), vm_soft, 1e-10 * vm_soft);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) EXPECT_NEAR(sigma->GetComponent(n, 3 * i + j), exact(i, j), 1e-10 * exact.norm());
    } else {
      EXPECT_TRUE(std::isnan(vm->GetTuple1(n)));
      EXPECT_TRUE(std::isnan(sigma->GetComponent(n, 0)));
    }
    EXPECT_EQ(std::isnan(vm_fabric->GetTuple1(n)), !stiff_node[n]);
    if (stiff_node[n]) {
      EXPECT_GT(vm_fabric->GetTuple1(n), 500 * vm_soft);
    }
    soft_only += soft_node[n] && !stiff_node[n];
    stiff_only += stiff_node[n] && !soft_node[n];
  }
  EXPECT_GT(soft_only + stiff_only, 0);  // the test sees both kinds of node, or proves less

  // One material throughout: no stiff layer, no fabric field.
  const Model plain = cube_model(GetParam());
  const Assembler plain_asm(plain);
  const fs::path plain_file = dir.path / "plain.vtu";
  write_vtu(plain_file.string(), plain,
            compute_fields(plain_asm, homogeneous_u(plain.mesh, kStretch), tagged_state(plain_asm)), 0.0, 1, 0.0, 0.0);
  vtkNew<vtkXMLUnstructuredGridReader> plain_reader;
  plain_reader->SetFileName(plain_file.c_str());
  plain_reader->Update();
  EXPECT_EQ(plain_reader->GetOutput()->GetCellData()->GetArray("fabric_von_mises_Pa"), nullptr);
  EXPECT_NE(plain_reader->GetOutput()->GetPointData()->GetArray("von_mises_Pa"), nullptr);
}

INSTANTIATE_TEST_SUITE_P(Elements, VtkOutput, ::testing::Values(ElementType::Tet4, ElementType::Tet10),
                         [](const ::testing::TestParamInfo<ElementType>& p) {
                           return p.param == ElementType::Tet4 ? "Tet4" : "Tet10";
                         });

TEST(VtkOutputErrors, MissingDirectoryThrowsWithPathAndLeavesNoTmp) {
  const Model model = cube_model(ElementType::Tet4);
  const Assembler assembler(model);
  const StateFields f = compute_fields(assembler, homogeneous_u(model.mesh, kStretch), tagged_state(assembler));
  const TempDir dir;
  const fs::path file = dir.path / "no_such_dir" / "out.vtu";
  try {
    write_vtu(file.string(), model, f, 0.0, 0, 0.0, 0.0);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& err) {
    const std::string msg = err.what();
    EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
    EXPECT_NE(msg.find("does not exist"), std::string::npos) << msg;
  }
  EXPECT_FALSE(fs::exists(file.string() + ".tmp"));
  EXPECT_FALSE(fs::exists(dir.path / "no_such_dir"));
}

// The temporary is written fine but cannot be renamed (the target is a non-empty directory):
// the error names the path and the temporary is cleaned up.
TEST(VtkOutputErrors, FailedRenameRemovesTmp) {
  const Model model = cube_model(ElementType::Tet10);
  const Assembler assembler(model);
  const StateFields f = compute_fields(assembler, homogeneous_u(model.mesh, kStretch), tagged_state(assembler));
  const TempDir dir;
  const fs::path file = dir.path / "out.vtu";
  fs::create_directories(file / "occupied");
  try {
    write_vtu(file.string(), model, f, 0.0, 0, 0.0, 0.0);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& err) {
    EXPECT_NE(std::string(err.what()).find(file.string()), std::string::npos) << err.what();
  }
  EXPECT_FALSE(fs::exists(file.string() + ".tmp"));
  EXPECT_TRUE(fs::is_directory(file / "occupied"));

  PvdSeries series((dir.path / "out.vtu").string());
  EXPECT_THROW(series.add(0.0, "a.vtu"), std::runtime_error);
  EXPECT_FALSE(fs::exists(file.string() + ".tmp"));
}

// VTK itself fails to open the temporary (a directory is in the way): its error event is
// turned into the exception instead of being printed.
TEST(VtkOutputErrors, VtkOpenFailureIsReported) {
  const Model model = cube_model(ElementType::Tet4);
  const Assembler assembler(model);
  const StateFields f = compute_fields(assembler, homogeneous_u(model.mesh, kStretch), tagged_state(assembler));
  const TempDir dir;
  const fs::path file = dir.path / "out.vtu";
  fs::create_directories(dir.path / "out.vtu.tmp" / "occupied");
  try {
    write_vtu(file.string(), model, f, 0.0, 0, 0.0, 0.0);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& err) {
    const std::string msg = err.what();
    EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
    EXPECT_NE(msg.find("Error opening output file"), std::string::npos) << msg;  // VTK's own words
  }
  EXPECT_FALSE(fs::exists(file));
}

TEST(PvdSeries, WritesCollectionAfterEachAdd) {
  const TempDir dir;
  const fs::path pvd = dir.path / "run.pvd";
  PvdSeries series(pvd.string());
  EXPECT_EQ(series.path(), pvd.string());
  series.add(0.0, "run_0000.vtu");
  EXPECT_NE(read_text(pvd).find("file=\"run_0000.vtu\""), std::string::npos);
  series.add(1.0 / 3.0, (dir.path / "frames" / "run&0001.vtu").string());  // absolute -> relative
  EXPECT_FALSE(fs::exists(pvd.string() + ".tmp"));

  const std::string expected =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "  <Collection>\n"
      "    <DataSet timestep=\"0\" part=\"0\" file=\"run_0000.vtu\"/>\n"
      "    <DataSet timestep=\"0.3333333333333333\" part=\"0\" file=\"frames/run&amp;0001.vtu\"/>\n"
      "  </Collection>\n"
      "</VTKFile>\n";
  EXPECT_EQ(read_text(pvd), expected);

  // Well-formed XML whose time reads back exactly (full precision).
  vtkNew<vtkXMLDataParser> parser;
  parser->SetFileName(pvd.c_str());
  ASSERT_EQ(parser->Parse(), 1);
  vtkXMLDataElement* collection = parser->GetRootElement()->GetNestedElement(0);
  ASSERT_EQ(collection->GetNumberOfNestedElements(), 2);
  EXPECT_EQ(std::stod(collection->GetNestedElement(1)->GetAttribute("timestep")), 1.0 / 3.0);
  EXPECT_STREQ(collection->GetNestedElement(1)->GetAttribute("file"), "frames/run&0001.vtu");
}

// XML 1.0 cannot hold a control character, escaped or not (dropping it would name another file):
// such a name is refused and the index stays as it was.
TEST(PvdSeries, RefusesAFileNameXmlCannotHold) {
  const TempDir dir;
  const fs::path pvd = dir.path / "run.pvd";
  PvdSeries series(pvd.string());
  series.add(0.0, "a<b>&'c'.vtu");
  const std::string before = read_text(pvd);
  EXPECT_NE(before.find("file=\"a&lt;b&gt;&amp;&apos;c&apos;.vtu\""), std::string::npos) << before;
  EXPECT_THROW(series.add(1.0, std::string("state\x01.vtu")), std::invalid_argument);
  EXPECT_EQ(read_text(pvd), before);
  vtkNew<vtkXMLDataParser> parser;
  parser->SetFileName(pvd.c_str());
  ASSERT_EQ(parser->Parse(), 1);
  EXPECT_STREQ(parser->GetRootElement()->GetNestedElement(0)->GetNestedElement(0)->GetAttribute("file"), "a<b>&'c'.vtu");
}

TEST(PvdSeries, MissingDirectoryThrows) {
  const TempDir dir;
  const fs::path pvd = dir.path / "missing" / "run.pvd";
  PvdSeries series(pvd.string());
  try {
    series.add(0.0, "a.vtu");
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& err) {
    EXPECT_NE(std::string(err.what()).find(pvd.string()), std::string::npos) << err.what();
  }
  EXPECT_THROW(series.add(std::nan(""), "a.vtu"), std::invalid_argument);
}

}  // namespace
}  // namespace pneufem

#include "viz/vtk_output.h"

#include <array>
#include <atomic>
#include <charconv>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include <Eigen/Eigenvalues>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <vtkCallbackCommand.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkErrorCode.h>
#include <vtkExecutive.h>
#include <vtkFieldData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkStringArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include "core/errors.h"
#include "engine/static_solver.h"
#include "viz/xml_escape.h"

namespace pneufem {

namespace fs = std::filesystem;

namespace {

/// Von Mises equivalent stress sqrt(3/2 s:s), s = sigma - tr(sigma)/3 I (Pa).
double von_mises(const Mat3& sigma) {
  const Mat3 s = sigma - (sigma.trace() / 3.0) * Mat3::Identity();
  return std::sqrt(1.5 * s.squaredNorm());
}

/// Largest principal stretch: square root of the largest eigenvalue of C = F^T F.
double max_principal_stretch(const Mat3& F) {
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(F.transpose() * F, Eigen::EigenvaluesOnly);
  return std::sqrt(eig.eigenvalues()(2));  // eigenvalues are sorted ascending
}

/// Writes through `write(tmp)` with tmp = path + ".tmp", then renames tmp onto `path` (atomic on
/// POSIX within one file system, so readers never see a half-written file). On any failure the
/// temporary file is removed and std::runtime_error names `path` and the reason.
void write_atomically(const std::string& path, const std::function<void(const std::string&)>& write) {
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw std::runtime_error("cannot write '" + path + "': directory '" + dir.string() +
                             "' does not exist (create it or choose another output directory)");
  const std::string tmp = path + ".tmp";
  try {
    write(tmp);
    fs::rename(tmp, target, ec);
    if (ec) throw std::runtime_error("renaming '" + tmp + "' onto it failed: " + ec.message());
  } catch (const std::runtime_error& ex) {
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot write '" + path + "': " + ex.what());
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
}

/// Writes `grid` to `file` as XML, appended raw binary, zlib-compressed. VTK reports failures
/// through its error events (not exceptions); they are captured here and thrown.
void write_grid(vtkUnstructuredGrid* grid, const std::string& file) {
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  std::string errors;
  vtkNew<vtkCallbackCommand> on_error;
  on_error->SetClientData(&errors);
  on_error->SetCallback([](vtkObject*, unsigned long, void* client, void* call) {
    auto& out = *static_cast<std::string*>(client);
    std::string msg = call ? static_cast<const char*>(call) : "";
    if (const auto p = msg.find("): "); p != std::string::npos) msg.erase(0, p + 3);  // "Class (0x..): "
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
    out += (out.empty() ? "" : "; ") + msg;
  });
  writer->AddObserver(vtkCommand::ErrorEvent, on_error);
  // The pipeline then repeats the failure as a long request dump; the writer's own message
  // above already says what went wrong, so the executive's is swallowed.
  vtkNew<vtkCallbackCommand> ignore;
  ignore->SetCallback([](vtkObject*, unsigned long, void*, void*) {});
  writer->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, ignore);
  writer->SetFileName(file.c_str());
  writer->SetInputData(grid);
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();  // raw binary, not base64
  writer->SetCompressorTypeToZLib();
  writer->SetHeaderTypeToUInt64();
  const int ok = writer->Write();
  const unsigned long code = writer->GetErrorCode();
  if (ok && code == vtkErrorCode::NoError && errors.empty()) return;
  if (!errors.empty()) throw std::runtime_error(errors);  // VTK's message names the file and errno text
  // Codes below FirstVTKErrorCode are errno values. (vtkErrorCode::GetStringFromErrorCode lives
  // in VTK::CommonMisc, which is not linked, so the VTK codes that matter are spelled out.)
  std::string reason = "VTK writer failed (error code " + std::to_string(code) + ")";
  if (code > 0 && code < vtkErrorCode::FirstVTKErrorCode) reason = std::strerror(static_cast<int>(code));
  if (code == vtkErrorCode::CannotOpenFileError) reason = "cannot open the file (is the directory writable?)";
  if (code == vtkErrorCode::OutOfDiskSpaceError) reason = "out of disk space";
  throw std::runtime_error(reason);
}

vtkNew<vtkDoubleArray> double_array(const char* name, int components, vtkIdType tuples) {
  vtkNew<vtkDoubleArray> a;
  a->SetName(name);
  a->SetNumberOfComponents(components);
  a->SetNumberOfTuples(tuples);
  return a;
}

void add_cell_scalars(vtkUnstructuredGrid* grid, const char* name, const std::vector<double>& values) {
  auto a = double_array(name, 1, static_cast<vtkIdType>(values.size()));
  for (std::size_t i = 0; i < values.size(); ++i) a->SetValue(static_cast<vtkIdType>(i), values[i]);
  grid->GetCellData()->AddArray(a);
}

/// The stiff layer (the fabric): elements whose material is stiffer in shear than the softest by the
/// ratio the static solver's stiff-layer elimination uses (StaticOptions::stiff_modulus_ratio).
std::vector<char> stiff_layer(const Model& model) {
  const int ne = model.mesh.num_elements();
  double mu_min = std::numeric_limits<double>::infinity();
  for (int e = 0; e < ne; ++e) mu_min = std::min(mu_min, model.material_of(e).initial_shear_modulus());
  const double ratio = StaticOptions{}.stiff_modulus_ratio;
  std::vector<char> stiff(static_cast<std::size_t>(ne), 0);
  for (int e = 0; e < ne; ++e) stiff[e] = model.material_of(e).initial_shear_modulus() > ratio * mu_min;
  return stiff;
}

/// `values` where `keep[e]`, NaN elsewhere (ParaView leaves NaN out of the colour range).
std::vector<double> only(const std::vector<double>& values, const std::vector<char>& keep, bool want) {
  std::vector<double> out(values.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t e = 0; e < values.size(); ++e)
    if (static_cast<bool>(keep[e]) == want) out[e] = values[e];
  return out;
}

/// Point values from element values: at each node the mean over the elements around it with
/// stiff[e] == `want` (NaN at a node with none), so the two layers are never averaged together.
/// `per_element` holds `components` values per element.
std::vector<double> to_points(const Mesh& mesh, const std::vector<double>& per_element, int components,
                              const std::vector<char>& stiff, bool want) {
  const auto nc = static_cast<std::size_t>(components);
  std::vector<double> sum(static_cast<std::size_t>(mesh.num_nodes()) * nc, 0.0);
  std::vector<int> count(static_cast<std::size_t>(mesh.num_nodes()), 0);
  for (int e = 0; e < mesh.num_elements(); ++e) {
    if (static_cast<bool>(stiff[e]) != want) continue;
    for (int a = 0; a < mesh.npe(); ++a) {
      const auto n = static_cast<std::size_t>(mesh.element(e)[a]);
      ++count[n];
      for (std::size_t c = 0; c < nc; ++c) sum[n * nc + c] += per_element[static_cast<std::size_t>(e) * nc + c];
    }
  }
  for (std::size_t n = 0; n < count.size(); ++n)
    for (std::size_t c = 0; c < nc; ++c)
      sum[n * nc + c] = count[n] > 0 ? sum[n * nc + c] / count[n] : std::numeric_limits<double>::quiet_NaN();
  return sum;
}

vtkNew<vtkDoubleArray> tensor_array(const char* name, const std::vector<double>& rows9) {
  // Row-major components XX XY XZ YX ... (ParaView's convention for 9-component tensors).
  static constexpr const char* kComp[9] = {"XX", "XY", "XZ", "YX", "YY", "YZ", "ZX", "ZY", "ZZ"};
  auto a = double_array(name, 9, static_cast<vtkIdType>(rows9.size() / 9));
  for (int c = 0; c < 9; ++c) a->SetComponentName(c, kComp[c]);
  for (std::size_t i = 0; i < rows9.size(); ++i) a->SetValue(static_cast<vtkIdType>(i), rows9[i]);
  return a;
}

void add_point_scalars(vtkUnstructuredGrid* grid, const char* name, const std::vector<double>& values) {
  auto a = double_array(name, 1, static_cast<vtkIdType>(values.size()));
  for (std::size_t i = 0; i < values.size(); ++i) a->SetValue(static_cast<vtkIdType>(i), values[i]);
  grid->GetPointData()->AddArray(a);
}

void add_field_scalar(vtkFieldData* fd, const char* name, double value) {
  auto a = double_array(name, 1, 1);
  a->SetValue(0, value);
  fd->AddArray(a);
}

void add_field_strings(vtkFieldData* fd, const char* name, const std::vector<std::string>& values) {
  vtkNew<vtkStringArray> a;
  a->SetName(name);
  a->SetNumberOfValues(static_cast<vtkIdType>(values.size()));
  for (std::size_t i = 0; i < values.size(); ++i) a->SetValue(static_cast<vtkIdType>(i), values[i]);
  fd->AddArray(a);
}

/// Shortest decimal text that reads back to exactly `v` (std::to_chars round-trip guarantee).
std::string exact_decimal(double v) {
  std::array<char, 32> buf{};
  const auto res = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return std::string(buf.data(), res.ptr);
}

void write_text(const std::string& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot open '" + file + "' for writing: " + std::strerror(errno));
  out << text;
  out.close();
  if (!out) throw std::runtime_error("write error on '" + file + "' (disk full?)");
}

}  // namespace

StateFields compute_fields(const Assembler& assembler, const Eigen::VectorXd& u, const std::vector<double>& state) {
  const Model& model = assembler.model();
  const Mesh& mesh = model.mesh;
  const int nn = mesh.num_nodes(), ne = mesh.num_elements();
  if (u.size() != model.num_dofs() || state.size() != assembler.state_size())
    throw std::invalid_argument("compute_fields: u has " + std::to_string(u.size()) + " entries (expected " +
                                std::to_string(model.num_dofs()) + "), state has " + std::to_string(state.size()) +
                                " (expected " + std::to_string(assembler.state_size()) + ")");

  StateFields f;
  f.displacement_m.resize(nn);
  for (int i = 0; i < nn; ++i) f.displacement_m[i] = u.segment<3>(3 * i);
  f.cauchy_Pa.resize(ne);
  for (auto* v : {&f.von_mises_Pa, &f.max_principal_stretch, &f.energy_density_J_m3, &f.damage, &f.W_max_J_m3,
                  &f.viscous_strain})
    v->resize(ne);

  // Element means (1/V) int x dV, by the element's own quadrature (weights w det J, sum V). The
  // scalars are means of the point values (e.g. mean of the points' von Mises), not functions
  // of the mean tensor: peaks inside an element are smoothed less.
  const ElementGeometry& geom = assembler.geometry();
  const int nqp = geom.nqp;
  std::atomic<int> first_inverted{INT_MAX};
  tbb::parallel_for(tbb::blocked_range<int>(0, ne), [&](const tbb::blocked_range<int>& range) {
    std::vector<Mat3> F(nqp);
    std::vector<PointResponse> resp(nqp);
    for (int e = range.begin(); e < range.end(); ++e) {
      const std::span<const double> se = assembler.element_state(state, e);
      assembler.point_responses(u, e, se, F, resp);
      const Material& mat = model.material_of(e);
      const std::size_t ss = static_cast<std::size_t>(mat.state_size());
      double V = 0.0, vm = 0.0, stretch = 0.0, psi = 0.0, damage = 0.0, W_max = 0.0, visc = 0.0;
      Mat3 sigma = Mat3::Zero();
      for (int q = 0; q < nqp; ++q) {
        const double J = F[q].determinant();
        if (!(J > 0.0)) {
          int cur = first_inverted.load();
          while (e < cur && !first_inverted.compare_exchange_weak(cur, e)) {
          }
          break;
        }
        const double w = geom.w(e, q);
        const Mat3 sigma_q = resp[q].P() * F[q].transpose() / J;  // sigma = P F^T / J
        const PointFields pf = mat.fields(se.subspan(q * ss, ss));
        V += w;
        sigma += w * sigma_q;
        vm += w * von_mises(sigma_q);
        stretch += w * max_principal_stretch(F[q]);
        psi += w * resp[q].psi();
        damage += w * pf.damage;
        W_max += w * pf.W_max;
        visc += w * pf.viscous_strain;
      }
      f.cauchy_Pa[e] = sigma / V;
      f.von_mises_Pa[e] = vm / V;
      f.max_principal_stretch[e] = stretch / V;
      f.energy_density_J_m3[e] = psi / V;
      f.damage[e] = damage / V;
      f.W_max_J_m3[e] = W_max / V;
      f.viscous_strain[e] = visc / V;
    }
  });
  if (const int e = first_inverted.load(); e != INT_MAX) {
    throw PhysicsError("output: " + mesh.element_label(e) +
                           " is inverted (det F <= 0) in the state to be written; the state was not a valid "
                           "equilibrium (check the solver's convergence for this step)",
                       e);
  }
  return f;
}

void write_vtu(const std::string& path, const Model& model, const StateFields& fields, double time_s, int trial,
               double pressure_kPa, double angle_deg) {
  const Mesh& mesh = model.mesh;
  const int nn = mesh.num_nodes(), ne = mesh.num_elements(), npe = mesh.npe();
  const auto sne = static_cast<std::size_t>(ne);
  for (const std::vector<double>* v : {&fields.von_mises_Pa, &fields.max_principal_stretch,
                                       &fields.energy_density_J_m3, &fields.damage, &fields.W_max_J_m3,
                                       &fields.viscous_strain})
    if (v->size() != sne)
      throw std::invalid_argument("write_vtu('" + path + "'): a cell field does not have one value per element");
  if (fields.displacement_m.size() != static_cast<std::size_t>(nn) || fields.cauchy_Pa.size() != sne ||
      model.element_part.size() != sne)
    throw std::invalid_argument("write_vtu('" + path + "'): fields do not match the model (nodes/elements)");

  vtkNew<vtkUnstructuredGrid> grid;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(nn);
  for (int i = 0; i < nn; ++i) points->SetPoint(i, mesh.X[i].data());
  grid->SetPoints(points);

  // The Abaqus Tet10 order (mesh.h) is also VTK's: corners, then mid-edges (0,1) (1,2) (2,0)
  // (0,3) (1,3) (2,3) (vtkQuadraticTetra.h), so the connectivity is copied unchanged.
  const int cell_type = mesh.type == ElementType::Tet4 ? VTK_TETRA : VTK_QUADRATIC_TETRA;
  grid->Allocate(ne);
  std::array<vtkIdType, 10> ids{};
  for (int e = 0; e < ne; ++e) {
    const int* n = mesh.element(e);
    for (int a = 0; a < npe; ++a) ids[a] = n[a];
    grid->InsertNextCell(cell_type, npe, ids.data());
  }

  auto u = double_array("displacement_m", 3, nn);
  for (int i = 0; i < nn; ++i) u->SetTypedTuple(i, fields.displacement_m[i].data());
  grid->GetPointData()->AddArray(u);
  grid->GetPointData()->SetActiveVectors("displacement_m");

  // Stress. The fabric is ~1000x stiffer than the silicone (19 MPa against 0.1 MPa at 45 kPa), so
  // one colour range over both shows the silicone as one colour: von Mises is split into the soft
  // material (von_mises_Pa) and the stiff layer (fabric_von_mises_Pa), NaN in the other, as cell
  // data and as point data (nodal means over each layer's own elements, never across the two).
  const std::vector<char> stiff = stiff_layer(model);
  const bool has_stiff = std::find(stiff.begin(), stiff.end(), 1) != stiff.end();
  std::vector<double> sigma9(9 * sne);
  for (std::size_t e = 0; e < sne; ++e)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) sigma9[9 * e + 3 * i + j] = fields.cauchy_Pa[e](i, j);
  grid->GetCellData()->AddArray(tensor_array("cauchy_stress_Pa", sigma9));
  grid->GetPointData()->AddArray(tensor_array("cauchy_stress_Pa", to_points(mesh, sigma9, 9, stiff, false)));
  add_cell_scalars(grid, "von_mises_Pa", only(fields.von_mises_Pa, stiff, false));
  add_point_scalars(grid, "von_mises_Pa", to_points(mesh, fields.von_mises_Pa, 1, stiff, false));
  if (has_stiff) {
    add_cell_scalars(grid, "fabric_von_mises_Pa", only(fields.von_mises_Pa, stiff, true));
    add_point_scalars(grid, "fabric_von_mises_Pa", to_points(mesh, fields.von_mises_Pa, 1, stiff, true));
  }
  add_cell_scalars(grid, "max_principal_stretch", fields.max_principal_stretch);
  add_cell_scalars(grid, "strain_energy_density_J_m3", fields.energy_density_J_m3);
  add_cell_scalars(grid, "damage", fields.damage);
  add_cell_scalars(grid, "W_max_J_m3", fields.W_max_J_m3);
  add_cell_scalars(grid, "viscous_strain", fields.viscous_strain);

  // region_id indexes the field data "region_names" (-1 when the mesh carries no regions);
  // material_id indexes "material_names" (the model's parts).
  vtkNew<vtkIntArray> region, material;
  region->SetName("region_id");
  material->SetName("material_id");
  region->SetNumberOfValues(ne);
  material->SetNumberOfValues(ne);
  const bool has_regions = mesh.region.size() == sne;
  for (int e = 0; e < ne; ++e) {
    region->SetValue(e, has_regions ? static_cast<int>(mesh.region[e]) : -1);
    material->SetValue(e, model.element_part[e]);
  }
  grid->GetCellData()->AddArray(region);
  grid->GetCellData()->AddArray(material);

  vtkFieldData* fd = grid->GetFieldData();
  add_field_scalar(fd, "time_s", time_s);
  vtkNew<vtkIntArray> trial_array;
  trial_array->SetName("trial");
  trial_array->InsertNextValue(trial);
  fd->AddArray(trial_array);
  add_field_scalar(fd, "pressure_kPa", pressure_kPa);
  add_field_scalar(fd, "angle_deg", angle_deg);
  add_field_strings(fd, "region_names", mesh.region_names);
  std::vector<std::string> part_names;
  for (const Part& p : model.parts) part_names.push_back(p.name);
  add_field_strings(fd, "material_names", part_names);

  write_atomically(path, [&](const std::string& tmp) { write_grid(grid, tmp); });
}

PvdSeries::PvdSeries(std::string pvd_path) : path_(std::move(pvd_path)) {}

void PvdSeries::add(double time_s, const std::string& vtu_file_relative) {
  if (!std::isfinite(time_s)) throw std::invalid_argument("PvdSeries::add: time_s must be finite");
  // XML 1.0 cannot hold a control character, escaped or not: dropped, the index would name another file.
  if (has_xml_forbidden_char(vtu_file_relative))
    throw std::invalid_argument("PvdSeries::add: the file name '" + xml_escape(vtu_file_relative) +
                                "' holds a control character, which a .pvd (XML) cannot name");
  // ParaView resolves "file" against the .pvd's directory; an absolute path is made relative to it.
  fs::path file(vtu_file_relative);
  if (file.is_absolute()) {
    const fs::path rel = file.lexically_relative(fs::absolute(fs::path(path_)).parent_path());
    if (!rel.empty()) file = rel;
  }
  entries_.emplace_back(time_s, file.generic_string());
  try {
    flush();
  } catch (...) {
    entries_.pop_back();  // strong guarantee: the series is unchanged when the write fails
    throw;
  }
}

void PvdSeries::flush() const {
  std::ostringstream xml;
  xml << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <Collection>\n";
  for (const auto& [t, file] : entries_)
    xml << "    <DataSet timestep=\"" << exact_decimal(t) << "\" part=\"0\" file=\"" << xml_escape(file) << "\"/>\n";
  xml << "  </Collection>\n"
      << "</VTKFile>\n";
  const std::string text = xml.str();
  write_atomically(path_, [&](const std::string& tmp) { write_text(tmp, text); });
}

}  // namespace pneufem

// Fuzz target: the Abaqus/CalculiX deck reader (scenes/inp/deck.h). read_inp reads files (and
// resolves *INCLUDE from the deck's directory), so each input is written to deck.inp in a private
// temporary directory made once per process; an *INCLUDE of a name the fuzzer invents then fails
// as a missing file, and INPUT=deck.inp as a cycle. InputError is the documented answer to bad
// input; anything else is a finding, and so is a deck read without error that names nodes,
// elements or faces that do not exist, or that does not read back the same after write_inp_mesh.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "core/errors.h"
#include "fuzz/report.h"
#include "scenes/inp/deck.h"

namespace {

const std::string& deck_path() {
  static const std::string path = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::string dir = std::string(tmp && *tmp ? tmp : "/tmp") + "/pneufem_fuzz_inp_XXXXXX";
    if (!mkdtemp(dir.data())) std::abort();
    return dir + "/deck.inp";
  }();
  return path;
}

/// A deck read without error is a mesh the engine can index: every node, element, face and dof
/// that the mesh, its sets, surfaces, pressure faces and fixed dofs name exists, and every
/// coordinate is finite. Else abort: a finding (a silent wrong the engine would meet later).
void check(const pneufem::InpDeck& deck) {
  const pneufem::Mesh& m = deck.mesh;
  const int n = m.num_nodes(), ne = m.num_elements();
  auto require = [](bool ok) {
    if (!ok) std::abort();
  };
  require(m.conn.size() == static_cast<std::size_t>(ne) * static_cast<std::size_t>(m.npe()));
  require(m.region.size() == static_cast<std::size_t>(ne));
  for (const Eigen::Vector3d& x : m.X) require(x.allFinite());
  for (int v : m.conn) require(v >= 0 && v < n);
  for (std::uint16_t r : m.region) require(r < m.region_names.size());
  for (const auto& [name, members] : m.node_sets)
    for (int v : members) require(v >= 0 && v < n);
  for (const auto& [name, members] : m.element_sets)
    for (int e : members) require(e >= 0 && e < ne);
  auto face_ok = [&](const pneufem::FaceRef& f) {
    return f.element >= 0 && f.element < ne && f.local_face >= 0 && f.local_face < 4;
  };
  for (const auto& [name, faces] : m.surfaces)
    for (const pneufem::FaceRef& f : faces) require(face_ok(f));
  for (const pneufem::InpPressure& p : deck.pressure_faces) require(face_ok(p.face) && std::isfinite(p.magnitude));
  for (const auto& [node, dof] : deck.fixed_dofs) require(node >= 0 && node < n && dof >= 0 && dof < 3);
}

/// write_inp_mesh promises that read_inp returns the same mesh (deck.h): same nodes and elements in
/// the same order, coordinates to the 14 digits the writer keeps at least. A name the writer
/// cannot hold is its documented InputError.
void check_round_trip(const pneufem::InpDeck& deck, const std::string& path) {
  std::ostringstream os;
  try {
    pneufem::write_inp_mesh(os, deck.mesh, 1e-3);
  } catch (const pneufem::InputError&) {
    return;
  }
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << os.str();
    if (!out) std::abort();
  }
  const pneufem::Mesh& a = deck.mesh;
  const pneufem::Mesh b = pneufem::read_inp(path, 1e-3).mesh;  // an InputError here is a finding
  if (a.type != b.type || a.conn != b.conn || a.X.size() != b.X.size()) std::abort();
  double scale = 0.0;
  for (const Eigen::Vector3d& x : a.X) scale = std::max(scale, x.cwiseAbs().maxCoeff());
  for (std::size_t i = 0; i < a.X.size(); ++i)
    if (((a.X[i] - b.X[i]).cwiseAbs().array() > 1e-12 * (a.X[i].cwiseAbs().array() + scale)).any()) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& path = deck_path();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) std::abort();
  }
  pneufem::InpDeck deck;
  try {
    deck = pneufem::read_inp(path, 1e-3);
  } catch (const pneufem::InputError& e) {
    pneufem::fuzz::report("error", e.what());
    return 0;
  }
  check(deck);
  check_round_trip(deck, path);
  pneufem::fuzz::report("accepted");
  return 0;
}

// Fuzz target: the Abaqus/CalculiX deck reader (scenes/inp/deck.h). read_inp reads files (and
// resolves *INCLUDE from the deck's directory), so each input is written to deck.inp in a private
// temporary directory made once per process; an *INCLUDE of a name the fuzzer invents then fails
// as a missing file, and INPUT=deck.inp as a cycle. InputError is the documented answer to bad
// input; anything else is a finding, and so is a deck read without error whose elements name
// nodes that do not exist.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>

#include "core/errors.h"
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

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& path = deck_path();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) std::abort();
  }
  try {
    check(pneufem::read_inp(path, 1e-3));
  } catch (const pneufem::InputError&) {
  }
  return 0;
}

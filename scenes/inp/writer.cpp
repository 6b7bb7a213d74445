// Writing a mesh as an Abaqus/CalculiX deck: write_inp_mesh (scenes/inp/deck.h).
#include "scenes/inp/deck.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <map>

#include "core/errors.h"
#include "core/message_text.h"
#include "scenes/inp/text.h"

namespace pneufem {

namespace {

using inp::is_blank;
using inp::upper;

// CalculiX reads each real from the first 20 characters of its field (Fortran f20.0, nodes.f),
// so a coordinate must fit in 20 characters.
constexpr std::size_t kMaxRealChars = 20;
constexpr std::size_t kMaxEntriesPerLine = 16;
constexpr std::size_t kMaxNameChars = 80;  // CalculiX set-name limit

/// Shortest text that reads back to exactly `v` (std::to_chars), if it fits in 20 characters;
/// otherwise the most significant digits that fit (>= 14, i.e. relative error < 1e-13, and
/// only for values whose magnitude is far below the model size).
std::string format_real(double v) {
  std::array<char, 64> buf{};
  auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  std::size_t n = static_cast<std::size_t>(r.ptr - buf.data());
  for (int digits = 17; n > kMaxRealChars && digits > 0; --digits) {
    r = std::to_chars(buf.data(), buf.data() + buf.size(), v, std::chars_format::general, digits);
    n = static_cast<std::size_t>(r.ptr - buf.data());
  }
  return std::string(buf.data(), n);
}

/// Upper-case deck name of a set, surface or region; names the reader would misread are refused.
std::string deck_name(const std::string& name, const char* what) {
  const std::string u = upper(name);
  const bool letter_first = !u.empty() && u[0] >= 'A' && u[0] <= 'Z';
  const bool bad_char = std::any_of(u.begin(), u.end(), [](char c) {
    return c == ',' || c == '=' || c == '*' || c == '"' || c == '\n' || is_blank(c);
  });
  if (!letter_first || u.size() > kMaxNameChars || bad_char)
    throw InputError(printable(std::string(what) + " name '" + name + "' cannot be written to an .inp deck; rename it (1-80 " +
                     "characters starting with a letter, no blanks, commas, '=', '*' or quotes)"));
  return u;
}

/// Set members, at most 16 per data line.
void write_id_lines(std::ostream& os, const std::vector<long>& ids) {
  for (std::size_t i = 0; i < ids.size(); ++i)
    os << ids[i] << ((i + 1) % kMaxEntriesPerLine == 0 || i + 1 == ids.size() ? "\n" : ", ");
}

}  // namespace

std::string inp_real_text(double v) { return format_real(v); }

void write_inp_mesh(std::ostream& os, const Mesh& mesh, double length_to_m) {
  if (!(length_to_m > 0.0) || !std::isfinite(length_to_m))
    throw InputError(printable("write_inp_mesh: length_to_m = " + std::to_string(length_to_m) +
                     " is not a positive length; give the deck's length unit in metres (1e-3 for mm)"));
  const auto nn = static_cast<std::size_t>(mesh.num_nodes());
  const auto ne = static_cast<std::size_t>(mesh.num_elements());
  auto node_id = [&](int i) {
    return mesh.node_ids.size() == nn ? mesh.node_ids[static_cast<std::size_t>(i)] : i + 1L;
  };
  auto element_id = [&](int e) {
    return mesh.element_ids.size() == ne ? mesh.element_ids[static_cast<std::size_t>(e)] : e + 1L;
  };
  auto region_name = [&](int e) -> const std::string& {
    static const std::string kDefault = "default";  // as Mesh::ensure_ids
    if (mesh.region.size() != ne) return kDefault;
    const std::size_t r = mesh.region[static_cast<std::size_t>(e)];
    return r < mesh.region_names.size() ? mesh.region_names[r] : kDefault;
  };
  const char* type = mesh.type == ElementType::Tet4 ? "C3D4" : "C3D10";

  os << "** pneufem mesh: " << nn << " nodes, " << ne << " " << type << " elements; lengths in units of "
     << format_real(length_to_m) << " m\n";

  os << "*NODE\n";
  for (std::size_t i = 0; i < nn; ++i) {
    const Eigen::Vector3d& x = mesh.X[i];
    if (!x.allFinite())
      throw InputError(printable("write_inp_mesh: node " + std::to_string(node_id(static_cast<int>(i))) +
                       " has a non-finite coordinate; fix the mesh before writing it"));
    os << node_id(static_cast<int>(i)) << ", " << format_real(x[0] / length_to_m) << ", "
       << format_real(x[1] / length_to_m) << ", " << format_real(x[2] / length_to_m) << '\n';
  }

  // Consecutive runs of one region, so the element order (and hence every index) survives a
  // round trip; CalculiX and Abaqus add repeated ELSET= blocks to the same set.
  const int npe = mesh.npe();
  std::map<std::string, std::vector<int>> region_elements;  // upper-case region -> elements
  for (std::size_t e = 0; e < ne;) {
    const std::string& region = region_name(static_cast<int>(e));
    const std::string elset = deck_name(region, "region");
    os << "*ELEMENT, TYPE=" << type << ", ELSET=" << elset << '\n';
    std::vector<int>& members = region_elements[elset];
    for (; e < ne && region_name(static_cast<int>(e)) == region; ++e) {
      members.push_back(static_cast<int>(e));
      const int* n = mesh.element(static_cast<int>(e));
      os << element_id(static_cast<int>(e));
      // C3D10: 8 nodes, then a trailing comma and the last 2 on a continuation line, as in our
      // CalculiX reference decks (<= 16 entries and far below 132 characters per line).
      for (int k = 0; k < npe; ++k) os << (k == 8 ? ",\n" : ", ") << node_id(n[k]);
      os << '\n';
    }
  }

  for (const auto& [name, nodes] : mesh.node_sets) {
    os << "*NSET, NSET=" << deck_name(name, "node set") << '\n';
    std::vector<long> ids;
    ids.reserve(nodes.size());
    for (int i : nodes) ids.push_back(node_id(i));
    write_id_lines(os, ids);
  }
  for (const auto& [name, elements] : mesh.element_sets) {
    const std::string elset = deck_name(name, "element set");
    const auto it = region_elements.find(elset);
    if (it != region_elements.end() && it->second == elements) continue;  // already the region's ELSET=
    os << "*ELSET, ELSET=" << elset << '\n';
    std::vector<long> ids;
    ids.reserve(elements.size());
    for (int e : elements) ids.push_back(element_id(e));
    write_id_lines(os, ids);
  }
  for (const auto& [name, faces] : mesh.surfaces) {
    os << "*SURFACE, NAME=" << deck_name(name, "surface") << ", TYPE=ELEMENT\n";
    for (const FaceRef& f : faces) os << element_id(f.element) << ", S" << f.local_face + 1 << '\n';
  }
}

}  // namespace pneufem

// Surfaces, loads and boundary conditions in a deck (reader.h): *SURFACE (element faces, or
// other surfaces), *DLOAD face pressures Pn, *DSLOAD surface pressures P, *BOUNDARY dofs.
#include <algorithm>
#include <sstream>

#include "scenes/inp/reader.h"

namespace pneufem::inp {

// ---- *SURFACE -----------------------------------------------------------------------------
void DeckReader::begin_surface(const Keyword& kw, const Loc& loc) {
  const std::string name = upper(kw.get("NAME"));
  if (name.empty()) fail(loc, "*SURFACE without NAME=", "add NAME=<surface name>");
  const std::string type = upper(kw.get("TYPE"));
  if (!type.empty() && type != "ELEMENT") {
    deck_.warnings.push_back(at(loc) + "*SURFACE " + name + " of TYPE=" + type +
                             " skipped (only element-face surfaces are read)");
    return;  // stays Block::Skip
  }
  block_ = Block::Surface;
  surface_ = name;
  scope().surfaces[surface_];
  if (kw.has("INTERNAL")) scope().internal_surfaces.insert(name);
}

/// "elset_or_element, Sn" (CAE: "_Surf-1_S3, S3", the internal element set of the faces S3),
/// or a line naming another surface, whose faces are added (a surface made of others).
void DeckReader::surface_line(const Loc& loc) {
  if (fields_.size() < 2 || fields_[1].empty()) {
    if (const std::vector<FaceRef>* other =
            find_named(&Scope::surfaces, fields_[0], loc, "*SURFACE " + surface_, "surface")) {
      const std::vector<FaceRef> copy = *other;  // may be this surface
      std::vector<FaceRef>& faces = scope().surfaces[surface_];
      faces.insert(faces.end(), copy.begin(), copy.end());
      return;
    }
    fail(loc, "a *SURFACE data line needs a face label", "write 'element_or_elset, S1' (faces S1..S6)");
  }
  const std::string label = upper(fields_[1]);
  int face = -1;
  if (label.size() == 2 && label[0] == 'S' && label[1] >= '1' && label[1] <= '6') face = label[1] - '1';
  if (face < 0)
    fail(loc, "'" + std::string(fields_[1]) + "' is not an element face",
         "use S1..S4 (tetrahedra), S1..S5 (wedges, pyramids) or S1..S6 (hexahedra)");
  std::vector<FaceRef>& faces = scope().surfaces[surface_];
  for_elements(fields_[0], loc, "*SURFACE " + surface_, [&](int e) {
    check_face(e, face, label, loc);
    faces.push_back(FaceRef{e, face});
  });
}

/// Face `face` (0-based) named by `label` (S3, P3) must exist on element e.
void DeckReader::check_face(int e, int face, const std::string& label, const Loc& loc) const {
  const SolidType t = solids_.type[static_cast<std::size_t>(e)];
  const int faces = solid_faces(t);
  if (face >= faces)
    fail(loc,
         label + " names face " + std::to_string(face + 1) + " of element " + element_name(e) + ", a " +
             solid_name(t) + " with faces 1-" + std::to_string(faces),
         "use " + label.substr(0, 1) + "1.." + label.substr(0, 1) + std::to_string(faces) + " for that element");
}

// ---- *DLOAD -------------------------------------------------------------------------------
void DeckReader::dload_line(const Loc& loc) {
  if (fields_.size() < 2 || fields_[1].empty())
    fail(loc, "a *DLOAD data line needs a load label", "write 'element_or_elset, P1, magnitude'");
  const std::string label = upper(fields_[1]);
  const bool pressure = label.size() == 2 && label[0] == 'P' && label[1] >= '1' && label[1] <= '9';
  if (!pressure) {
    warn_once("dload " + label, loc, "*DLOAD load type " + label + " skipped (only face pressures P1..P6 are read)");
    return;
  }
  const int face = label[1] - '1';
  const std::optional<double> p = magnitude("*DLOAD", label, "element_or_elset", loc);
  for_elements(fields_[0], loc, "*DLOAD", [&](int e) {
    check_face(e, face, label, loc);
    add_pressure(FaceRef{e, face}, *p, label, loc);
  });
}

/// The magnitude field of a *DLOAD / *DSLOAD line.
std::optional<double> DeckReader::magnitude(const std::string& keyword, const std::string& label,
                                            const std::string& first, const Loc& loc) const {
  if (fields_.size() < 3 || fields_[2].empty())
    fail(loc, keyword + " " + label + " without a magnitude", "write '" + first + ", " + label + ", magnitude'");
  const std::optional<double> p = parse_double(fields_[2]);
  if (!p) fail(loc, keyword + " magnitude '" + std::string(fields_[2]) + "' is not a finite number", "fix the value");
  return p;
}

/// Each (element, face) once, the first magnitude kept (a differing repeat warns).
void DeckReader::add_pressure(const FaceRef& f, double p, const std::string& label, const Loc& loc) {
  const long long key = static_cast<long long>(f.element) * 8 + f.local_face;  // faces of solids: up to 6
  const auto [it, inserted] = load_index_.try_emplace(key, deck_.pressure_faces.size());
  if (inserted) {
    deck_.pressure_faces.push_back(InpPressure{f, p});
  } else if (deck_.pressure_faces[it->second].magnitude != p) {
    std::ostringstream msg;
    msg.precision(17);
    msg << "element " << element_name(f.element) << " face " << label << " loaded again with " << p
        << "; keeping the first magnitude " << deck_.pressure_faces[it->second].magnitude;
    deck_.warnings.push_back(at(loc) + msg.str());
  }
}

// ---- *DSLOAD ------------------------------------------------------------------------------
/// "surface, P, magnitude": how Abaqus/CAE writes a pressure load on a surface (the chamber
/// pressure of a pneu-net); its faces join the *DLOAD Pn faces.
void DeckReader::dsload_line(const Loc& loc) {
  if (fields_.size() < 2 || fields_[1].empty())
    fail(loc, "a *DSLOAD data line needs a load label", "write 'surface, P, magnitude'");
  const std::string label = upper(fields_[1]);
  if (label != "P") {
    warn_once("dsload " + label, loc, "*DSLOAD load type " + label + " skipped (only the pressure P is read)");
    return;
  }
  const std::optional<double> p = magnitude("*DSLOAD", label, "surface", loc);
  const std::vector<FaceRef>* faces = find_named(&Scope::surfaces, fields_[0], loc, "*DSLOAD", "surface");
  if (!faces) {
    const std::string name(fields_[0]);  // an lvalue: GCC 12 warns (-Wrestrict) on "literal" + std::string(view)
    fail(loc, "unknown surface '" + name + "' in *DSLOAD",
         "define it with *SURFACE, TYPE=ELEMENT, NAME=" + name + " before this line" +
             (instance_index_.empty() ? std::string() : " (an instance's surface is <instance>.<surface> here)"));
  }
  const std::vector<FaceRef> copy = *faces;
  for (const FaceRef& f : copy) {
    std::string face = "S";  // not "S" + std::to_string(...): a false -Wrestrict of GCC 12 here
    face += std::to_string(f.local_face + 1);
    add_pressure(f, *p, face, loc);
  }
}

// ---- *BOUNDARY ----------------------------------------------------------------------------
void DeckReader::boundary_line(const Loc& loc) {
  if (fields_.size() < 2 || fields_[1].empty())
    fail(loc, "a *BOUNDARY data line needs a degree of freedom",
         "write 'node_or_nset, first_dof[, last_dof[, value]]' or 'node_or_nset, ENCASTRE'");
  long first = 0, last = 0;
  if (const std::optional<long> d = parse_long(fields_[1])) {
    first = last = *d;
    if (fields_.size() > 2 && !fields_[2].empty()) {
      const std::optional<long> d2 = parse_long(fields_[2]);
      if (!d2)
        fail(loc, "last dof '" + std::string(fields_[2]) + "' is not an integer",
             "write 'node_or_nset, first_dof, last_dof'");
      last = *d2;
    }
    if (fields_.size() > 3 && !fields_[3].empty()) {
      const std::optional<double> value = parse_double(fields_[3]);
      if (!value)
        fail(loc, "*BOUNDARY value '" + std::string(fields_[3]) + "' is not a finite number", "fix the value");
      if (*value != 0.0)
        fail(loc, "*BOUNDARY value " + std::string(fields_[3]) + " is not zero",
             "only homogeneous conditions (fixed dofs, value 0) are supported: set the value to 0 or remove it");
    }
  } else {
    const std::string name = upper(fields_[1]);
    if (name == "ENCASTRE" || name == "PINNED") {
      first = 1;
      last = 3;
    } else if (name == "XSYMM" || name == "YSYMM" || name == "ZSYMM") {
      first = last = name[0] - 'X' + 1;
    } else {
      fail(loc, "boundary type '" + std::string(fields_[1]) + "' is not supported",
           "use dof numbers 1-3 or ENCASTRE, PINNED, XSYMM, YSYMM, ZSYMM");
    }
  }
  if (first < 1 || last < first)
    fail(loc, "dof range " + std::to_string(first) + "-" + std::to_string(last) + " is invalid",
         "give 1 <= first_dof <= last_dof (1-3 are the displacements)");
  if (last > 3)
    warn_once("boundary dofs", loc,
              "*BOUNDARY dofs above 3 ignored (solid elements have only the displacement dofs 1-3)");
  last = std::min(last, 3L);
  for_nodes(fields_[0], loc, "*BOUNDARY", [&](int n) {
    for (long d = first; d <= last; ++d) {
      const long long key = static_cast<long long>(n) * 3 + (d - 1);
      if (fixed_.insert(key).second) deck_.fixed_dofs.emplace_back(n, static_cast<int>(d - 1));
    }
  });
}

}  // namespace pneufem::inp

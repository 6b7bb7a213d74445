#pragma once
// The deck reader behind read_inp (scenes/inp/deck.h): one class, DeckReader, whose state is declared
// here and whose keyword handlers are defined in one file per group of keywords:
//   reader.cpp            the pass over the deck: keyword dispatch, *NODE, *ELEMENT (solids),
//                         the end of the deck (split into tetrahedra, checks), read_inp;
//   read_parts.cpp        *PART, *ASSEMBLY, *INSTANCE, and the id scopes they make;
//   read_sets.cpp         *NSET, *ELSET, and how a data line's ids and names are looked up;
//   read_loads.cpp        *SURFACE, *DLOAD, *DSLOAD, *BOUNDARY;
//   surface_elements.cpp  *ELEMENT blocks of surface elements (a mesher's named surfaces).
// Beside them: writer.cpp (write_inp_mesh), assembly.h (instance placement and names) and
// solid_split.h (hexahedra, wedges and pyramids into tetrahedra).
// The text layer (lines, *INCLUDE, fields, numbers) is scenes/inp/text.h. Internal to these files.
#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "core/errors.h"
#include "core/message_text.h"
#include "scenes/inp/assembly.h"
#include "scenes/inp/deck.h"
#include "scenes/inp/solid_split.h"
#include "scenes/inp/text.h"

namespace pneufem::inp {

/// What the data lines of the current keyword are.
enum class Block {
  None, Skip, Node, Element, SurfaceElement, NodeSet, ElementSet, Surface, Dload, Dsload, Boundary, Placement
};

/// Where a keyword stands in an Abaqus model: a flat deck and the history data after the
/// assembly are at Model level.
enum class Level { Model, Part, Assembly, Instance };

constexpr std::size_t kMaxRegions = 65535;  // Mesh::region holds std::uint16_t
constexpr std::size_t kMaxScopes = 65535;   // Mesh::node_scope holds std::uint16_t

/// A surface element type (plane, shell, membrane, rigid: how meshers write named surfaces): its
/// corners (3 or 4) and nodes (3, 6, 4 or 8); {0, 0} for any other type (surface_elements.cpp).
struct SurfaceShape {
  int corners = 0;
  int nodes = 0;
};
SurfaceShape surface_element_shape(const std::string& type);
/// Line elements (trusses, beams: a mesher's named curves), skipped with a warning.
bool line_element_type(const std::string& type);

/// Single pass over the deck (LineSource resolves *INCLUDE).
///
/// Parts and instances (decks as Abaqus/CAE writes them): the lines of a *PART block are recorded
/// and read again for every *INSTANCE of it, in the instance's id scope and placement, so each
/// instance gets its own nodes, elements, sets and surfaces (the deck's ids are per instance);
/// lines inside an *INSTANCE block (an independent instance's mesh) add to that instance.
class DeckReader {
 public:
  DeckReader(const std::string& path, double length_to_m) : lines_(path), length_to_m_(length_to_m) {}

  InpDeck read();

 private:
  /// An id scope: the model/assembly level (scopes_[0]) or one instance. Ids, set and surface
  /// names are the deck's own within it; sets hold Mesh indices.
  struct Scope {
    std::string name;  // instance name as written; the assembly's name for scopes_[0]
    std::string part;  // upper-case part name (instances)
    Loc loc;           // its *INSTANCE line
    inp::Placement placement;
    std::unordered_map<long, int> node_index, element_index;  // deck id -> Mesh index
    std::map<std::string, std::vector<int>> node_sets, element_sets;
    std::map<std::string, std::vector<FaceRef>> surfaces;
    std::set<std::string> internal_node_sets, internal_element_sets, internal_surfaces;
    long max_node_id = 0, max_element_id = 0;
    int nodes = 0;
  };
  struct RecordedLine {
    std::string_view text;
    Loc loc;
  };
  struct PartDef {
    std::string name;  // as written
    Loc loc;
    std::vector<RecordedLine> lines;  // read again for each instance
    bool instanced = false;
  };

  // ---- errors and warnings ------------------------------------------------------------------
  std::string where(const Loc& loc) const { return lines_.where(loc); }

  /// "<file>:<line>: ", and the part and instance while a part's lines are read for an instance.
  std::string at(const Loc& loc) const { return where(loc) + ": " + context_; }

  [[noreturn]] void fail(const Loc& loc, const std::string& what, const std::string& todo) const {
    throw InputError(printable(at(loc) + what + "; " + todo));
  }

  /// Adds `message` to the warnings unless a warning with the same key was already given.
  void warn_once(const std::string& key, const Loc& loc, const std::string& message) {
    if (warned_.insert(key).second) deck_.warnings.push_back(at(loc) + message);
  }

  // ---- blocks (reader.cpp) ----------------------------------------------------------------------
  void begin_block(std::string_view text, const Loc& loc);
  void end_block();
  void data_line(std::string_view text, const Loc& loc);

  // ---- *PART, *ASSEMBLY, *INSTANCE (read_parts.cpp) ----------------------------------------
  void begin_part(const Keyword& kw, const Loc& loc);
  void record_in_part(const Keyword& kw, std::string_view text, const Loc& loc);
  void begin_assembly(const Keyword& kw, const Loc& loc);
  void end_assembly(const Loc& loc);
  void begin_instance(const Keyword& kw, const Loc& loc);
  void placement_line(const Loc& loc);
  std::string part_context(const Scope& s) const;
  void instantiate();
  void end_instance(const Loc& loc);
  void end_of_structure();

  // ---- *MATERIAL, MODULI= of *HYPERELASTIC / *VISCOELASTIC (reader.cpp) -----------------------
  void material_keyword(const Keyword& kw, const Loc& loc);

  // ---- *NODE, *ELEMENT (reader.cpp) ---------------------------------------------------------------
  void begin_nodes(const Keyword& kw, const Loc& loc);
  void node_line(const Loc& loc);
  void begin_elements(const Keyword& kw, const Loc& loc);
  bool gather_element(const Loc& loc);
  int element_node(long node) const;
  void element_line(const Loc& loc);

  // ---- surface elements (surface_elements.cpp) -----------------------------------------------
  struct SurfaceElement {
    long id;
    Loc loc;
    std::uint16_t part_instance;  // its instance if read from a part (as solid_part_instance_), else 0
    int n_corners;                // 3 or 4
    std::array<int, 4> corners;   // node indices, in the element's order
  };
  void begin_surface_elements(const Keyword& kw, const Loc& loc, const std::string& type, const SurfaceShape& shape);
  void surface_element_line(const Loc& loc);
  void resolve_surface_elements();
  std::string surface_element_where(const SurfaceElement& t) const;

  // ---- *NSET / *ELSET, names and ids in data lines (read_sets.cpp) --------------------------
  // A data line names nodes, elements, sets and surfaces of its own scope: a part's (read for an
  // instance), an instance's, or the model/assembly level's. At the model/assembly level, as in
  // Abaqus, "Actuator-1.Set-1" and "Actuator-1.123" name an instance's set and id; a bare name
  // the assembly does not define is accepted for the one instance that defines it (several: an
  // error listing the choices), as the names the reader stores allow too (assembly.h).
  void begin_set(const Keyword& kw, const Loc& loc);
  void set_line(const Loc& loc);

  Scope& scope() { return scopes_[static_cast<std::size_t>(scope_)]; }
  const Scope& scope() const { return scopes_[static_cast<std::size_t>(scope_)]; }
  /// The scope whose ids and names a data line uses: the instance of a set with INSTANCE=.
  int home_index() const { return member_scope_ >= 0 ? member_scope_ : scope_; }
  Scope& home() { return scopes_[static_cast<std::size_t>(home_index())]; }

  std::vector<std::string> instance_names() const;
  /// The instance named by the qualifier of "INSTANCE.REST" (at the model/assembly level), with
  /// `rest` set to REST; -1 if the token is not qualified by an instance.
  int qualifier(std::string_view token, std::string_view& rest) const;
  /// "123", or "Actuator-1.123" for an id of another scope than the line's own.
  std::string id_text(int scope, long id) const;
  /// Index of the node (or element) that `token` names by id ("123", or "Actuator-1.123"); -1 if
  /// the token is not an id. An undefined id is an error naming `context` and `todo`.
  int find_id(bool nodes, std::string_view token, const Loc& loc, const std::string& context,
              const std::string& todo);
  /// The set (or surface) of `names` that `token` names, or nullptr; an ambiguous bare name is
  /// an error listing the qualified choices. (V: std::vector<int> or std::vector<FaceRef>.)
  template <class V>
  V* find_named(std::map<std::string, V> Scope::*names, std::string_view token, const Loc& loc,
                const std::string& context, const std::string& kind);
  /// Members of the node (or element) set named `name`; error naming `context` when unknown.
  const std::vector<int>& named_set(bool nodes, std::string_view name, const Loc& loc, const std::string& context);

  /// Calls f(index) for the element id or element set named by `token`.
  template <class F>
  void for_elements(std::string_view token, const Loc& loc, const std::string& context, F&& f) {
    if (const int e = find_id(false, token, loc, context, "define it under *ELEMENT before this line or fix the id");
        e >= 0) {
      f(e);
      return;
    }
    for (int e : named_set(false, token, loc, context)) f(e);
  }

  template <class F>
  void for_nodes(std::string_view token, const Loc& loc, const std::string& context, F&& f) {
    if (const int n = find_id(true, token, loc, context, "define it under *NODE before this line or fix the id"); n >= 0) {
      f(n);
      return;
    }
    for (int n : named_set(true, token, loc, context)) f(n);
  }

  /// Makes `name` (upper-cased) the set the current block adds to; a set exists once declared,
  /// even if empty. Repeated definitions add to the set, as in CalculiX.
  void open_set(std::map<std::string, std::vector<int>>& sets, const std::string& name);
  static void normalise(std::vector<int>& v);

  // ---- *SURFACE, *DLOAD, *DSLOAD, *BOUNDARY (read_loads.cpp) ------------------------------
  void begin_surface(const Keyword& kw, const Loc& loc);
  void surface_line(const Loc& loc);
  void check_face(int e, int face, const std::string& label, const Loc& loc) const;
  void dload_line(const Loc& loc);
  std::optional<double> magnitude(const std::string& keyword, const std::string& label, const std::string& first,
                                  const Loc& loc) const;
  void add_pressure(const FaceRef& f, double p, const std::string& label, const Loc& loc);
  void dsload_line(const Loc& loc);
  void boundary_line(const Loc& loc);

  // ---- end of deck (reader.cpp; the id scopes in read_parts.cpp) -----------------------------
  void finish();
  void split();
  std::string solid_where(int s) const;
  void export_names();
  int scopes_with_mesh() const;
  std::string element_name(int e) const;
  void number_scopes();
  void check_instances();

  // ---- state --------------------------------------------------------------------------------
  LineSource lines_;
  double length_to_m_;
  InpDeck deck_;

  std::vector<std::string_view> fields_;
  bool trailing_comma_ = false;

  Block block_ = Block::None;
  std::string open_set_;                      // set filled by the current block (upper case), or empty
  std::vector<int>* open_members_ = nullptr;  // its members (std::map values do not move)
  // Sets changed since they were last sorted; sorted when next used (not after every block: a
  // region written as many *ELEMENT runs would be re-sorted once per run).
  std::unordered_set<std::vector<int>*> unsorted_;
  bool generate_ = false;
  std::string surface_;

  std::optional<Loc> first_type_loc_;
  std::string first_type_;    // TYPE of the first *ELEMENT block (its order is the deck's)
  SolidType solid_ = SolidType::C3D4;  // of the current *ELEMENT block
  SolidElements solids_;      // the deck's solid elements, split into tetrahedra by finish()
  std::vector<Loc> solid_loc_;
  std::vector<std::uint16_t> solid_part_instance_;  // its instance if read from a part (solid_where), else 0
  std::vector<int> element_nodes_;
  std::string type_name_;
  int npe_ = 0;
  std::uint16_t region_ = 0;
  std::vector<long> pending_;  // element id + nodes read so far (continuation lines)
  // (scope, ELSET) -> its surface elements, resolved by finish()
  std::map<std::pair<int, std::string>, std::vector<SurfaceElement>> surface_elements_;
  std::string surface_set_;  // ELSET of the surface element block being read
  int surface_corners_ = 0;  // and the corners of its elements
  Loc pending_loc_;

  std::deque<Scope> scopes_;  // a deque: open_members_ points into a Scope's sets
  int scope_ = 0;             // scope of the line being read
  int member_scope_ = -1;     // scope of the members of a set with INSTANCE=, or -1

  std::map<std::string, PartDef> parts_;   // upper-case name -> part
  PartDef* recording_ = nullptr;           // the *PART block being recorded
  std::map<std::string, int> instance_index_;  // upper-case instance name -> scope
  Level level_ = Level::Model;
  std::optional<Loc> assembly_loc_;
  int pending_instance_ = -1;  // instance whose placement lines are being read (its part follows)
  int placement_lines_ = 0;
  std::string context_;        // "part 'P' (instance 'I'): " while a part is read for an instance

  std::string material_;  // NAME= of the last *MATERIAL (upper case)

  std::unordered_map<long long, std::size_t> load_index_;
  std::unordered_set<long long> fixed_;
  std::set<std::string> warned_;
};

}  // namespace pneufem::inp

#include "scenes/inp.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <deque>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

#include "materials/errors.h"
#include "scenes/inp_assembly.h"
#include "scenes/solid_split.h"

namespace pneufem {

namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// Text helpers
// ---------------------------------------------------------------------------------------------

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

std::string upper(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
  return out;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return out;
}

/// Splits a data or keyword line at commas into trimmed fields. A trailing comma (Abaqus:
/// "continued on the next line") does not produce an empty last field; it is reported instead.
void split_fields(std::string_view line, std::vector<std::string_view>& fields, bool& trailing_comma) {
  fields.clear();
  line = trim(line);
  trailing_comma = !line.empty() && line.back() == ',';
  if (trailing_comma) line.remove_suffix(1);
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(trim(line.substr(start, comma == std::string_view::npos ? line.npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
}

/// Whole-field integer ("+12" allowed); nullopt for anything else.
std::optional<long> parse_long(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  long v = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

/// Whole-field finite real. Accepts what Fortran list input accepts in decks: "1.", ".5", "+2",
/// "1e-3" and the double-precision exponent "1.0D-3". Rejects inf/nan.
std::optional<double> parse_double(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty() || s.size() > 64) return std::nullopt;
  std::array<char, 64> buf{};
  for (std::size_t i = 0; i < s.size(); ++i) buf[i] = (s[i] == 'd' || s[i] == 'D') ? 'e' : s[i];
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(buf.data(), buf.data() + s.size(), v);
  if (ec != std::errc() || ptr != buf.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

/// Keyword name: "*Solid  Section, ..." -> "SOLID SECTION".
std::string keyword_name(std::string_view field) {
  field = trim(field.substr(1));  // drop '*'
  std::string out;
  bool space = false;
  for (char c : field) {
    if (is_blank(c)) {
      space = true;
      continue;
    }
    if (space && !out.empty()) out.push_back(' ');
    space = false;
    out.push_back(c);
  }
  return upper(out);
}

struct Keyword {
  std::string name;                           ///< upper case, single spaces
  std::map<std::string, std::string> params;  ///< upper-case key -> value as written (unquoted)
  bool has(const std::string& key) const { return params.count(key) != 0; }
  std::string get(const std::string& key) const {
    const auto it = params.find(key);
    return it == params.end() ? std::string() : it->second;
  }
};

Keyword parse_keyword(std::string_view line) {
  std::vector<std::string_view> fields;
  bool trailing = false;
  split_fields(line, fields, trailing);
  Keyword kw;
  kw.name = keyword_name(fields[0]);
  for (std::size_t i = 1; i < fields.size(); ++i) {
    const std::string_view f = fields[i];
    if (f.empty()) continue;
    const std::size_t eq = f.find('=');
    std::string key = upper(trim(f.substr(0, eq)));
    std::string_view value = eq == f.npos ? std::string_view() : trim(f.substr(eq + 1));
    if (value.size() >= 2 && value.front() == '"' && value.back() == '"') value = value.substr(1, value.size() - 2);
    kw.params[std::move(key)] = std::string(value);
  }
  return kw;
}

// ---------------------------------------------------------------------------------------------
// Deck reader
// ---------------------------------------------------------------------------------------------

struct Loc {
  int file = 0;  ///< index into DeckReader::file_names_
  int line = 0;  ///< 1-based
};

enum class Block {
  None, Skip, Node, Element, SurfaceElement, NodeSet, ElementSet, Surface, Dload, Dsload, Boundary, Placement
};

/// Where a keyword stands in an Abaqus model: a flat deck and the history data after the
/// assembly are at Model level.
enum class Level { Model, Part, Assembly, Instance };

/// Nodes of a triangular surface/shell/membrane/plane element type, or 0. Meshers (Gmsh among
/// them) write a deck's named boundary surfaces as such elements; pneufem reads them as faces of
/// its tetrahedra (DeckReader::finish).
int triangle_nodes(const std::string& type) {
  static const std::set<std::string> three = {"CPS3", "CPE3", "CAX3", "S3", "S3R", "S3RS", "STRI3", "M3D3",
                                              "SFM3D3", "DS3", "R3D3"};
  static const std::set<std::string> six = {"CPS6", "CPS6M", "CPE6", "CPE6M", "CAX6", "CAX6M", "S6",
                                            "STRI65", "M3D6", "SFM3D6", "DS6"};
  return three.count(type) ? 3 : six.count(type) ? 6 : 0;
}

/// Line and quadrilateral elements (trusses, beams, quad shells and planes): nothing a tetrahedral
/// model can use; a mesher writes them for named curves or quad-meshed faces.
bool skipped_element_type(const std::string& type) {
  static const std::set<std::string> skipped = {"T2D2", "T2D3", "T3D2", "T3D3", "B21", "B22", "B31", "B32", "B33",
                                                "R2D2", "CPS4", "CPS4R", "CPE4", "CPE4R", "CAX4", "CAX4R", "S4",
                                                "S4R", "M3D4", "M3D4R", "SFM3D4", "CPS8", "CPS8R", "CPE8", "CPE8R",
                                                "S8R", "M3D8", "M3D8R", "R3D4"};
  return skipped.count(type) != 0;
}

constexpr int kMaxIncludeDepth = 32;
constexpr std::size_t kMaxRegions = 65535;  // Mesh::region holds std::uint16_t
constexpr std::size_t kMaxScopes = 65535;   // Mesh::node_scope holds std::uint16_t

/// Keywords that join surfaces or nodes (ties, couplings, equations, contact): pneufem applies
/// none of them, it needs one conforming mesh.
bool constraint_keyword(const std::string& name) {
  static const std::set<std::string> constraints = {
      "TIE", "COUPLING", "KINEMATIC COUPLING", "DISTRIBUTING COUPLING", "MPC", "EQUATION", "RIGID BODY",
      "CONTACT PAIR", "CONTACT", "CONTACT INCLUSIONS", "EMBEDDED ELEMENT", "SHELL TO SOLID COUPLING"};
  return constraints.count(name) != 0;
}

/// Single pass over the deck. *INCLUDE is textual (as in CalculiX): the included lines are read in
/// place of the *INCLUDE line, so a data block may continue into an included file.
///
/// Parts and instances (decks as Abaqus/CAE writes them): the lines of a *PART block are recorded
/// and read again for every *INSTANCE of it, in the instance's id scope and placement, so each
/// instance gets its own nodes, elements, sets and surfaces (the deck's ids are per instance);
/// lines inside an *INSTANCE block (an independent instance's mesh) add to that instance.
class DeckReader {
 public:
  explicit DeckReader(double length_to_m) : length_to_m_(length_to_m) {}

  InpDeck read(const std::string& path) {
    push_file(path, std::nullopt);
    scopes_.emplace_back();  // the model / assembly level
    std::string_view text;
    Loc loc;
    bool any_line = false;
    while (next_line(text, loc)) {
      any_line = true;
      if (text.front() == '*')
        begin_block(text, loc);
      else
        data_line(text, loc);
    }
    end_block();
    if (!any_line)
      fail(Loc{0, std::max(1, last_line_of_top_)}, "the deck is empty (no keyword or data lines)",
           "give a deck with *NODE and *ELEMENT, TYPE=C3D4 or C3D10 blocks");
    end_of_structure();
    finish();
    return std::move(deck_);
  }

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
  std::string where(const Loc& loc) const {
    return file_names_[static_cast<std::size_t>(loc.file)] + ":" + std::to_string(loc.line);
  }

  /// "<file>:<line>: ", and the part and instance while a part's lines are read for an instance.
  std::string at(const Loc& loc) const { return where(loc) + ": " + context_; }

  [[noreturn]] void fail(const Loc& loc, const std::string& what, const std::string& todo) const {
    throw InputError(at(loc) + what + "; " + todo);
  }

  /// Adds `message` to the warnings unless a warning with the same key was already given.
  void warn_once(const std::string& key, const Loc& loc, const std::string& message) {
    if (warned_.insert(key).second) deck_.warnings.push_back(at(loc) + message);
  }

  // ---- line source --------------------------------------------------------------------------
  struct Frame {
    int file = 0;
    std::size_t pos = 0;
    int line = 0;
  };

  void push_file(const std::string& path, const std::optional<Loc>& from) {
    std::ifstream in;
    std::error_code ec;
    if (!fs::is_directory(path, ec)) in.open(path, std::ios::binary);
    if (!in) {
      if (!from) throw InputError(path + ": cannot open the deck; check the path and the file permissions");
      fail(*from, "cannot open include file '" + path + "'",
           "check INPUT= (a relative path is taken from the directory of the including file)");
    }
    std::string text;
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    in.seekg(0, std::ios::beg);
    if (size > 0) {
      text.resize(static_cast<std::size_t>(size));
      in.read(text.data(), size);
      text.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
    }
    if (text.starts_with("\xEF\xBB\xBF")) text.erase(0, 3);  // UTF-8 byte-order mark
    buffers_.push_back(std::move(text));
    file_names_.push_back(path);
    stack_.push_back(Frame{static_cast<int>(file_names_.size()) - 1, 0, 0});
  }

  /// Next non-blank, non-comment line (trimmed), with *INCLUDE resolved. False at the end.
  bool next_line(std::string_view& text, Loc& loc) {
    while (!stack_.empty()) {
      Frame& fr = stack_.back();
      const std::string& buf = buffers_[static_cast<std::size_t>(fr.file)];
      if (fr.pos >= buf.size()) {
        if (stack_.size() == 1) last_line_of_top_ = fr.line;
        stack_.pop_back();
        continue;
      }
      const std::size_t nl = buf.find('\n', fr.pos);
      const std::size_t end = nl == std::string::npos ? buf.size() : nl;
      text = trim(std::string_view(buf).substr(fr.pos, end - fr.pos));
      fr.pos = end + 1;
      ++fr.line;
      loc = Loc{fr.file, fr.line};
      if (text.empty() || text.starts_with("**")) continue;
      if (text.front() == '*' && keyword_name(text.substr(0, text.find(','))) == "INCLUDE") {
        include(text, loc);
        continue;
      }
      return true;
    }
    return false;
  }

  void include(std::string_view text, const Loc& loc) {
    const Keyword kw = parse_keyword(text);
    const std::string input = kw.get("INPUT");
    if (input.empty()) fail(loc, "*INCLUDE without INPUT=<file>", "add INPUT=<path of the file to include>");
    if (static_cast<int>(stack_.size()) >= kMaxIncludeDepth)
      fail(loc, "*INCLUDE nested deeper than " + std::to_string(kMaxIncludeDepth) + " files",
           "check for a file that includes itself");
    fs::path p(input);
    if (p.is_relative()) p = fs::path(file_names_[static_cast<std::size_t>(loc.file)]).parent_path() / p;
    push_file(p.string(), loc);
  }

  // ---- blocks -------------------------------------------------------------------------------
  void begin_block(std::string_view text, const Loc& loc) {
    end_block();
    const Keyword kw = parse_keyword(text);
    if (recording_) return record_in_part(kw, text, loc);
    if (pending_instance_ >= 0) instantiate();  // its placement lines are read: now its part
    block_ = Block::Skip;
    if (kw.name == "NODE")
      begin_nodes(kw, loc);
    else if (kw.name == "ELEMENT")
      begin_elements(kw, loc);
    else if (kw.name == "NSET" || kw.name == "ELSET")
      begin_set(kw, loc);
    else if (kw.name == "SURFACE")
      begin_surface(kw, loc);
    else if (kw.name == "DLOAD")
      block_ = Block::Dload;
    else if (kw.name == "DSLOAD")
      block_ = Block::Dsload;
    else if (kw.name == "BOUNDARY")
      block_ = Block::Boundary;
    else if (kw.name == "PART")
      begin_part(kw, loc);
    else if (kw.name == "END PART")
      fail(loc, "*End Part without *Part", "remove it, or add *Part, name=<name> where the part begins");
    else if (kw.name == "ASSEMBLY")
      begin_assembly(kw, loc);
    else if (kw.name == "END ASSEMBLY")
      end_assembly(loc);
    else if (kw.name == "INSTANCE")
      begin_instance(kw, loc);
    else if (kw.name == "END INSTANCE")
      end_instance(loc);
    else if (constraint_keyword(kw.name))
      warn_once("constraint " + kw.name, loc,
                "*" + kw.name + (kw.has("NAME") ? " " + kw.get("NAME") : std::string()) +
                    " ignored: pneufem applies no ties, couplings, equations or contact and needs one conforming "
                    "mesh; if it joins instances, merge the instances in Abaqus (Merge/Cut Instances) so the mesh "
                    "is conforming");
    else if (kw.name == "MEMBRANE SECTION" || kw.name == "SHELL SECTION")
      // A fabric modelled as membrane or shell elements: its triangles are read as a surface, so
      // say how to give it stiffness, since a solid-fabric scene would silently leave it out.
      warn_once("section " + upper(kw.get("ELSET")), loc,
                "*" + kw.name + ", ELSET=" + upper(kw.get("ELSET")) +
                    ": its elements are read as a surface, without stiffness; to model them as the fabric set "
                    "mesh.fabric_model = \"membrane\" and mesh.fabric_surface = \"" + upper(kw.get("ELSET")) +
                    "\" (thickness geometry.fabric_thickness_mm, E and nu from [materials.fabric])");
    else
      warn_once("keyword " + kw.name, loc,
                "*" + kw.name +
                    " skipped (only the mesh, sets, surfaces, *DLOAD Pn, *DSLOAD P and *BOUNDARY are read; "
                    "materials and steps come from the scene)");
  }

  void end_block() {
    if ((block_ == Block::Element || block_ == Block::SurfaceElement) && !pending_.empty()) {
      fail(pending_loc_,
           "element " + std::to_string(pending_[0]) + " lists " + std::to_string(pending_.size() - 1) +
               " nodes but a " + type_name_ + " has " + std::to_string(npe_),
           "list all its nodes (a line ending with ',' continues on the next data line)");
    }
    if (open_members_) unsorted_.insert(open_members_);
    open_members_ = nullptr;
    open_set_.clear();
    member_scope_ = -1;
    block_ = Block::None;
  }

  void data_line(std::string_view text, const Loc& loc) {
    if (recording_) {
      recording_->lines.push_back(RecordedLine{text, loc});
      return;
    }
    split_fields(text, fields_, trailing_comma_);
    switch (block_) {
      case Block::None:
        fail(loc, "data line before any keyword", "start the deck with a keyword line such as *NODE");
      case Block::Skip:
        return;
      case Block::Node:
        return node_line(loc);
      case Block::Element:
        return element_line(loc);
      case Block::SurfaceElement:
        return surface_element_line(loc);
      case Block::NodeSet:
      case Block::ElementSet:
        return set_line(loc);
      case Block::Surface:
        return surface_line(loc);
      case Block::Dload:
        return dload_line(loc);
      case Block::Dsload:
        return dsload_line(loc);
      case Block::Boundary:
        return boundary_line(loc);
      case Block::Placement:
        return placement_line(loc);
    }
  }

  // ---- *PART, *ASSEMBLY, *INSTANCE ------------------------------------------------------------
  void begin_part(const Keyword& kw, const Loc& loc) {
    if (level_ != Level::Model)
      fail(loc, "*Part inside *Assembly", "define the parts before *Assembly (close the assembly with *End Assembly)");
    const std::string name = kw.get("NAME");
    if (name.empty()) fail(loc, "*Part without NAME=", "add NAME=<part name>");
    const auto [it, fresh] = parts_.try_emplace(upper(name), PartDef{name, loc, {}, false});
    if (!fresh)
      fail(loc, "part '" + name + "' is defined twice (first at " + where(it->second.loc) + ")",
           "rename one of them (part names are case-insensitive)");
    recording_ = &it->second;
    level_ = Level::Part;
  }

  /// A line of the part being recorded; *END PART ends it. Parts do not nest.
  void record_in_part(const Keyword& kw, std::string_view text, const Loc& loc) {
    if (kw.name == "END PART") {
      recording_ = nullptr;
      level_ = Level::Model;
      return;
    }
    if (kw.name == "PART" || kw.name == "ASSEMBLY" || kw.name == "END ASSEMBLY" || kw.name == "INSTANCE" ||
        kw.name == "END INSTANCE")
      fail(loc, "*" + kw.name + " inside *Part '" + recording_->name + "' (" + where(recording_->loc) + ")",
           "close the part with *End Part first");
    recording_->lines.push_back(RecordedLine{text, loc});
  }

  void begin_assembly(const Keyword& kw, const Loc& loc) {
    if (assembly_loc_)
      fail(loc, "a second *Assembly (the first is at " + where(*assembly_loc_) + ")",
           "a deck has one assembly: put every *Instance into it");
    if (level_ != Level::Model) fail(loc, "*Assembly inside another block", "close that block first");
    assembly_loc_ = loc;
    scopes_[0].name = kw.get("NAME").empty() ? std::string("Assembly") : kw.get("NAME");
    level_ = Level::Assembly;
  }

  void end_assembly(const Loc& loc) {
    if (level_ == Level::Instance)
      fail(loc, "*End Assembly inside *Instance '" + scope().name + "' (" + where(scope().loc) + ")",
           "close the instance with *End Instance first");
    if (level_ != Level::Assembly)
      fail(loc, "*End Assembly without *Assembly", "remove it, or add *Assembly, name=Assembly before the instances");
    level_ = Level::Model;
  }

  void begin_instance(const Keyword& kw, const Loc& loc) {
    if (level_ == Level::Instance)
      fail(loc, "*Instance inside *Instance '" + scope().name + "' (" + where(scope().loc) + ")",
           "close that instance with *End Instance first");
    if (level_ != Level::Assembly)
      fail(loc, "*Instance outside *Assembly", "put the instances between *Assembly, name=Assembly and *End Assembly");
    if (kw.has("INSTANCE") || kw.has("LIBRARY"))
      fail(loc, "*Instance imported from a previous analysis (INSTANCE=, LIBRARY=) is not supported",
           "write the part into the deck (*Part ... *End Part) and instance it with PART=");
    const std::string name = kw.get("NAME"), part = kw.get("PART");
    if (name.empty() || part.empty())
      fail(loc, "*Instance without " + std::string(name.empty() ? "NAME=" : "PART="),
           "write *Instance, name=<instance>, part=<part>");
    if (name.find('.') != std::string::npos)
      fail(loc, "instance name '" + name + "' contains a '.'",
           "rename the instance: '.' separates an instance from its sets and ids ('Actuator-1.Set-1')");
    const auto p = parts_.find(upper(part));
    if (p == parts_.end())
      fail(loc, "instance '" + name + "' refers to part '" + part + "', which is not defined above",
           "define *Part, name=" + part + " ... *End Part before the assembly (part names are case-insensitive)");
    const auto [it, fresh] = instance_index_.try_emplace(upper(name), static_cast<int>(scopes_.size()));
    if (!fresh)
      fail(loc, "instance '" + name + "' is defined twice (first at " + where(scopes_[static_cast<std::size_t>(it->second)].loc) + ")",
           "rename one of them (instance names are case-insensitive)");
    if (scopes_.size() > kMaxScopes)
      fail(loc, "more than " + std::to_string(kMaxScopes) + " instances", "merge instances in Abaqus");
    p->second.instanced = true;
    Scope& s = scopes_.emplace_back();
    s.name = name;
    s.part = p->first;
    s.loc = loc;
    pending_instance_ = it->second;
    placement_lines_ = 0;
    level_ = Level::Instance;
    block_ = Block::Placement;
  }

  /// The data lines of *INSTANCE: a translation "dx, dy, dz", then optionally a rotation
  /// "xa, ya, za, xb, yb, zb, angle" (degrees about the axis a -> b, applied after the translation).
  void placement_line(const Loc& loc) {
    Scope& s = scopes_[static_cast<std::size_t>(pending_instance_)];
    const std::string what = "*Instance '" + s.name + "'";
    const std::size_t need = ++placement_lines_ == 1 ? 3 : 7;
    if (placement_lines_ > 2)
      fail(loc, what + " has a third data line",
           "an instance has a translation line (3 numbers) and optionally a rotation line (7 numbers: two "
           "points on the axis and the angle in degrees)");
    const char* form = need == 3 ? "'dx, dy, dz'" : "'xa, ya, za, xb, yb, zb, angle_deg' (two points on the axis, the angle in degrees)";
    if (fields_.size() != need)
      fail(loc, "the " + std::string(need == 3 ? "translation" : "rotation") + " line of " + what + " has " +
                    std::to_string(fields_.size()) + " values",
           "write " + std::string(form));
    std::array<double, 7> v{};
    for (std::size_t k = 0; k < need; ++k) {
      const std::optional<double> x = fields_[k].empty() ? std::optional<double>(0.0) : parse_double(fields_[k]);
      if (!x) fail(loc, what + ": '" + std::string(fields_[k]) + "' is not a finite number", "write " + std::string(form));
      v[k] = *x;
    }
    if (need == 3) {
      s.placement.t = Eigen::Vector3d(v[0], v[1], v[2]) * length_to_m_;
      return;
    }
    const Eigen::Vector3d a(v[0], v[1], v[2]), b(v[3], v[4], v[5]);
    if (v[6] == 0.0) return;
    if ((b - a).norm() == 0.0)
      fail(loc, what + ": the rotation axis has two equal points", "give two distinct points a, b on the axis");
    s.placement.a = a * length_to_m_;
    s.placement.R = inp::rotation_deg((b - a).normalized(), v[6]);
  }

  /// "part 'P' (instance 'I')": messages about a part's line read for instance s say so.
  std::string part_context(const Scope& s) const {
    return "part '" + parts_.at(s.part).name + "' (instance '" + s.name + "')";
  }

  /// Reads the instance's part: its recorded lines in the instance's scope and placement.
  void instantiate() {
    const int index = pending_instance_;
    pending_instance_ = -1;
    const Scope& s = scopes_[static_cast<std::size_t>(index)];
    const PartDef& part = parts_.at(s.part);
    scope_ = index;
    context_ = part_context(s) + ": ";
    for (const RecordedLine& l : part.lines) {
      if (l.text.front() == '*')
        begin_block(l.text, l.loc);
      else
        data_line(l.text, l.loc);
    }
    end_block();
    context_.clear();
  }

  void end_instance(const Loc& loc) {
    if (level_ != Level::Instance)
      fail(loc, "*End Instance without *Instance", "remove it, or add *Instance, name=<instance>, part=<part> above");
    level_ = Level::Assembly;
    scope_ = 0;
  }

  /// At the end of the deck: every *PART, *INSTANCE and *ASSEMBLY must be closed.
  void end_of_structure() {
    if (recording_)
      fail(recording_->loc, "*Part '" + recording_->name + "' has no *End Part", "close the part with *End Part");
    if (level_ == Level::Instance) {
      const Scope& s = scopes_[static_cast<std::size_t>(pending_instance_ >= 0 ? pending_instance_ : scope_)];
      fail(s.loc, "*Instance '" + s.name + "' has no *End Instance", "close it with *End Instance");
    }
    if (level_ == Level::Assembly)
      fail(*assembly_loc_, "*Assembly has no *End Assembly",
           "close it with *End Assembly after the instances and the assembly's sets and surfaces");
  }

  // ---- *NODE --------------------------------------------------------------------------------
  void begin_nodes(const Keyword& kw, const Loc& loc) {
    if (kw.has("INPUT")) fail(loc, "*NODE, INPUT= is not supported", "put the node lines in a file read with *INCLUDE");
    const std::string system = upper(kw.get("SYSTEM"));
    if (!system.empty() && system != "R")
      fail(loc, "*NODE, SYSTEM=" + system + " (non-Cartesian coordinates) is not supported",
           "write Cartesian coordinates (SYSTEM=R)");
    block_ = Block::Node;
    open_set(scope().node_sets, kw.get("NSET"));
  }

  void node_line(const Loc& loc) {
    const std::optional<long> id = parse_long(fields_[0]);
    if (!id || *id <= 0)
      fail(loc, "node id '" + std::string(fields_[0]) + "' is not a positive integer",
           "a *NODE data line is 'id, x, y, z'");
    if (fields_.size() < 4)
      fail(loc,
           "node " + std::to_string(*id) + " has " + std::to_string(fields_.size() - 1) +
               " coordinate(s) but pneufem needs 3-D nodes",
           "give 'id, x, y, z' (2-D decks are not supported)");
    Eigen::Vector3d x;
    for (int k = 0; k < 3; ++k) {
      const std::string_view f = fields_[static_cast<std::size_t>(k) + 1];
      const std::optional<double> v = f.empty() ? std::optional<double>(0.0) : parse_double(f);  // Abaqus: blank = 0
      if (!v)
        fail(loc,
             "node " + std::to_string(*id) + ": coordinate " + "xyz"[k] + " '" + std::string(f) +
                 "' is not a finite number",
             "fix the value");
      x[k] = *v * length_to_m_;
    }
    Scope& s = scope();
    const int index = deck_.mesh.num_nodes();
    if (!s.node_index.try_emplace(*id, index).second)
      fail(loc, "node " + std::to_string(*id) + " is defined twice", "node ids must be unique: renumber or remove one");
    deck_.mesh.X.push_back(s.placement.apply(x));
    deck_.mesh.node_ids.push_back(*id);
    deck_.mesh.node_scope.push_back(static_cast<std::uint16_t>(scope_));
    s.max_node_id = std::max(s.max_node_id, *id);
    ++s.nodes;
    if (open_members_) open_members_->push_back(index);
  }

  // ---- *ELEMENT -----------------------------------------------------------------------------
  void begin_elements(const Keyword& kw, const Loc& loc) {
    if (kw.has("INPUT"))
      fail(loc, "*ELEMENT, INPUT= is not supported", "put the element lines in a file read with *INCLUDE");
    const std::string type = upper(kw.get("TYPE"));
    if (type.empty()) fail(loc, "*ELEMENT without TYPE=", "add TYPE=C3D4 or TYPE=C3D10");
    if (const int n = triangle_nodes(type); n > 0) return begin_surface_elements(kw, loc, type, n);
    if (skipped_element_type(type)) {
      warn_once("type " + type, loc,
                "*ELEMENT, TYPE=" + type + " skipped (line and quadrilateral elements: a tetrahedral model uses "
                "triangles for named surfaces)");
      block_ = Block::Skip;
      return;
    }
    const std::optional<SolidType> solid = solid_type(type);
    if (!solid)
      fail(loc,
           "element type " + type + " is not supported (pneufem reads the solid elements C3D4, C3D10, C3D5, C3D6, "
           "C3D15, C3D8 and C3D20, with the suffixes H, R, I, M, S)",
           "convert the mesh to one of them (triangular surface elements such as CPS3/CPS6/S3 are read as named "
           "surfaces; line and quadrilateral elements are skipped)");
    solid_ = *solid;
    type_name_ = solid_name(solid_);
    if (type != type_name_)
      warn_once("type " + type, loc,
                type + " is read as " + type_name_ +
                    " (hybrid, reduced-integration, incompatible-mode or modified: the scene chooses the formulation)");
    const ElementType et = solid_quadratic(solid_) ? ElementType::Tet10 : ElementType::Tet4;
    if (!first_type_loc_) {
      deck_.mesh.type = et;
      first_type_loc_ = loc;
      first_type_ = type_name_;
    } else if (deck_.mesh.type != et) {
      fail(loc,
           "TYPE=" + type + " mixes element orders with the " + first_type_ + " elements of " + where(*first_type_loc_),
           "use one element order throughout (all linear: C3D4, C3D5, C3D6, C3D8; or all quadratic: C3D10, C3D15, "
           "C3D20)");
    }
    npe_ = solid_nodes(solid_);
    block_ = Block::Element;
    const std::string elset = kw.get("ELSET");
    open_set(scope().element_sets, elset);
    const std::string region = elset.empty() ? std::string("default") : lower(elset);
    if (deck_.mesh.find_region(region) < 0 && deck_.mesh.region_names.size() > kMaxRegions)
      fail(loc, "more than " + std::to_string(kMaxRegions + 1) + " distinct ELSET= names on *ELEMENT",
           "group the elements into fewer element sets (regions)");
    region_ = deck_.mesh.region_id(region);
  }

  /// Appends a data line of an *ELEMENT block (solid or surface: type_name_, npe_) to pending_
  /// (id, then nodes). False while the element continues on the next line (trailing comma); true
  /// when it is complete.
  bool gather_element(const Loc& loc) {
    if (pending_.empty()) pending_loc_ = loc;
    for (const std::string_view f : fields_) {
      const std::optional<long> v = parse_long(f);
      if (!v) {
        const std::string who =
            pending_.empty() ? std::string("element id") : "element " + std::to_string(pending_[0]) + ": node";
        fail(loc, who + " '" + std::string(f) + "' is not an integer",
             "an *ELEMENT data line is 'id, node1, node2, ...'");
      }
      pending_.push_back(*v);
    }
    const std::size_t need = static_cast<std::size_t>(npe_) + 1;
    if (pending_.size() < need && trailing_comma_) return false;  // continued on the next data line
    if (pending_.size() != need)
      fail(pending_loc_,
           "element " + std::to_string(pending_[0]) + " lists " + std::to_string(pending_.size() - 1) +
               " nodes but a " + type_name_ + " has " + std::to_string(npe_),
           pending_.size() < need ? "list all its nodes (end a line with ',' to continue on the next)"
                                  : "fix the connectivity (or the TYPE= of the block)");
    return true;
  }

  /// Index of node `node` of the element being read (pending_[0]); fails if it is not defined.
  int element_node(long node) const {
    const auto& ids = scopes_[static_cast<std::size_t>(scope_)].node_index;
    const auto it = ids.find(node);
    if (it == ids.end())
      fail(pending_loc_,
           "element " + std::to_string(pending_[0]) + " refers to node " + std::to_string(node) +
               ", which is not defined",
           "define the node under *NODE before this *ELEMENT block, or fix the connectivity");
    return it->second;
  }

  void element_line(const Loc& loc) {
    if (!gather_element(loc)) return;
    const std::size_t need = static_cast<std::size_t>(npe_) + 1;
    Mesh& mesh = deck_.mesh;
    const long id = pending_[0];
    if (id <= 0) fail(pending_loc_, "element id " + std::to_string(id) + " is not positive", "use ids >= 1");
    const int index = solids_.size();
    Scope& s = scope();
    if (!s.element_index.try_emplace(id, index).second)
      fail(pending_loc_, "element " + std::to_string(id) + " is defined twice",
           "element ids must be unique: renumber or remove one");
    element_nodes_.clear();
    for (std::size_t k = 1; k < need; ++k) element_nodes_.push_back(element_node(pending_[k]));
    solids_.add(solid_, element_nodes_);
    solid_loc_.push_back(pending_loc_);
    solid_part_instance_.push_back(static_cast<std::uint16_t>(context_.empty() ? 0 : scope_));
    mesh.element_ids.push_back(id);
    mesh.element_scope.push_back(static_cast<std::uint16_t>(scope_));
    s.max_element_id = std::max(s.max_element_id, id);
    mesh.region.push_back(region_);
    if (open_members_) open_members_->push_back(index);
    pending_.clear();
  }

  // ---- triangular surface elements (a mesher's named surfaces) -----------------------------------
  void begin_surface_elements(const Keyword& kw, const Loc& loc, const std::string& type, int nodes) {
    type_name_ = type;
    npe_ = nodes;
    surface_set_ = upper(kw.get("ELSET"));
    if (surface_set_.empty())
      fail(loc, "*ELEMENT, TYPE=" + type + " without ELSET=",
           "name the surface (ELSET=CAVITY, say): pneufem reads triangular elements as named surfaces");
    warn_once("surface " + surface_set_, loc,
              "*ELEMENT, TYPE=" + type + ", ELSET=" + surface_set_ +
                  " read as faces of the tetrahedra: surface and node set " + surface_set_ +
                  " (usable as mesh.cavity_surface, fixed_set, tip_set, fabric_surface)");
    block_ = Block::SurfaceElement;
  }

  void surface_element_line(const Loc& loc) {
    if (!gather_element(loc)) return;
    SurfaceTriangle t{pending_[0], pending_loc_, {}};
    for (std::size_t k = 0; k < 3; ++k) t.corners[k] = element_node(pending_[k + 1]);
    surface_elements_[{scope_, surface_set_}].push_back(t);
    pending_.clear();
  }

  /// Each triangle of a surface element set -> the face of a tetrahedron it covers (matched by
  /// its three corner nodes, so the triangle's own node order and order do not matter, and the
  /// face's outward normal, which orients the cavity pressure, comes from the tetrahedron). A face
  /// shared by two tetrahedra (an embedded sheet) is kept with a note: build_model refuses it as
  /// a cavity, a membrane may lie there. The set becomes a surface and, unless a node set of that
  /// name exists, a node set of the faces' nodes.
  void resolve_surface_elements() {
    if (surface_elements_.empty()) return;
    Mesh& mesh = deck_.mesh;
    std::map<std::array<int, 3>, std::pair<FaceRef, int>> faces;  // sorted corners -> face, times seen
    for (int e = 0; e < mesh.num_elements(); ++e)
      for (int f = 0; f < 4; ++f) {
        const int* ln = face_local_nodes(mesh.type, f);
        std::array<int, 3> key = {mesh.element(e)[ln[0]], mesh.element(e)[ln[1]], mesh.element(e)[ln[2]]};
        std::sort(key.begin(), key.end());
        auto [it, inserted] = faces.try_emplace(key, FaceRef{e, f}, 0);
        ++it->second.second;
      }
    const int npf = nodes_per_face(mesh.type);
    for (const auto& [where_named, tris] : surface_elements_) {
      const auto& [scope_index, name] = where_named;
      Scope& s = scopes_[static_cast<std::size_t>(scope_index)];
      std::vector<FaceRef>& surface = s.surfaces[name];
      std::vector<int> nodes;
      std::size_t inside = 0;
      for (const SurfaceTriangle& t : tris) {
        std::array<int, 3> key = t.corners;
        std::sort(key.begin(), key.end());
        const auto it = faces.find(key);
        if (it == faces.end())
          fail(t.loc, "surface element " + std::to_string(t.id) + " (ELSET=" + name + ") matches no face of the tetrahedra",
               "its first three nodes must be the corners of a tetrahedron's face (export the surface from the same mesh" +
                   std::string(scopes_.size() > 1 ? "; in an assembly, from the same instance: merge the instances in "
                                                    "Abaqus (Merge/Cut Instances) so the mesh is conforming)"
                                                  : ")"));
        if (it->second.second > 1) ++inside;  // an embedded sheet: only a membrane may use it
        surface.push_back(it->second.first);
        const int* ln = face_local_nodes(mesh.type, it->second.first.local_face);
        for (int a = 0; a < npf; ++a) nodes.push_back(mesh.element(it->second.first.element)[ln[a]]);
      }
      if (!s.node_sets.count(name)) {
        normalise(nodes);
        s.node_sets[name] = std::move(nodes);
      }
      if (inside > 0)
        deck_.warnings.push_back(where(tris.front().loc) + ": " + std::to_string(inside) + " of the " + std::to_string(tris.size()) +
                                 " triangles of ELSET=" + name +
                                 " lie inside the solid (two tetrahedra share each): an embedded sheet, usable as "
                                 "the fabric membrane (mesh.fabric_surface), not as a cavity");
    }
  }

  // ---- *NSET / *ELSET -----------------------------------------------------------------------
  void begin_set(const Keyword& kw, const Loc& loc) {
    const bool nodes = kw.name == "NSET";
    const std::string key = nodes ? "NSET" : "ELSET";
    const std::string name = kw.get(key);
    if (name.empty()) fail(loc, "*" + key + " without " + key + "=<name>", "add the set name");
    if (nodes && kw.has("ELSET"))
      fail(loc, "*NSET, ELSET= (nodes of an element set) is not supported", "list the nodes or node sets instead");
    if (kw.has("INPUT")) fail(loc, "*" + key + ", INPUT= is not supported", "use *INCLUDE for the member lines");
    int members_in = -1;
    if (kw.has("INSTANCE")) {
      // An assembly-level set of one instance's nodes or elements: its data lines use that
      // instance's ids and set names.
      const std::string instance = kw.get("INSTANCE");
      if (scope_ != 0)
        fail(loc, "*" + key + ", INSTANCE= inside a part or an instance",
             "use INSTANCE= on assembly-level sets only (between the instances and *End Assembly)");
      const auto it = instance_index_.find(upper(instance));
      if (it == instance_index_.end())
        fail(loc, "*" + key + ", INSTANCE=" + instance + ": no such instance above",
             instance_index_.empty() ? std::string("define it with *Instance, name=" + instance + ", part=<part>")
                                     : "use one of " + inp::join_names(instance_names()));
      members_in = it->second;
    }
    block_ = nodes ? Block::NodeSet : Block::ElementSet;
    generate_ = kw.has("GENERATE");
    Scope& s = scope();
    open_set(nodes ? s.node_sets : s.element_sets, name);
    // CAE's INTERNAL sets (the element sets behind a *SURFACE, picked regions) are the deck's
    // plumbing: used while reading, not offered to the scene.
    if (kw.has("INTERNAL")) (nodes ? s.internal_node_sets : s.internal_element_sets).insert(open_set_);
    member_scope_ = members_in;
  }

  void set_line(const Loc& loc) {
    const bool nodes = block_ == Block::NodeSet;
    const char* kind = nodes ? "node" : "element";
    std::vector<int>& members = *open_members_;
    if (generate_) {
      const auto& ids = nodes ? home().node_index : home().element_index;
      std::array<long, 3> g{0, 0, 1};
      const std::size_t n = fields_.size();
      if (n < 2 || n > 3) fail(loc, "a GENERATE data line needs 'first, last[, step]'", "write e.g. '1, 100, 1'");
      for (std::size_t i = 0; i < n; ++i) {
        const std::optional<long> v = parse_long(fields_[i]);
        if (!v)
          fail(loc, "GENERATE value '" + std::string(fields_[i]) + "' is not an integer",
               "write 'first, last[, step]'");
        g[i] = *v;
      }
      const auto [first, last, step] = g;
      if (first < 1 || step <= 0 || last < first)
        fail(loc,
             "GENERATE range " + std::to_string(first) + ", " + std::to_string(last) + ", " + std::to_string(step) +
                 " is empty or invalid",
             "give 1 <= first <= last and a positive step");
      const long count = (last - first) / step + 1;
      long found = 0;
      if (static_cast<std::size_t>(count) <= 4 * ids.size() + 64) {
        for (long k = 0; k < count; ++k) {
          const auto it = ids.find(first + k * step);
          if (it != ids.end()) {
            members.push_back(it->second);
            ++found;
          }
        }
      } else {  // huge sparse range: scan the defined ids instead
        const std::size_t before = members.size();
        for (const auto& [id, index] : ids)
          if (id >= first && id <= last && (id - first) % step == 0) members.push_back(index);
        std::sort(members.begin() + static_cast<std::ptrdiff_t>(before), members.end());  // hash order is arbitrary
        found = static_cast<long>(members.size() - before);
      }
      const long missing = count - found;
      if (missing > 0)
        deck_.warnings.push_back(at(loc) + "GENERATE " + std::to_string(first) + ", " + std::to_string(last) +
                                 ", " + std::to_string(step) + " of " + open_set_ + ": " + std::to_string(missing) +
                                 " undefined " + kind + " id(s) skipped");
      return;
    }
    for (const std::string_view f : fields_) {
      if (f.empty()) continue;
      if (const int index = find_id(nodes, f, loc, "set " + open_set_, "define it before this line or remove it from the set");
          index >= 0) {
        members.push_back(index);
      } else {
        const std::vector<int> other = named_set(nodes, f, loc, nodes ? "*NSET" : "*ELSET");  // copy: may be `members`
        members.insert(members.end(), other.begin(), other.end());
      }
    }
  }

  // ---- names and ids in data lines ------------------------------------------------------------
  // A data line names nodes, elements, sets and surfaces of its own scope: a part's (read for an
  // instance), an instance's, or the model/assembly level's. At the model/assembly level, as in
  // Abaqus, "Actuator-1.Set-1" and "Actuator-1.123" name an instance's set and id; a bare name
  // the assembly does not define is accepted for the one instance that defines it (several: an
  // error listing the choices), as the names the reader stores allow too (inp_assembly.h).

  Scope& scope() { return scopes_[static_cast<std::size_t>(scope_)]; }
  const Scope& scope() const { return scopes_[static_cast<std::size_t>(scope_)]; }
  /// The scope whose ids and names a data line uses: the instance of a set with INSTANCE=.
  int home_index() const { return member_scope_ >= 0 ? member_scope_ : scope_; }
  Scope& home() { return scopes_[static_cast<std::size_t>(home_index())]; }

  std::vector<std::string> instance_names() const {
    std::vector<std::string> out;
    for (std::size_t i = 1; i < scopes_.size(); ++i) out.push_back(scopes_[i].name);
    return out;
  }

  /// The instance named by the qualifier of "INSTANCE.REST" (at the model/assembly level), with
  /// `rest` set to REST; -1 if the token is not qualified by an instance.
  int qualifier(std::string_view token, std::string_view& rest) const {
    if (scope_ != 0 || instance_index_.empty()) return -1;
    const auto [instance, r] = inp::split_qualified(token);
    if (instance.empty()) return -1;
    const auto it = instance_index_.find(upper(instance));
    if (it == instance_index_.end()) return -1;
    rest = r;
    return it->second;
  }

  /// "123", or "Actuator-1.123" for an id of another scope than the line's own.
  std::string id_text(int scope, long id) const {
    return scope == scope_ ? std::to_string(id) : scopes_[static_cast<std::size_t>(scope)].name + "." + std::to_string(id);
  }

  /// Index of the node (or element) that `token` names by id ("123", or "Actuator-1.123"); -1 if
  /// the token is not an id. An undefined id is an error naming `context` and `todo`.
  int find_id(bool nodes, std::string_view token, const Loc& loc, const std::string& context, const std::string& todo) {
    int s = home_index();
    std::string_view rest = token;
    if (const int q = qualifier(token, rest); q >= 0) s = q;
    const std::optional<long> id = parse_long(rest);
    if (!id) return -1;
    const Scope& sc = scopes_[static_cast<std::size_t>(s)];
    const auto& ids = nodes ? sc.node_index : sc.element_index;
    const auto it = ids.find(*id);
    if (it != ids.end()) return it->second;
    std::string hint = todo;
    if (s == 0 && !instance_index_.empty())
      hint += "; at the assembly level a bare id names an assembly-level " + std::string(nodes ? "node" : "element") +
              ": write <instance>." + std::to_string(*id) + " (e.g. " + scopes_[1].name + "." + std::to_string(*id) +
              ") or put INSTANCE= on the set";
    fail(loc, std::string(nodes ? "node " : "element ") + id_text(s, *id) + " in " + context + " is not defined", hint);
  }

  /// The set (or surface) of `names` that `token` names, or nullptr; an ambiguous bare name is
  /// an error listing the qualified choices.
  template <class V>
  V* find_named(std::map<std::string, V> Scope::*names, std::string_view token, const Loc& loc,
                const std::string& context, const std::string& kind) {
    std::string_view rest;
    if (const int q = qualifier(token, rest); q >= 0) {
      auto& m = scopes_[static_cast<std::size_t>(q)].*names;
      const auto it = m.find(upper(rest));
      return it == m.end() ? nullptr : &it->second;
    }
    const std::string key = upper(token);
    const int h = home_index();
    auto& own = scopes_[static_cast<std::size_t>(h)].*names;
    if (const auto it = own.find(key); it != own.end()) return &it->second;
    if (h != 0) return nullptr;
    std::vector<std::size_t> in;
    for (std::size_t i = 1; i < scopes_.size(); ++i)
      if ((scopes_[i].*names).count(key)) in.push_back(i);
    if (in.empty()) return nullptr;
    if (in.size() > 1) {
      std::vector<std::string> instances, choices;
      for (std::size_t i : in) {
        instances.push_back(scopes_[i].name);
        choices.push_back(scopes_[i].name + "." + std::string(token));
      }
      fail(loc, kind + " '" + std::string(token) + "' in " + context + " is ambiguous: instances " +
                    inp::join_names(instances) + " each define one",
           "name one with its instance: " + inp::join_names(choices, " or "));
    }
    return &(scopes_[in[0]].*names).at(key);
  }

  /// Members of the node (or element) set named `name`; error naming `context` when unknown.
  const std::vector<int>& named_set(bool nodes, std::string_view name, const Loc& loc, const std::string& context) {
    const std::string kind = nodes ? "node" : "element";
    if (std::vector<int>* set = find_named(nodes ? &Scope::node_sets : &Scope::element_sets, name, loc, context,
                                           kind + " set")) {
      if (unsorted_.erase(set) != 0) normalise(*set);
      return *set;
    }
    if (find_named(nodes ? &Scope::element_sets : &Scope::node_sets, name, loc, context, kind + " set"))
      fail(loc,
           "'" + std::string(name) + "' in " + context +
               (nodes ? " is an element set, not a node set" : " is a node set, not an element set"),
           "use a " + kind + " set here");
    fail(loc, "unknown " + kind + " set '" + std::string(name) + "' in " + context,
         "define it with *" + std::string(nodes ? "NSET" : "ELSET") + (nodes ? "" : " (or ELSET= on *ELEMENT)") +
             " before this line; set names are case-insensitive" +
             (instance_index_.empty() || scope_ != 0 ? "" : "; an instance's set is <instance>.<set> here"));
  }

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
  void open_set(std::map<std::string, std::vector<int>>& sets, const std::string& name) {
    open_set_ = upper(name);
    open_members_ = open_set_.empty() ? nullptr : &sets[open_set_];
  }

  static void normalise(std::vector<int>& v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
  }

  // ---- *SURFACE -----------------------------------------------------------------------------
  void begin_surface(const Keyword& kw, const Loc& loc) {
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
  void surface_line(const Loc& loc) {
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
  void check_face(int e, int face, const std::string& label, const Loc& loc) const {
    const SolidType t = solids_.type[static_cast<std::size_t>(e)];
    const int faces = solid_faces(t);
    if (face >= faces)
      fail(loc,
           label + " names face " + std::to_string(face + 1) + " of element " + element_name(e) + ", a " +
               solid_name(t) + " with faces 1-" + std::to_string(faces),
           "use " + label.substr(0, 1) + "1.." + label.substr(0, 1) + std::to_string(faces) + " for that element");
  }

  // ---- *DLOAD -------------------------------------------------------------------------------
  void dload_line(const Loc& loc) {
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
  std::optional<double> magnitude(const std::string& keyword, const std::string& label, const std::string& first,
                                  const Loc& loc) const {
    if (fields_.size() < 3 || fields_[2].empty())
      fail(loc, keyword + " " + label + " without a magnitude", "write '" + first + ", " + label + ", magnitude'");
    const std::optional<double> p = parse_double(fields_[2]);
    if (!p) fail(loc, keyword + " magnitude '" + std::string(fields_[2]) + "' is not a finite number", "fix the value");
    return p;
  }

  /// Each (element, face) once, the first magnitude kept (a differing repeat warns).
  void add_pressure(const FaceRef& f, double p, const std::string& label, const Loc& loc) {
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
  void dsload_line(const Loc& loc) {
    if (fields_.size() < 2 || fields_[1].empty())
      fail(loc, "a *DSLOAD data line needs a load label", "write 'surface, P, magnitude'");
    const std::string label = upper(fields_[1]);
    if (label != "P") {
      warn_once("dsload " + label, loc, "*DSLOAD load type " + label + " skipped (only the pressure P is read)");
      return;
    }
    const std::optional<double> p = magnitude("*DSLOAD", label, "surface", loc);
    const std::vector<FaceRef>* faces = find_named(&Scope::surfaces, fields_[0], loc, "*DSLOAD", "surface");
    if (!faces)
      fail(loc, "unknown surface '" + std::string(fields_[0]) + "' in *DSLOAD",
           "define it with *SURFACE, TYPE=ELEMENT, NAME=" + std::string(fields_[0]) + " before this line" +
               (instance_index_.empty() ? std::string() : " (an instance's surface is <instance>.<surface> here)"));
    const std::vector<FaceRef> copy = *faces;
    for (const FaceRef& f : copy) add_pressure(f, *p, "S" + std::to_string(f.local_face + 1), loc);
  }

  // ---- *BOUNDARY ----------------------------------------------------------------------------
  void boundary_line(const Loc& loc) {
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

  // ---- end of deck --------------------------------------------------------------------------
  void finish() {
    Mesh& mesh = deck_.mesh;
    const Loc end{0, std::max(1, last_line_of_top_)};
    std::vector<std::string> unused_parts;
    for (const auto& [key, part] : parts_)
      if (!part.instanced) unused_parts.push_back(part.name);
    if (!unused_parts.empty() && instance_index_.empty() && solids_.size() == 0) {
      const PartDef& p = parts_.begin()->second;
      fail(p.loc, "part '" + p.name + "' is defined but never instanced, so the deck has no mesh",
           "instance it: *Assembly, name=Assembly / *Instance, name=" + p.name + "-1, part=" + p.name +
               " / *End Instance / *End Assembly");
    }
    if (!unused_parts.empty())
      deck_.warnings.push_back(file_names_[0] + ": part(s) " + inp::join_names(unused_parts) +
                               " never instanced: their mesh is not read");
    if (mesh.num_nodes() == 0) fail(end, "the deck defines no nodes", "add a *NODE block with 'id, x, y, z' lines");
    if (solids_.size() == 0)
      fail(end, "the deck defines no elements", "add an *ELEMENT, TYPE=C3D4 or TYPE=C3D10 block");
    for (Scope& s : scopes_) {
      for (auto& [name, v] : s.node_sets) normalise(v);
      for (auto& [name, v] : s.element_sets) normalise(v);
    }
    split();
    resolve_surface_elements();
    for (Scope& s : scopes_)
      for (auto& [name, faces] : s.surfaces) {  // a face listed twice would be loaded twice
        std::unordered_set<long long> seen;
        std::erase_if(faces, [&](const FaceRef& f) {
          return !seen.insert(static_cast<long long>(f.element) * 4 + f.local_face).second;
        });
      }
    export_names();
    check_instances();
    number_scopes();
    // Advice the solver would otherwise give far less clearly.
    std::vector<char> used(static_cast<std::size_t>(mesh.num_nodes()), 0);
    for (int n : mesh.conn) used[static_cast<std::size_t>(n)] = 1;
    const auto unused = std::count(used.begin(), used.end(), 0);
    if (unused > 0)
      deck_.warnings.push_back(file_names_[0] + ": " + std::to_string(unused) +
                               " node(s) belong to no element (they carry no stiffness)");
    int inverted = 0;
    int first_inverted = 0;
    for (int e = 0; e < mesh.num_elements(); ++e)
      if (corner_volume(mesh, e) <= 0.0 && inverted++ == 0) first_inverted = e;
    if (inverted > 0)
      deck_.warnings.push_back(file_names_[0] + ": " + std::to_string(inverted) +
                               " element(s) have zero or negative volume (first: element " +
                               mesh.element_name(first_inverted) + "); check the node order");
    mesh.ensure_ids();
  }

  /// Hexahedra, wedges and pyramids -> tetrahedra (solid_split.h), those of every instance and of
  /// the model/assembly level at once, so the sets and surfaces of every scope and the pressure
  /// faces follow the split. New ids continue each scope's own (number_scopes offsets them later).
  void split() {
    SplitSets sets;
    for (Scope& s : scopes_) {
      sets.node_sets.push_back(&s.node_sets);
      sets.element_sets.push_back(&s.element_sets);
      sets.surfaces.push_back(&s.surfaces);
    }
    split_solids(solids_, deck_, [&](int s) { return solid_where(s); }, sets);
    const Mesh& mesh = deck_.mesh;
    for (std::size_t e = 0; e < mesh.element_ids.size(); ++e) {
      long& last = scopes_[mesh.element_scope[e]].max_element_id;
      last = std::max(last, mesh.element_ids[e]);
    }
    for (std::size_t n = 0; n < mesh.node_ids.size(); ++n) {
      long& last = scopes_[mesh.node_scope[n]].max_node_id;
      last = std::max(last, mesh.node_ids[n]);
    }
  }

  /// Where solid element s was read, "<file>:<line>", and the part and instance when it is a
  /// part's line read for an instance.
  std::string solid_where(int s) const {
    const std::size_t i = static_cast<std::size_t>(s);
    const std::string w = where(solid_loc_[i]);
    const std::uint16_t instance = solid_part_instance_[i];
    return instance == 0 ? w : w + ": " + part_context(scopes_[instance]);
  }

  /// The Mesh's set and surface names (inp_assembly.h): the model/assembly level's as they are,
  /// an instance's qualified and, when unambiguous, bare; INTERNAL ones not at all.
  void export_names() {
    std::vector<inp::ScopedNames<std::vector<int>>> nsets, elsets;
    std::vector<inp::ScopedNames<std::vector<FaceRef>>> surfaces;
    for (std::size_t i = 0; i < scopes_.size(); ++i) {
      const Scope& s = scopes_[i];
      const std::string prefix = i == 0 ? std::string() : upper(s.name) + ".";
      nsets.push_back({prefix, &s.node_sets, &s.internal_node_sets});
      elsets.push_back({prefix, &s.element_sets, &s.internal_element_sets});
      surfaces.push_back({prefix, &s.surfaces, &s.internal_surfaces});
    }
    deck_.mesh.node_sets = inp::export_names(nsets);
    deck_.mesh.element_sets = inp::export_names(elsets);
    deck_.mesh.surfaces = inp::export_names(surfaces);
  }

  /// Scopes that hold nodes or elements.
  int scopes_with_mesh() const {
    return static_cast<int>(std::count_if(scopes_.begin(), scopes_.end(), [](const Scope& s) { return s.nodes > 0; }));
  }

  /// Element e as the user knows it: "123", or "Actuator-1.123" once the deck has more than one
  /// id scope with a mesh so far (as Mesh::element_name will name it; ids are still the deck's).
  std::string element_name(int e) const {
    const Mesh& mesh = deck_.mesh;
    const long id = mesh.element_ids[static_cast<std::size_t>(e)];
    if (scopes_with_mesh() <= 1) return std::to_string(id);
    return scopes_[mesh.element_scope[static_cast<std::size_t>(e)]].name + "." + std::to_string(id);
  }

  /// Ids are per instance in a deck: with several scopes holding a mesh, each gets an offset
  /// (the largest ids of the scopes before it) so the Mesh's ids are distinct, and the Mesh
  /// keeps the scopes for its labels; with one, the deck's ids stay as they are.
  void number_scopes() {
    Mesh& mesh = deck_.mesh;
    if (scopes_with_mesh() <= 1) {
      mesh.node_scope.clear();
      mesh.element_scope.clear();
      return;
    }
    long node_offset = 0, element_offset = 0;
    for (const Scope& s : scopes_) {
      mesh.id_scopes.push_back(Mesh::IdScope{s.name, node_offset, element_offset});
      node_offset += s.max_node_id;
      element_offset += s.max_element_id;
    }
    for (std::size_t n = 0; n < mesh.node_ids.size(); ++n) mesh.node_ids[n] += mesh.id_scopes[mesh.node_scope[n]].node_id_offset;
    for (std::size_t e = 0; e < mesh.element_ids.size(); ++e)
      mesh.element_ids[e] += mesh.id_scopes[mesh.element_scope[e]].element_id_offset;
    for (std::size_t e = 0; e < mesh.element_sources.size(); ++e)  // a split element's id, in the same scope
      mesh.element_sources[e].id += mesh.id_scopes[mesh.element_scope[e]].element_id_offset;
  }

  /// Instances never share nodes: several holding solid elements are separate bodies, which a
  /// *TIE in Abaqus may join but pneufem cannot (build_model refuses such a model).
  void check_instances() {
    std::vector<char> solid(scopes_.size(), 0);
    for (std::uint16_t s : deck_.mesh.element_scope) solid[s] = 1;
    for (std::size_t i = 0; i < scopes_.size(); ++i)
      if (solid[i] && (i > 0 || !instance_index_.empty())) deck_.solid_instances.push_back(scopes_[i].name);
    if (deck_.solid_instances.size() > 1)
      deck_.warnings.push_back(file_names_[0] + ": the solid elements are in " +
                               std::to_string(deck_.solid_instances.size()) + " instances (" +
                               inp::join_names(deck_.solid_instances) +
                               ") that share no node, so the mesh is not connected and pneufem cannot simulate it; "
                               "merge the instances in Abaqus (Merge/Cut Instances) so the mesh is conforming");
  }

  // ---- state --------------------------------------------------------------------------------
  double length_to_m_;
  InpDeck deck_;

  std::deque<std::string> buffers_;  // whole files; kept until the end (lines are views into them)
  std::vector<std::string> file_names_;
  std::vector<Frame> stack_;
  int last_line_of_top_ = 0;

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
  struct SurfaceTriangle {
    long id;
    Loc loc;
    std::array<int, 3> corners;  // node indices
  };
  std::map<std::pair<int, std::string>, std::vector<SurfaceTriangle>> surface_elements_;  // (scope, ELSET) -> triangles
  std::string surface_set_;  // ELSET of the surface element block being read
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

  std::unordered_map<long long, std::size_t> load_index_;
  std::unordered_set<long long> fixed_;
  std::set<std::string> warned_;
};

// ---------------------------------------------------------------------------------------------
// Writer
// ---------------------------------------------------------------------------------------------

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
    throw InputError(std::string(what) + " name '" + name + "' cannot be written to an .inp deck; rename it (1-80 " +
                     "characters starting with a letter, no blanks, commas, '=', '*' or quotes)");
  return u;
}

/// Set members, at most 16 per data line.
void write_id_lines(std::ostream& os, const std::vector<long>& ids) {
  for (std::size_t i = 0; i < ids.size(); ++i)
    os << ids[i] << ((i + 1) % kMaxEntriesPerLine == 0 || i + 1 == ids.size() ? "\n" : ", ");
}

}  // namespace

InpDeck read_inp(const std::string& path, double length_to_m) {
  if (!(length_to_m > 0.0) || !std::isfinite(length_to_m))
    throw InputError(path + ": length_to_m = " + std::to_string(length_to_m) +
                     " is not a positive length; give the deck's length unit in metres (1e-3 for mm)");
  return DeckReader(length_to_m).read(path);
}

void write_inp_mesh(std::ostream& os, const Mesh& mesh, double length_to_m) {
  if (!(length_to_m > 0.0) || !std::isfinite(length_to_m))
    throw InputError("write_inp_mesh: length_to_m = " + std::to_string(length_to_m) +
                     " is not a positive length; give the deck's length unit in metres (1e-3 for mm)");
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
      throw InputError("write_inp_mesh: node " + std::to_string(node_id(static_cast<int>(i))) +
                       " has a non-finite coordinate; fix the mesh before writing it");
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

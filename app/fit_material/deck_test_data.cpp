#include "app/fit_material/deck_test_data.h"

#include <optional>
#include <string_view>

#include "core/errors.h"
#include "core/number_text.h"
#include "scenes/inp/text.h"

namespace pneufem {

namespace {

using inp::Keyword;
using inp::Loc;

/// The --model word of a *HYPERELASTIC line with TEST DATA INPUT.
std::string law_of(const Keyword& kw, const std::string& where) {
  const auto flag = [&](const std::string& f) { return kw.has(f); };
  const std::string n = kw.has("N") ? kw.get("N") : "1";
  if (flag("YEOH")) return "yeoh";
  if (flag("NEO HOOKE")) return "neo_hookean";
  if (flag("MOONEY-RIVLIN")) return "mooney_rivlin";
  if (flag("OGDEN")) {
    if (n != "1" && n != "2" && n != "3")
      throw InputError(where + ": *HYPERELASTIC, OGDEN, N=" + n + ": pneufem's Ogden law has 1 to 3 terms; use N=1, 2 or 3");
    return "ogden" + n;
  }
  if (flag("POLYNOMIAL") || flag("REDUCED POLYNOMIAL")) {
    if (n != "1")
      throw InputError(where + ": *HYPERELASTIC, " + std::string(flag("POLYNOMIAL") ? "POLYNOMIAL" : "REDUCED POLYNOMIAL") +
                       ", N=" + n + ": pneufem fits N=1 (Mooney-Rivlin / neo-Hookean) and YEOH (reduced polynomial N=3); "
                       "pass --model to choose");
    return flag("POLYNOMIAL") ? "mooney_rivlin" : "neo_hookean";
  }
  for (const char* other : {"ARRUDA-BOYCE", "VAN DER WAALS", "MARLOW", "HYPERFOAM", "USER"})
    if (flag(other))
      throw InputError(where + ": *HYPERELASTIC, " + std::string(other) +
                       ": pneufem has no such law; pass --model yeoh, neo_hookean, mooney_rivlin or ogdenN to fit one it has");
  return "mooney_rivlin";  // no law named: Abaqus's default, POLYNOMIAL with N = 1
}

/// The reader's state between lines: the materials read so far and the block being filled.
class DeckParser {
 public:
  explicit DeckParser(double stress_scale) : scale_(stress_scale) {}

  void keyword(const Keyword& kw, const std::string& where) {
    block_ = Block::none;
    if (kw.name == "MATERIAL") {
      material_ = kw.get("NAME");
      test_data_input_ = false;
    } else if (kw.name == "HYPERELASTIC") {
      test_data_input_ = kw.has("TEST DATA INPUT");
      if (test_data_input_) out_.push_back(DeckTestData{material_, law_of(kw, where), where, {}, {}});
    } else if (kw.name == "UNIAXIAL TEST DATA" || kw.name == "BIAXIAL TEST DATA" || kw.name == "PLANAR TEST DATA" ||
               kw.name == "VOLUMETRIC TEST DATA") {
      begin_test_data(kw.name, where);
    }
  }

  void data_line(std::string_view text, const std::string& where, int line) {
    if (block_ == Block::none) return;
    inp::split_fields(text, fields_, trailing_);
    if (block_ == Block::volumetric) {
      const double p = number(0, "pressure", where) * scale_, J = number(1, "volume ratio", where);
      if (!(J > 0.0)) throw InputError(where + ": volume ratio " + short_num(J) + " <= 0 is impossible");
      out_.back().volumetric.back().points.push_back({J, p, line});
      return;
    }
    fit::TestCurve& curve = out_.back().tests.back();
    const double P = number(0, "nominal stress", where) * scale_, e = number(1, "nominal strain", where);
    if (e < 0.0)
      throw InputError(where + ": nominal strain " + short_num(e) + " is negative: fit-material fits tension data only; "
                       "remove the compression lines");
    if (!curve.points.empty() && e < curve.points.back().stretch - 1.0)
      throw InputError(where + ": the strain falls (" + short_num(e) + " after " +
                       short_num(curve.points.back().stretch - 1.0) + "): give the loading curve in order");
    if (e > 0.0 && P <= 0.0) return;  // as the CSV reader: an offset, not a pulling rubber
    curve.points.push_back({1.0 + e, P, line});
  }

  std::vector<DeckTestData>& result() { return out_; }

 private:
  enum class Block { none, tension, volumetric };

  void begin_test_data(const std::string& name, const std::string& where) {
    if (!test_data_input_ || out_.empty())
      throw InputError(where + ": *" + name + " outside a *HYPERELASTIC, TEST DATA INPUT of a *MATERIAL; put it after "
                       "that line (a *MULLINS EFFECT, TEST DATA INPUT is not read yet)");
    const std::string source = where + " (*MATERIAL " + material_ + ")";
    if (name == "VOLUMETRIC TEST DATA") {
      out_.back().volumetric.push_back({source, {}});
      block_ = Block::volumetric;
      return;
    }
    const fit::TestMode m = name[0] == 'U' ? fit::TestMode::uniaxial : name[0] == 'B' ? fit::TestMode::biaxial
                                                                                      : fit::TestMode::planar;
    out_.back().tests.push_back({m, source, {}});
    block_ = Block::tension;
  }

  double number(std::size_t i, const char* what, const std::string& where) const {
    const std::optional<double> v = i < fields_.size() ? inp::parse_double(fields_[i]) : std::nullopt;
    if (!v)
      throw InputError(where + ": field " + std::to_string(i + 1) + " (" + what + ") is not a number; a test data line is '" +
                       (block_ == Block::volumetric ? "pressure, volume ratio" : "nominal stress, nominal strain") + "'");
    return *v;
  }

  double scale_;
  std::vector<DeckTestData> out_;
  std::string material_;
  bool test_data_input_ = false;  // the current *MATERIAL's *HYPERELASTIC has TEST DATA INPUT
  Block block_ = Block::none;
  std::vector<std::string_view> fields_;
  bool trailing_ = false;
};

}  // namespace

std::vector<DeckTestData> read_deck_test_data(const std::string& path, const std::string& length_unit) {
  if (length_unit != "mm" && length_unit != "m")
    throw InputError("--deck-length-unit " + length_unit + ": use mm (the deck's stresses in MPa) or m (Pa)");
  inp::LineSource src(path);
  DeckParser parser(length_unit == "mm" ? 1e6 : 1.0);
  std::string_view text;
  Loc loc;
  while (src.next(text, loc)) {
    if (text.front() == '*') parser.keyword(inp::parse_keyword(text), src.where(loc));
    else parser.data_line(text, src.where(loc), loc.line);
  }
  return std::move(parser.result());
}

}  // namespace pneufem

#include "app/fit_material/deck_test_data.h"

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

}  // namespace

std::vector<DeckTestData> read_deck_test_data(const std::string& path, const std::string& length_unit) {
  if (length_unit != "mm" && length_unit != "m")
    throw InputError("--deck-length-unit " + length_unit + ": use mm (the deck's stresses in MPa) or m (Pa)");
  const double scale = length_unit == "mm" ? 1e6 : 1.0;
  inp::LineSource src(path);
  std::vector<DeckTestData> out;
  std::string material;
  bool test_data_input = false;  // the current *MATERIAL's *HYPERELASTIC has TEST DATA INPUT
  enum class Block { none, tension, volumetric } block = Block::none;
  fit::TestCurve* curve = nullptr;
  fit::VolumetricCurve* vol = nullptr;
  std::vector<std::string_view> fields;
  bool trailing = false;
  std::string_view text;
  Loc loc;
  while (src.next(text, loc)) {
    const std::string where = src.where(loc);
    if (text.front() == '*') {
      const Keyword kw = inp::parse_keyword(text);
      block = Block::none;
      if (kw.name == "MATERIAL") {
        material = kw.get("NAME");
        test_data_input = false;
      } else if (kw.name == "HYPERELASTIC") {
        test_data_input = kw.has("TEST DATA INPUT");
        if (test_data_input) out.push_back(DeckTestData{material, law_of(kw, where), where, {}, {}});
      } else if (kw.name == "UNIAXIAL TEST DATA" || kw.name == "BIAXIAL TEST DATA" || kw.name == "PLANAR TEST DATA" ||
                 kw.name == "VOLUMETRIC TEST DATA") {
        if (!test_data_input || out.empty())
          throw InputError(where + ": *" + kw.name + " outside a *HYPERELASTIC, TEST DATA INPUT of a *MATERIAL; put "
                           "it after that line (a *MULLINS EFFECT, TEST DATA INPUT is not read yet)");
        const std::string src_name = where + " (*MATERIAL " + material + ")";
        if (kw.name == "VOLUMETRIC TEST DATA") {
          out.back().volumetric.push_back({src_name, {}});
          vol = &out.back().volumetric.back();
          block = Block::volumetric;
        } else {
          const fit::TestMode m = kw.name[0] == 'U'   ? fit::TestMode::uniaxial
                                  : kw.name[0] == 'B' ? fit::TestMode::biaxial
                                                      : fit::TestMode::planar;
          out.back().tests.push_back({m, src_name, {}});
          curve = &out.back().tests.back();
          block = Block::tension;
        }
      }
      continue;
    }
    if (block == Block::none) continue;
    inp::split_fields(text, fields, trailing);
    const auto num = [&](std::size_t i, const char* what) {
      const std::optional<double> v = i < fields.size() ? inp::parse_double(fields[i]) : std::nullopt;
      if (!v)
        throw InputError(where + ": field " + std::to_string(i + 1) + " (" + what + ") is not a number; a test data "
                         "line is '" + (block == Block::volumetric ? "pressure, volume ratio" : "nominal stress, nominal strain") + "'");
      return *v;
    };
    if (block == Block::volumetric) {
      const double p = num(0, "pressure") * scale, J = num(1, "volume ratio");
      if (!(J > 0.0)) throw InputError(where + ": volume ratio " + short_num(J) + " <= 0 is impossible");
      vol->points.push_back({J, p, loc.line});
      continue;
    }
    const double P = num(0, "nominal stress") * scale, e = num(1, "nominal strain");
    if (e < 0.0)
      throw InputError(where + ": nominal strain " + short_num(e) + " is negative: fit-material fits tension data only; "
                       "remove the compression lines");
    if (!curve->points.empty() && e < curve->points.back().stretch - 1.0)
      throw InputError(where + ": the strain falls (" + short_num(e) + " after " +
                       short_num(curve->points.back().stretch - 1.0) + "): give the loading curve in order");
    if (e > 0.0 && P <= 0.0) continue;  // as the CSV reader: an offset, not a pulling rubber
    curve->points.push_back({1.0 + e, P, loc.line});
  }
  return out;
}

}  // namespace pneufem

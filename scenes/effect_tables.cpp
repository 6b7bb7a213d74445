#include "scenes/effect_tables.h"

#include <sstream>

#include "core/json_writer.h"

namespace pneufem {

namespace {

constexpr const char* kMarker = "# @effect-tables ";
constexpr std::size_t kCommentColumn = 38;  // as the hand-written tables of the default scene

/// `code` with `comment` aligned at kCommentColumn (one space after long code).
std::string commented(const std::string& code, const std::string& comment) {
  if (comment.empty()) return code + "\n";
  const std::size_t pad = code.size() < kCommentColumn ? kCommentColumn - code.size() : 1;
  return code + std::string(pad, ' ') + "# " + comment + "\n";
}

std::string calibration_range(const EffectParameter& p) {
  return "calibrated in " + json::num(p.lo) + " .. " + json::num(p.hi) + (p.log ? ", log scale" : "");
}

}  // namespace

std::string toml_float(double v) {
  std::string s = json::num(v);
  if (s.find_first_of(".en") == std::string::npos) s += ".0";  // "nan"/"inf" never reach a scene
  return s;
}

std::string toml_default(const EffectParameter& p) {
  std::string v = toml_float(p.default_value);
  if (p.per_term) {  // (not "[" + v + "]": GCC 12 warns of a false -Wrestrict there)
    v.insert(v.begin(), '[');
    v.push_back(']');
  }
  return v;
}

std::string effect_tables_toml(const std::string& material_table) {
  std::string out;
  for (const MaterialEffect* fx : material_effects()) {
    if (!is_builtin_effect(fx->name)) continue;
    if (!out.empty()) out += "\n";
    out += commented("[" + material_table + "." + fx->name + "]", fx->doc);
    out += "enabled = false\n";
    for (const EffectChoice& c : fx->choices) {
      std::string words;
      for (std::size_t i = 0; i < c.values.size(); ++i) words += (i ? " or \"" : "\"") + c.values[i] + "\"";
      out += commented(c.name + " = \"" + c.values.front() + "\"", words + ": " + c.doc);
    }
    for (const EffectParameter& p : fx->params) {
      out += commented(p.name + " = " + toml_default(p), p.doc + " (" + calibration_range(p) + ")");
    }
  }
  return out;
}

std::string expand_effect_tables(const std::string& text) {
  std::istringstream in(text);
  std::string out;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(kMarker, 0) == 0)
      out += effect_tables_toml(line.substr(std::string(kMarker).size()));
    else
      out += line + "\n";
  }
  return out;
}

}  // namespace pneufem

#include "scenes/scene_reference.h"

#include <sstream>
#include <utility>
#include <vector>

#include "core/json_writer.h"
#include "damage/registry.h"
#include "engine/load_history.h"
#include "scenes/default_scene_text.h"
#include "scenes/effect_tables.h"
#include "scenes/key_limits.h"

namespace pneufem {

namespace {

constexpr const char* kMarker = "# @effect-tables ";

std::string trim(const std::string& s) {
  const std::size_t a = s.find_first_not_of(" \t");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t") + 1 - a);
}

/// Comment text as Markdown: characters Markdown would read as table cells, emphasis or HTML escaped.
std::string cell(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '|': out += "\\|"; break;
      case '*': out += "\\*"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      default: out += c;
    }
  }
  return out;
}

/// Splits "code  # comment" at the first '#' outside a string; the comment without its "# ".
std::pair<std::string, std::string> split_comment(const std::string& line) {
  bool in_string = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    if (line[i] == '"') in_string = !in_string;
    if (line[i] == '#' && !in_string) return {trim(line.substr(0, i)), trim(line.substr(i + 1))};
  }
  return {trim(line), ""};
}

/// Accumulates the Markdown: per table a heading, its description, then rows of keys (a comment
/// block inside a table ends the rows and starts new ones after it).
class Writer {
 public:
  void section(const std::string& header, const std::string& comment) {
    close_rows();
    out_ << "## `" << header << "`\n\n";
    description_ = comment;
  }
  void prose(const std::string& text) {
    close_rows();
    out_ << cell(text) << "\n\n";
  }
  void row(const std::string& key, const std::string& value, const std::string& unit, const std::string& meaning) {
    open_rows("| key | default | unit | meaning |\n|---|---|---|---|\n");
    out_ << "| `" << key << "` | `" << cell(value) << "` | " << unit << " | " << cell(meaning);
  }
  void effect_row(const std::string& key, const std::string& value, const std::string& unit, const std::string& range,
                  const std::string& meaning) {
    open_rows("| key | default | unit | calibration range | meaning |\n|---|---|---|---|---|\n");
    out_ << "| `" << key << "` | `" << cell(value) << "` | " << unit << " | " << range << " | " << cell(meaning);
  }
  void limit_row(const std::string& pattern, const std::string& range, const std::string& why) {
    open_rows("| key | allowed | why |\n|---|---|---|\n");
    out_ << "| `" << pattern << "` | " << cell(range) << " | " << cell(why);
  }
  /// An indented comment line: continues the last row's meaning, or the table's description.
  void continue_text(const std::string& more) {
    if (row_open_)
      out_ << " " << cell(more);
    else if (!description_.empty() || !in_rows_)
      description_ += (description_.empty() ? "" : " ") + more;
  }
  void close_rows() {
    end_row();
    flush_description();
    if (in_rows_) out_ << "\n";
    in_rows_ = false;
  }
  std::string str() {
    close_rows();
    return out_.str();
  }

 private:
  void flush_description() {
    if (!description_.empty()) out_ << cell(description_) << "\n\n";
    description_.clear();
  }
  void end_row() {
    if (row_open_) out_ << " |\n";
    row_open_ = false;
  }
  void open_rows(const char* head) {
    end_row();
    flush_description();
    if (!in_rows_) out_ << head;
    in_rows_ = row_open_ = true;
  }
  std::ostringstream out_;
  std::string description_;  ///< the current table's, until its first row
  bool in_rows_ = false, row_open_ = false;
};

void effect_sections(Writer& w, const std::string& material_table) {
  for (const MaterialEffect* fx : material_effects()) {
    if (!is_builtin_effect(fx->name)) continue;
    w.section("[" + material_table + "." + fx->name + "]", fx->doc + ".");
    w.effect_row("enabled", "false", "", "", "switches the effect on");
    for (const EffectChoice& c : fx->choices) {
      std::string words;
      for (std::size_t i = 0; i < c.values.size(); ++i) words += (i ? " or `\"" : "`\"") + c.values[i] + "\"`";
      w.effect_row(c.name, "\"" + c.values.front() + "\"", "", "", words + ": " + c.doc);
    }
    for (const EffectParameter& p : fx->params) {
      const std::string value = toml_default(p);
      const std::string range = json::num(p.lo) + " – " + json::num(p.hi) + (p.log ? " (log)" : "");
      w.effect_row(p.name, value, p.unit == "1" ? "–" : p.unit, range, p.doc + (p.per_term ? "; a list, one per term" : ""));
    }
  }
  w.close_rows();
}

/// The ranges of scenes/key_limits.h, which every read of a numeric key checks.
void limits_section(Writer& w) {
  w.prose("## Allowed ranges");
  w.prose("Every number of a scene must be finite (no inf or nan) and every integer key a TOML integer (no "
          "decimal point or exponent) that fits 32 bits. The keys below must also lie in their range; a value "
          "outside is an error naming the key, where it was set, the value and the range (declared once, in "
          "scenes/key_limits.cpp). Checks that relate keys come on top: load.ramp_s < load.hold_s, at most " +
          json::num(kMaxStaircaseLevels) + " pressure levels and " + json::num(kMaxReports) +
          " reports per run (engine/load_history.h), the mesher's cell limit, and each law's and effect's own "
          "physics (C10 > 0, Mullins r > 1, ...).");
  for (const KeyLimit& l : key_limits()) w.limit_row(l.pattern, l.range_text(), l.why);
  w.close_rows();
}

}  // namespace

std::string unit_of_key(const std::string& key) {
  static const std::vector<std::pair<std::string, std::string>> kSuffixes = {
      {"_kg_m3", "kg/m³"}, {"_m_s2", "m/s²"}, {"_1_s", "1/s"}, {"_MPa", "MPa"}, {"_kPa", "kPa"},
      {"_mm", "mm"},       {"_deg", "deg"},   {"_s", "s"}};
  for (const auto& [suffix, unit] : kSuffixes)
    if (key.size() > suffix.size() && key.compare(key.size() - suffix.size(), suffix.size(), suffix) == 0) return unit;
  return "";
}

std::string scene_reference_markdown() {
  Writer w;
  std::istringstream in(kDefaultSceneText);
  std::string paragraph;  // a comment block at column 0
  auto flush_paragraph = [&] {
    if (!paragraph.empty()) w.prose(paragraph);
    paragraph.clear();
  };
  for (std::string line; std::getline(in, line);) {
    const std::string t = trim(line);
    if (t.empty()) {
      flush_paragraph();
    } else if (line.rfind(kMarker, 0) == 0) {
      flush_paragraph();
      effect_sections(w, line.substr(std::string(kMarker).size()));
    } else if (line[0] == '#') {
      if (!paragraph.empty()) paragraph += ' ';
      paragraph += trim(line.substr(1));
    } else if (t[0] == '#') {  // an indented comment continues the key (or the table) above it
      w.continue_text(trim(t.substr(1)));
    } else if (t[0] == '[') {
      flush_paragraph();
      const auto [header, comment] = split_comment(t);
      w.section(header, comment);
    } else {
      flush_paragraph();
      const auto [code, comment] = split_comment(t);
      const std::size_t eq = code.find('=');
      const std::string key = trim(code.substr(0, eq)), value = trim(code.substr(eq + 1));
      w.row(key, value, unit_of_key(key), comment);
    }
  }
  flush_paragraph();
  limits_section(w);
  return "# Scene reference\n\n"
         "Every key of a pneufem scene with its default, its unit and what it means. A scene file holds only the "
         "keys it changes; `--set key=value` overrides any of them; units are part of the key names and pneufem "
         "works in SI inside. This page is generated by `pneufem scene --reference` from the default scene "
         "(`scenes/data/default_scene.toml`) and, for the inelastic effects, from the effect registry "
         "(`damage/registry.cpp`), where each effect constant, its unit, default and calibration range are "
         "declared once; the ctest `scene_reference_is_current` fails when this file is out of date "
         "(regenerate it with `build/app/pneufem scene --reference > docs/scene_reference.md`). "
         "`pneufem scene --defaults` prints the default scene itself, a valid scene file.\n\n" +
         w.str();
}

}  // namespace pneufem

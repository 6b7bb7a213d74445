#include "app/fit_material/test_data.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <fstream>
#include <map>
#include <optional>

#include "core/errors.h"
#include "core/number_text.h"

namespace pneufem {

namespace {

using fit::TestMode;

/// The modes by the words that name them, in arguments and file names.
const std::vector<std::pair<std::string, TestMode>>& mode_words() {
  static const std::vector<std::pair<std::string, TestMode>> k = {
      {"uniaxial", TestMode::uniaxial},  {"equibiaxial", TestMode::biaxial}, {"biaxial", TestMode::biaxial},
      {"planar", TestMode::planar},      {"pure_shear", TestMode::planar},   {"pureshear", TestMode::planar}};
  return k;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

/// A column name as the reader compares it: lower case, spaces / brackets / '-' / '/' / '^' as
/// single '_', no leading or trailing '_'.
std::string normalise(const std::string& name) {
  std::string s;
  for (char c : lower(name)) {
    const bool sep = std::isspace(static_cast<unsigned char>(c)) || c == '(' || c == ')' || c == '[' || c == ']' ||
                     c == '-' || c == '/' || c == '^' || c == '_' || c == '"' || c == '\'';
    if (sep) {
      if (!s.empty() && s.back() != '_') s += '_';
    } else {
      s += c;
    }
  }
  while (!s.empty() && s.back() == '_') s.pop_back();
  return s;
}

/// What a header column holds.
struct Column {
  enum Kind { other, strain, stretch, stress, true_quantity, time, ratio, volume_ratio, pressure } kind = other;
  double scale = 1.0;  ///< to dimensionless strain or Pa
  std::string unit;    ///< as written after the quantity ("kpa", "%", "" = none)
  std::string name;    ///< as written in the header
};

Column classify(const std::string& raw) {
  Column c;
  c.name = raw;
  std::string s = normalise(raw);
  for (const char* p : {"true_", "cauchy_", "log_", "logarithmic_", "hencky_"})
    if (s.rfind(p, 0) == 0) {
      c.kind = Column::true_quantity;
      return c;
    }
  for (const char* p : {"nominal_", "engineering_", "eng_"})
    if (s.rfind(p, 0) == 0) s = s.substr(std::string(p).size());
  const auto unit_after = [&](const std::string& word) -> std::optional<std::string> {
    if (s == word) return std::string();
    if (s.rfind(word + "_", 0) == 0) return s.substr(word.size() + 1);
    return std::nullopt;
  };
  if (auto u = unit_after("strain")) {
    c.kind = Column::strain;
    c.unit = *u;
    if (u->empty() || *u == "mm_mm" || *u == "m_m" || *u == "1") c.scale = 1.0;
    else if (*u == "%" || *u == "percent" || *u == "pct") c.scale = 0.01;
    else c.scale = std::numeric_limits<double>::quiet_NaN();
    return c;
  }
  for (const char* w : {"stretch", "lambda", "stretch_ratio"})
    if (auto u = unit_after(w); u && (u->empty() || *u == "1")) {
      c.kind = Column::stretch;
      return c;
    }
  for (const char* w : {"g_r", "g", "normalized_modulus", "normalised_modulus", "modulus_ratio", "stress_ratio",
                        "relaxation_modulus_ratio", "normalized_stress", "normalised_stress"})
    if (s == w) {
      c.kind = Column::ratio;
      return c;
    }
  for (const char* w : {"volume_ratio", "volume_ratio_j", "j", "volumetric_ratio", "v_v0"})
    if (s == w) {
      c.kind = Column::volume_ratio;
      return c;
    }
  if (auto u = unit_after("time")) {
    static const std::map<std::string, double> kUnits = {{"s", 1.0}, {"sec", 1.0}, {"ms", 1e-3}, {"min", 60.0}, {"h", 3600.0}};
    c.kind = Column::time;
    c.unit = *u;
    const auto it = kUnits.find(*u);
    c.scale = it == kUnits.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
    return c;
  }
  std::optional<std::string> su = unit_after("stress");
  const bool is_pressure = !su && unit_after("pressure");
  if (is_pressure) su = unit_after("pressure");
  if (auto u = su) {
    static const std::map<std::string, double> kUnits = {
        {"pa", 1.0},     {"kpa", 1e3},    {"mpa", 1e6},   {"gpa", 1e9},  {"psi", 6894.757293168361},
        {"n_mm2", 1e6},  {"n_mm_2", 1e6}, {"n_m2", 1.0},  {"n_m_2", 1.0}};
    c.kind = is_pressure ? Column::pressure : Column::stress;
    c.unit = *u;
    const auto it = kUnits.find(*u);
    c.scale = it == kUnits.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
  }
  return c;
}

char delimiter_of(const std::string& line) {
  if (line.find(';') != std::string::npos) return ';';
  if (line.find(',') != std::string::npos) return ',';
  return ' ';
}

std::vector<std::string> split(const std::string& line, char d) {
  std::vector<std::string> out;
  if (d == ' ') {  // tabs or runs of spaces
    std::string cur;
    for (char c : line) {
      if (c == ' ' || c == '\t') {
        if (!cur.empty()) out.push_back(cur);
        cur.clear();
      } else {
        cur += c;
      }
    }
    if (!cur.empty()) out.push_back(cur);
    return out;
  }
  std::string cur;
  for (char c : line) {
    if (c == d) {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(cur);
  for (std::string& f : out) {  // trim
    while (!f.empty() && std::isspace(static_cast<unsigned char>(f.back()))) f.pop_back();
    std::size_t i = 0;
    while (i < f.size() && std::isspace(static_cast<unsigned char>(f[i]))) ++i;
    f = f.substr(i);
  }
  return out;
}

/// A whole cell as a number (decimal comma allowed with ';' and whitespace delimiters).
std::optional<double> number(std::string cell, char d) {
  if (d != ',') std::replace(cell.begin(), cell.end(), ',', '.');
  if (cell.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(cell.c_str(), &end);
  if (end != cell.c_str() + cell.size()) return std::nullopt;
  return v;
}

bool all_empty(const std::vector<std::string>& cells) {
  return std::all_of(cells.begin(), cells.end(), [](const std::string& c) { return c.empty(); });
}

/// Every non-empty cell is a number, and there is one.
bool all_numbers(const std::vector<std::string>& cells, char d) {
  for (const std::string& c : cells)
    if (!c.empty() && !number(c, d)) return false;
  return !all_empty(cells);
}

std::string where(const std::string& path, int line) { return path + ":" + std::to_string(line) + ": "; }

/// The strain (or stretch) and stress columns of a header line; throws on missing units, unknown
/// units, two columns for one quantity (mixed units).
struct Layout {
  int strain_col = -1, stress_col = -1;
  Column strain, stress;
};

Layout layout_of(const std::vector<Column>& cols, const std::string& path, int line, std::vector<std::string>& notes) {
  Layout l;
  std::vector<std::string> skipped;
  for (int i = 0; i < static_cast<int>(cols.size()); ++i) {
    const Column& c = cols[i];
    const bool is_strain = c.kind == Column::strain || c.kind == Column::stretch;
    if (c.kind == Column::true_quantity) skipped.push_back("'" + c.name + "'");
    if (!is_strain && c.kind != Column::stress) continue;
    int& slot = is_strain ? l.strain_col : l.stress_col;
    Column& kept = is_strain ? l.strain : l.stress;
    if (slot >= 0) {
      const bool mixed = kept.unit != c.unit || kept.kind != c.kind;
      throw InputError(where(path, line) + "columns '" + kept.name + "' and '" + c.name + "' both give the " +
                       (is_strain ? "strain" : "stress") +
                       (mixed ? " in different units (mixed units)" : "") + "; keep one of them");
    }
    slot = i;
    kept = c;
  }
  if (l.strain_col < 0 || l.stress_col < 0) return l;
  if (std::isnan(l.strain.scale))
    throw InputError(where(path, line) + "column '" + l.strain.name + "': unknown strain unit '" + l.strain.unit +
                     "'; write 'strain' (nominal, dimensionless), 'strain_percent' or 'stretch'");
  if (l.stress.unit.empty())
    throw InputError(where(path, line) + "column '" + l.stress.name + "' has no unit; name it stress_Pa, stress_kPa, "
                     "stress_MPa, stress_psi or stress_N_mm2 (nominal stress: force over the undeformed area)");
  if (std::isnan(l.stress.scale))
    throw InputError(where(path, line) + "column '" + l.stress.name + "': unknown stress unit '" + l.stress.unit +
                     "'; use Pa, kPa, MPa, GPa, psi or N_mm2");
  if (!skipped.empty()) {
    std::string s;
    for (const std::string& k : skipped) s += (s.empty() ? "" : ", ") + k;
    notes.push_back(path + ": true-stress/strain column(s) " + s + " skipped; fitted: '" + l.strain.name + "', '" +
                    l.stress.name + "' (nominal, as Abaqus's test data)");
  }
  return l;
}

/// The rows of a delimited file after its header: the first line (not '#', not blank) that
/// `is_header` accepts; lines before it that are not data (a machine's metadata block) are skipped and
/// counted, and a line of numbers before any header is an error (`example` shows a header).
struct Table {
  std::string path;
  char delimiter = ',';
  int header_line = 0;
  int skipped = 0;
  struct Row {
    int line;
    std::vector<std::string> cells;
  };
  std::vector<Row> rows;

  /// The number in column `col` of `row`, or an error naming the file, line and column.
  double number_at(const Row& row, int col, const Column& c) const {
    const std::optional<double> v = col < static_cast<int>(row.cells.size()) ? number(row.cells[col], delimiter) : std::nullopt;
    if (v && std::isfinite(*v)) return *v;
    const std::string cell = col < static_cast<int>(row.cells.size()) ? row.cells[col] : "";
    const bool unit_in_cell = cell.find_first_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ%") != std::string::npos;
    throw InputError(where(path, row.line) + "'" + cell + "' in column '" + c.name + "' is not a number" +
                     (unit_in_cell ? " (units belong in the header, e.g. stress_kPa, not in the cells)" : "") +
                     "; fix or remove the row");
  }
};

Table read_table(const std::string& path, const std::function<bool(const std::vector<Column>&, int)>& is_header,
                 const std::string& example) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the data file; check the path");
  Table t;
  t.path = path;
  std::string text;
  for (int line = 1; std::getline(in, text); ++line) {
    if (!text.empty() && text.back() == '\r') text.pop_back();
    if (line == 1 && text.rfind("\xEF\xBB\xBF", 0) == 0) text = text.substr(3);  // UTF-8 byte-order mark
    const std::size_t first = text.find_first_not_of(" \t");
    if (first == std::string::npos || text[first] == '#') continue;
    if (t.header_line == 0) {
      const char d = delimiter_of(text);
      const std::vector<std::string> cells = split(text, d);
      if (all_empty(cells)) continue;  // ";;;;": a spreadsheet's blank row
      if (all_numbers(cells, d))
        throw InputError(where(path, line) + "data before any header; the first line must name the columns with "
                         "their units, e.g. '" + example + "'");
      std::vector<Column> cols;
      for (const std::string& c : cells) cols.push_back(classify(c));
      if (!is_header(cols, line)) {
        if (++t.skipped > 200) break;
        continue;
      }
      t.header_line = line;
      t.delimiter = d;
      continue;
    }
    std::vector<std::string> cells = split(text, t.delimiter);
    if (!all_empty(cells)) t.rows.push_back({line, std::move(cells)});
  }
  if (t.header_line == 0)
    throw InputError(path + ": no header naming the columns with their units, e.g. '" + example +
                     "'; the file's first lines are not one");
  if (t.rows.empty()) throw InputError(path + ": no data rows after the header (line " + std::to_string(t.header_line) + ")");
  return t;
}

void note_skipped(const Table& t, std::vector<std::string>& notes) {
  if (t.skipped > 0)
    notes.push_back(t.path + ": " + std::to_string(t.skipped) + " line(s) before the header (line " +
                    std::to_string(t.header_line) + ") skipped");
}

}  // namespace

TestFileSpec parse_test_spec(const std::string& arg) {
  const std::size_t colon = arg.find(':');
  using Kind = TestFileSpec::Kind;
  if (colon != std::string::npos && lower(arg.substr(0, colon)) == "relaxation")
    return {TestMode::uniaxial, arg.substr(colon + 1), Kind::relaxation};
  if (colon != std::string::npos && lower(arg.substr(0, colon)) == "volumetric")
    return {TestMode::uniaxial, arg.substr(colon + 1), Kind::volumetric};
  if (colon != std::string::npos) {
    const std::string word = lower(arg.substr(0, colon));
    for (const auto& [w, m] : mode_words())
      if (word == w) return {m, arg.substr(colon + 1)};
  }
  const std::string name = lower(std::filesystem::path(arg).filename().string());
  std::optional<TestMode> found;
  for (const auto& [w, m] : mode_words()) {
    if (name.find(w) == std::string::npos) continue;
    if (w == "biaxial" && name.find("equibiaxial") != std::string::npos) continue;  // counted once
    if (found && *found != m) { found.reset(); break; }
    found = m;
  }
  const bool relaxation = name.find("relaxation") != std::string::npos;
  if (relaxation) return {TestMode::uniaxial, arg, Kind::relaxation};  // a held step of any specimen
  if (name.find("volumetric") != std::string::npos) return {TestMode::uniaxial, arg, Kind::volumetric};
  if (!found)
    throw InputError(arg + ": which test is it? Write uniaxial:" + arg + ", biaxial:" + arg + ", planar:" + arg +
                     ", relaxation:" + arg + " or volumetric:" + arg +
                     " (nominal stress against nominal strain, as Abaqus's *UNIAXIAL / *BIAXIAL / *PLANAR TEST DATA)");
  return {*found, arg};
}

fit::TestCurve read_test_csv(const std::string& path, TestMode mode, std::vector<std::string>& notes, double max_strain,
                             bool cycles) {
  Layout lay;
  const Table t = read_table(
      path,
      [&](const std::vector<Column>& cols, int line) {
        lay = layout_of(cols, path, line, notes);
        return lay.strain_col >= 0 && lay.stress_col >= 0;
      },
      "strain,stress_kPa' or 'stretch,stress_MPa");
  note_skipped(t, notes);
  fit::TestCurve curve{mode, path, {}};
  int dropped = 0, negative = 0, first_negative = 0, prev_line = 0;
  double prev_strain = -1.0;
  for (const Table::Row& row : t.rows) {
    const double x = t.number_at(row, lay.strain_col, lay.strain);
    const double P = t.number_at(row, lay.stress_col, lay.stress) * lay.stress.scale;
    const double strain = lay.strain.kind == Column::stretch ? x - 1.0 : x * lay.strain.scale;
    if (lay.strain.kind == Column::stretch && x <= 0.0)
      throw InputError(where(path, row.line) + "stretch " + short_num(x) + " <= 0 is impossible; the column '" +
                       lay.strain.name + "' must hold l = 1 + nominal strain");
    if (strain < 0.0)
      throw InputError(where(path, row.line) + "nominal strain " + short_num(strain) +
                       " is negative (compression, or an offset of the extensometer): fit-material fits tension "
                       "tests only; remove the compression rows or shift the strain so the test starts at 0");
    if (strain < prev_strain && !cycles)
      throw InputError(where(path, row.line) + "the strain falls from " + short_num(prev_strain) + " (line " +
                       std::to_string(prev_line) + ") to " + short_num(strain) +
                       ": not a loading curve (an unloading branch, a cycle, or unsorted rows). Keep the first "
                       "loading up to line " + std::to_string(prev_line) +
                       "; for loading-unloading cycles, fit the Mullins effect with --mullins");
    prev_strain = strain;
    prev_line = row.line;
    if (strain > max_strain) {
      ++dropped;
      continue;
    }
    if (strain > 0.0 && P <= 0.0) {  // a rubber in tension pulls: an offset or a slack specimen
      if (negative++ == 0) first_negative = row.line;
      continue;
    }
    curve.points.push_back({1.0 + strain, P, row.line});
  }
  if (curve.points.empty())
    throw InputError(path + ": no usable data rows after the header (line " + std::to_string(t.header_line) + ")" +
                     (dropped ? ": all above --max-strain " + short_num(max_strain) : std::string()));
  if (dropped)
    notes.push_back(path + ": " + std::to_string(dropped) + " point(s) above --max-strain " + short_num(max_strain) +
                    " left out");
  if (negative)
    notes.push_back(path + ":" + std::to_string(first_negative) + ": " + std::to_string(negative) +
                    " point(s) with zero or negative stress at a positive strain, the first here (a load-cell offset or "
                    "a slack specimen), left out: a rubber in tension pulls");
  return curve;
}

fit::RelaxationCurve read_relaxation_csv(const std::string& path, std::vector<std::string>& notes) {
  int time_col = -1, value_col = -1;
  Column time_c, value_c;
  const Table t = read_table(
      path,
      [&](const std::vector<Column>& cols, int line) {
        time_col = value_col = -1;
        for (int i = 0; i < static_cast<int>(cols.size()); ++i) {
          if (cols[i].kind == Column::time && time_col < 0) time_col = i, time_c = cols[i];
          if ((cols[i].kind == Column::ratio || cols[i].kind == Column::stress) && value_col < 0) value_col = i, value_c = cols[i];
        }
        if (time_col < 0 || value_col < 0) return false;
        if (std::isnan(time_c.scale))
          throw InputError(where(path, line) + "column '" + time_c.name + "': " +
                           (time_c.unit.empty() ? std::string("no time unit") : "unknown time unit '" + time_c.unit + "'") +
                           "; name it time_s, time_ms, time_min or time_h");
        if (value_c.kind == Column::stress && std::isnan(value_c.scale))
          throw InputError(where(path, line) + "column '" + value_c.name + "' needs a known stress unit (stress_kPa, "
                           "stress_MPa, ...), or give the normalised stress as g_R");
        return true;
      },
      "time_s,g_R' (the stress over the stress right after the step) or 'time_s,stress_kPa");
  note_skipped(t, notes);
  fit::RelaxationCurve curve{path, {}};
  double first_stress = 0.0, prev_t = -1.0;
  int prev_line = 0;
  for (const Table::Row& row : t.rows) {
    const double time = t.number_at(row, time_col, time_c) * time_c.scale, v = t.number_at(row, value_col, value_c);
    if (time < 0.0)
      throw InputError(where(path, row.line) + "time " + short_num(time) +
                       " s is negative: give the time since the step (the step at t = 0)");
    if (time <= prev_t)
      throw InputError(where(path, row.line) + "the time does not increase (" + short_num(time) + " s after " +
                       short_num(prev_t) + " s at line " + std::to_string(prev_line) + "); sort the rows or remove the repeat");
    prev_t = time;
    prev_line = row.line;
    double g = v;
    if (value_c.kind == Column::stress) {
      if (curve.points.empty()) {
        if (!(v > 0.0))
          throw InputError(where(path, row.line) + "the first stress, " + short_num(v) + " " + value_c.unit +
                           ", must be > 0: it normalises the curve (the stress right after the step)");
        first_stress = v;
        notes.push_back(path + ": stress normalised by its first row's (line " + std::to_string(row.line) + ", " +
                        short_num(v) + " " + value_c.unit + ", at t = " + short_num(time) + " s) as g_R(t)");
      }
      g = v / first_stress;
    }
    curve.points.push_back({time, g, row.line});
  }
  return curve;
}

fit::VolumetricCurve read_volumetric_csv(const std::string& path, std::vector<std::string>& notes) {
  int J_col = -1, p_col = -1;
  Column J_c, p_c;
  const Table t = read_table(
      path,
      [&](const std::vector<Column>& cols, int line) {
        J_col = p_col = -1;
        for (int i = 0; i < static_cast<int>(cols.size()); ++i) {
          if (cols[i].kind == Column::volume_ratio && J_col < 0) J_col = i, J_c = cols[i];
          if (cols[i].kind == Column::pressure && p_col < 0) p_col = i, p_c = cols[i];
        }
        if (J_col < 0 || p_col < 0) return false;
        if (p_c.unit.empty() || std::isnan(p_c.scale))
          throw InputError(where(path, line) + "column '" + p_c.name + "' needs a known unit: pressure_Pa, pressure_kPa, "
                           "pressure_MPa or pressure_psi");
        return true;
      },
      "volume_ratio,pressure_MPa");
  note_skipped(t, notes);
  fit::VolumetricCurve c{path, {}};
  for (const Table::Row& row : t.rows) {
    const double J = t.number_at(row, J_col, J_c), p = t.number_at(row, p_col, p_c) * p_c.scale;
    if (!(J > 0.0))
      throw InputError(where(path, row.line) + "volume ratio " + short_num(J) +
                       " <= 0 is impossible; the column '" + J_c.name + "' must hold J = V / V0");
    c.points.push_back({J, p, row.line});
  }
  return c;
}

}  // namespace pneufem

#include "analysis/measurements.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <climits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <system_error>

#include "analysis/csv_scan.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/message_text.h"

namespace pneufem {

namespace {

constexpr std::array<const char*, 4> kColumns = {"trial", "time_s", "pressure_kPa", "angle_deg"};
enum Col { kTrial = 0, kTime = 1, kPressure = 2, kAngle = 3 };

/// A column name with another unit that the reader converts: stem_unit (after canonical_name) and
/// the factor to the canonical unit. Exact SI/NIST factors (1 psi = 6.894757293168361 kPa).
struct UnitAlias {
  Col col;
  const char* name;
  double to_canonical;
};
constexpr std::array<UnitAlias, 10> kAliases = {{{kTime, "time_ms", 1e-3},
                                                 {kTime, "time_min", 60.0},
                                                 {kPressure, "pressure_pa", 1e-3},
                                                 {kPressure, "pressure_hpa", 0.1},
                                                 {kPressure, "pressure_mbar", 0.1},
                                                 {kPressure, "pressure_bar", 100.0},
                                                 {kPressure, "pressure_mpa", 1e3},
                                                 {kPressure, "pressure_psi", 6.894757293168361},
                                                 {kAngle, "angle_rad", 57.29577951308232},
                                                 {kTrial, "trial_number", 1.0}}};

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

/// A header name in the form the columns are matched in: "Time (s)", "time [s]" and "time_s" all
/// become "time_s" (lower case, brackets and blanks turned into single underscores).
std::string canonical_name(const std::string& header_name) {
  std::string out;
  for (char c : header_name) {
    if (c == ')' || c == ']') continue;
    if (c == '(' || c == '[' || c == ' ' || c == '\t') c = '_';
    if (c == '_' && (out.empty() || out.back() == '_')) continue;
    out += c;
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  return out;
}

/// The first header name (lower case, as csv::header_name gives them) that starts with the stem of
/// `column` ("pressure" for pressure_kPa: "pressure", "pressure_inh2o"), or nullptr.
const std::string* header_with_stem(const std::vector<std::string>& names, const std::string& column) {
  const std::string stem = lower(column.substr(0, column.find('_')));
  for (const std::string& n : names)
    if (n.rfind(stem, 0) == 0) return &n;
  return nullptr;
}

/// A hint for a missing required column: a header cell that shares its stem ("pressure" for
/// pressure_kPa) was probably meant, with another unit or none.
std::string missing_column_hint(const std::string& required, const std::vector<std::string>& names) {
  if (const std::string* n = header_with_stem(names, required))
    return "the header has '" + printable(*n, 40) + "': rename it to " + required +
           " (the unit is part of the name; convert the values if they are in another unit; units read and "
           "converted: time_s, time_ms, time_min; pressure_kPa, pressure_Pa, pressure_hPa, pressure_mbar, "
           "pressure_bar, pressure_MPa, pressure_psi; angle_deg, angle_rad)";
  return "add the column; the header must name trial,time_s,pressure_kPa,angle_deg (any order, "
         "other columns are ignored, cells of pressure_kPa or angle_deg may be empty)";
}

/// Where a continuous log of several staircases (no trial column, time_s never restarting) starts
/// its next trial: at each release, the first sample after the pressure has been above half the
/// record's peak, fallen below a tenth of it and settled at the rest level (within 2 % of the peak of
/// the median of the low stretch that follows, which lasts until the next rise past a tenth; a
/// trial's 0 kPa hold then begins its trial, as in the scene's staircase). The peak is the 99th
/// percentile, so a valve spike does not set it; a dip during a hold does not pass for a release,
/// since the low stretch must last kMinRest_s. Returns the split times in order (empty: one trial).
std::vector<double> release_times(const Series& p) {
  constexpr double kMinRest_s = 1.0;
  std::vector<double> out;
  if (p.value.size() < 10) return out;
  std::vector<double> sorted = p.value;
  const std::size_t q = static_cast<std::size_t>(0.99 * static_cast<double>(sorted.size() - 1));
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(q), sorted.end());
  const double peak = sorted[q];
  if (!(peak > 0.0)) return out;
  bool high = false;
  for (std::size_t i = 0; i < p.value.size(); ++i) {
    if (p.value[i] > 0.5 * peak) high = true;
    if (!high || p.value[i] >= 0.1 * peak) continue;
    std::size_t end = i;  // the low stretch: until the next rise past a tenth of the peak
    while (end < p.value.size() && p.value[end] < 0.1 * peak) ++end;
    if (p.t_s[end - 1] - p.t_s[i] < kMinRest_s) {
      i = end - 1;  // a dip, not a release (keep `high`)
      continue;
    }
    std::vector<double> low(p.value.begin() + static_cast<long>(i), p.value.begin() + static_cast<long>(end));
    std::nth_element(low.begin(), low.begin() + static_cast<long>(low.size() / 2), low.end());
    const double rest = low[low.size() / 2];
    std::size_t j = i;
    while (j + 1 < end && std::abs(p.value[j] - rest) > 0.02 * peak) ++j;
    if (end < p.value.size()) out.push_back(p.t_s[j]);  // a rest that ends the record starts no trial
    high = false;
    i = end - 1;
  }
  return out;
}

/// Splits the one trial of a continuous log at its releases (release_times); trial k's time_s
/// starts at 0 at its release (the first trial keeps the log's clock). A note says where.
void split_at_releases(Recording& rec) {
  const std::vector<double> cut = release_times(rec.trials[0].pressure_kPa);
  if (cut.empty()) return;
  const TrialRecording all = std::move(rec.trials[0]);
  rec.trials.assign(cut.size() + 1, TrialRecording{});
  for (std::size_t k = 0; k < rec.trials.size(); ++k) rec.trials[k].trial = static_cast<int>(k + 1);
  auto distribute = [&](const Series& s, Series TrialRecording::*member) {
    std::size_t k = 0;
    for (std::size_t i = 0; i < s.t_s.size(); ++i) {
      while (k < cut.size() && s.t_s[i] >= cut[k]) ++k;
      Series& d = rec.trials[k].*member;
      d.t_s.push_back(k == 0 ? s.t_s[i] : s.t_s[i] - cut[k - 1]);
      d.value.push_back(s.value[i]);
    }
  };
  distribute(all.pressure_kPa, &TrialRecording::pressure_kPa);
  distribute(all.angle_deg, &TrialRecording::angle_deg);
  std::string at;
  for (std::size_t k = 0; k < cut.size(); ++k) at += (k ? ", " : "") + csv::number_text(cut[k]);
  for (std::string& w : rec.warnings)
    if (w.find(": no trial column:") != std::string::npos)
      w = rec.source + ": no trial column and time_s never restarts: the log was split into " +
          std::to_string(cut.size() + 1) + " trials where the pressure is released (at time_s = " + at +
          "); each trial's time_s starts at 0 there. Give a trial column to number them yourself";
}

/// Per-stream bookkeeping while reading: order checks and repeated time stamps.
struct StreamState {
  int last_line = 0;
  int repeats = 0;
  int first_repeat_line = 0;
};

struct TrialState {
  TrialRecording rec;
  StreamState pressure, angle;
};

class CanonicalReader {
 public:
  CanonicalReader(std::string_view text, const std::string& source) : text_(text), source_(source) {}

  Recording read() {
    csv::LineCursor lines(text_);
    csv::Line line;
    if (!lines.next(line) || csv::trim(line.text).empty()) {
      csv::Line rest;
      bool only_blank = true;
      while (only_blank && lines.next(rest)) only_blank = csv::trim(rest.text).empty();
      if (only_blank)
        csv::fail(source_, 1, 1, "the file is empty",
                  "give a header line trial,time_s,pressure_kPa,angle_deg followed by one row per sample");
      csv::fail(source_, 1, 1, "the first line is blank",
                "put the header trial,time_s,pressure_kPa,angle_deg on line 1");
    }
    read_header(line);

    int skipped_rows = 0, first_skipped = 0, rows = 0;
    while (lines.next(line)) {
      if (csv::trim(line.text).empty()) continue;
      ++rows;
      if (!read_row(line) && skipped_rows++ == 0) first_skipped = line.number;
    }
    if (rows == 0)
      csv::fail(source_, line.number + 1, 1, "no data rows after the header",
                "add one row per sample: trial,time_s,pressure_kPa,angle_deg");
    if (trials_.empty())
      csv::fail(source_, first_skipped, 1,
                "no samples: none of the " + std::to_string(rows) + " data row(s) has " +
                    (no_pressure_column_ ? "an angle_deg" : "a pressure_kPa or angle_deg") + " value",
                "fill the pressure and angle cells (a row may leave one of them empty, not both)");

    Recording rec;
    rec.source = source_;
    rec.pressure_recorded = !no_pressure_column_;
    rec.warnings = conversions_;
    if (skipped_rows > 0)
      rec.warnings.push_back(source_ + ": " + std::to_string(skipped_rows) +
                             " row(s) with neither pressure_kPa nor angle_deg were skipped (first at line " +
                             std::to_string(first_skipped) + ")");
    for (auto& [number, index] : trial_index_) {
      TrialState& st = trials_[index];
      note_repeats(rec, st.rec.trial, "pressure", st.pressure);
      note_repeats(rec, st.rec.trial, "angle", st.angle);
      if (st.rec.pressure_kPa.t_s.empty() && !no_pressure_column_)
        rec.warnings.push_back(source_ + ": trial " + std::to_string(number) + " has no pressure_kPa samples");
      if (st.rec.angle_deg.t_s.empty())
        rec.warnings.push_back(source_ + ": trial " + std::to_string(number) + " has no angle_deg samples");
      rec.trials.push_back(std::move(st.rec));
    }
    if (auto_trials_ && rec.trials.size() == 1) split_at_releases(rec);
    return rec;
  }

 private:
  void read_header(const csv::Line& line) {
    csv::split(line.text, fields_);
    std::vector<std::string> names;
    for (std::string_view f : fields_) names.push_back(csv::header_name(f));
    header_names_.clear();
    for (std::string_view f : fields_) header_names_.emplace_back(csv::trim(f));
    column_.fill(-1);
    scale_.fill(1.0);
    for (std::size_t i = 0; i < names.size(); ++i) {
      // The canonical name, or another unit of the same quantity (converted on reading).
      const std::string name = canonical_name(names[i]);
      int c = -1;
      double factor = 1.0;
      for (std::size_t k = 0; k < kColumns.size(); ++k)
        if (name == lower(kColumns[k])) c = static_cast<int>(k);
      for (const UnitAlias& a : kAliases)
        if (name == a.name) c = a.col, factor = a.to_canonical;
      if (c < 0) continue;
      if (column_[c] >= 0)
        csv::fail(source_, line.number, static_cast<int>(i) + 1,
                  "column '" + std::string(kColumns[c]) + "' appears twice (also field " + std::to_string(column_[c] + 1) +
                      ")",
                  "keep one of them, or rename the other");
      column_[c] = static_cast<int>(i);
      scale_[c] = factor;
      if (factor != 1.0)
        conversions_.push_back(source_ + ": column '" + printable(header_names_[i], 40) + "' read as " + kColumns[c] +
                               " (values times " + csv::number_text(factor) + ")");
    }
    if (column_[kTrial] < 0 && column_[kTime] >= 0) {
      // No trial column (one trial, or trials one after another as some loggers write them): a
      // trial starts wherever time_s restarts.
      auto_trials_ = true;
      conversions_.push_back(source_ + ": no trial column: the trials are numbered 1, 2, ... where time_s restarts");
    }
    if (column_[kPressure] < 0 && !header_with_stem(names, kColumns[kPressure])) {
      // Angles alone (video tracking of a commanded protocol, as the seed paper's): the caller drives
      // the model with the scene's own [load] (app/simulate/drive.h, fill_commanded_pressure). A header that
      // names a pressure in an unknown unit is still an error below: that column was meant.
      no_pressure_column_ = true;
      conversions_.push_back(source_ + ": no pressure column: only angles were recorded; the model is driven by the "
                                       "scene's [load] protocol from time_s = 0 of every trial");
    }
    for (std::size_t c = 0; c < kColumns.size(); ++c) {
      if (column_[c] >= 0 || (c == kTrial && auto_trials_) || (c == kPressure && no_pressure_column_)) continue;
      std::string have;
      for (const std::string& n : header_names_) have += (have.empty() ? "" : ",") + n;
      csv::fail(source_, line.number, 1,
                "missing column '" + std::string(kColumns[c]) + "' (the header is '" + printable(have, 120) + "')",
                missing_column_hint(kColumns[c], names));
    }
    width_ = fields_.size();
  }

  /// The header's spelling of a column, for messages.
  std::string column_name(std::size_t field) const {
    return field < header_names_.size() && !header_names_[field].empty() ? printable(header_names_[field], 40)
                                                                         : "field " + std::to_string(field + 1);
  }

  [[noreturn]] void fail_field(const csv::Line& line, std::size_t field, const std::string& what,
                               const std::string& todo) const {
    csv::fail(source_, line.number, static_cast<int>(field) + 1, column_name(field) + " " + what, todo);
  }

  /// Number in a required or optional column; returns false for an empty optional cell.
  bool number(const csv::Line& line, int col, bool required, double& v) const {
    const std::size_t f = static_cast<std::size_t>(column_[col]);
    switch (csv::parse_double(fields_[f], v)) {
      case csv::Number::ok:
        if (scale_[col] != 1.0) v *= scale_[col];  // another unit of the column (kAliases)
        return true;
      case csv::Number::empty:
        if (!required) return false;
        fail_field(line, f, "is empty", "every row needs its " + std::string(kColumns[col]));
      case csv::Number::not_finite:
        fail_field(line, f, "= " + csv::quoted(fields_[f]) + " is not a finite number",
                   "write a measured value, or leave the cell empty when this row has no sample of that stream");
      case csv::Number::not_a_number: break;
    }
    fail_field(line, f, "= " + csv::quoted(fields_[f]) + " is not a number",
               "write a plain decimal number with '.' as the decimal point, e.g. 12.5 or 1.25e-3");
  }

  /// Returns false when the row carries neither pressure nor angle.
  bool read_row(const csv::Line& line) {
    csv::split(line.text, fields_);
    if (fields_.size() < width_)
      fail_field(line, fields_.size(),
                 "is missing: the row has " + std::to_string(fields_.size()) + " fields, the header " +
                     std::to_string(width_),
                 "give every row as many comma-separated fields as the header (leave cells empty, not out)");
    if (fields_.size() > width_)
      csv::fail(source_, line.number, static_cast<int>(width_) + 1,
                "the row has " + std::to_string(fields_.size()) + " fields, the header only " +
                    std::to_string(width_),
                "remove the extra fields or name them in the header (unnamed extra columns are not ignored)");

    long trial = 0;
    if (auto_trials_) {
      double t = 0.0;
      number(line, kTime, true, t);
      if (t < last_row_time_) ++auto_trial_;
      last_row_time_ = t;
      trial = auto_trial_;
    } else {
      read_trial(line, trial);
    }

    double t = 0.0, p = 0.0, a = 0.0;
    number(line, kTime, true, t);
    const bool has_p = !no_pressure_column_ && number(line, kPressure, false, p);
    const bool has_a = number(line, kAngle, false, a);
    if (!has_p && !has_a) return false;

    TrialState& st = trial_state(static_cast<int>(trial));
    if (has_p) append(line, st.rec.trial, "pressure", st.rec.pressure_kPa, st.pressure, t, p);
    if (has_a) append(line, st.rec.trial, "angle", st.rec.angle_deg, st.angle, t, a);
    return true;
  }

  void read_trial(const csv::Line& line, long& trial) {
    const std::size_t ft = static_cast<std::size_t>(column_[kTrial]);
    switch (csv::parse_int(fields_[ft], trial)) {
      case csv::Number::ok: break;
      case csv::Number::empty: fail_field(line, ft, "is empty", "every row needs its trial number");
      default:
        fail_field(line, ft, "= " + csv::quoted(fields_[ft]) + " is not an integer", "number the trials 1, 2, 3, ...");
    }
    if (trial < INT_MIN || trial > INT_MAX)
      fail_field(line, ft, "= " + csv::quoted(fields_[ft]) + " is out of range", "number the trials 1, 2, 3, ...");
  }

  TrialState& trial_state(int trial) {
    if (last_trial_index_ >= 0 && trials_[static_cast<std::size_t>(last_trial_index_)].rec.trial == trial)
      return trials_[static_cast<std::size_t>(last_trial_index_)];
    auto [it, inserted] = trial_index_.try_emplace(trial, trials_.size());
    if (inserted) {
      trials_.emplace_back();
      trials_.back().rec.trial = trial;
    }
    last_trial_index_ = static_cast<int>(it->second);
    return trials_[it->second];
  }

  void append(const csv::Line& line, int trial, const char* stream, Series& s, StreamState& st, double t, double v) {
    if (!s.t_s.empty() && t <= s.t_s.back()) {
      if (t == s.t_s.back()) {
        s.value.back() = v;  // a repeated time stamp: the last sample wins (documented, warned)
        if (st.repeats++ == 0) st.first_repeat_line = line.number;
        st.last_line = line.number;
        return;
      }
      fail_field(line, static_cast<std::size_t>(column_[kTime]),
                 "= " + csv::quoted(csv::trim(fields_[static_cast<std::size_t>(column_[kTime])])) +
                     " goes back in time: the previous " + stream + " sample of trial " + std::to_string(trial) +
                     " is at time_s = " + csv::number_text(s.t_s.back()) + " (line " + std::to_string(st.last_line) +
                     ")",
                 "sort each trial's rows by time; if a new trial starts here (time restarting), give it its own "
                 "trial number");
    }
    s.t_s.push_back(t);
    s.value.push_back(v);
    st.last_line = line.number;
  }

  void note_repeats(Recording& rec, int trial, const char* stream, const StreamState& st) const {
    if (st.repeats == 0) return;
    rec.warnings.push_back(source_ + ": trial " + std::to_string(trial) + ": " + std::to_string(st.repeats) +
                           " repeated " + stream + " time stamp(s) (first at line " +
                           std::to_string(st.first_repeat_line) + "); kept the last sample of each");
  }

  std::string_view text_;
  const std::string& source_;
  std::vector<std::string_view> fields_;
  std::vector<std::string> header_names_;
  std::array<int, 4> column_{};
  std::array<double, 4> scale_{};           ///< factor from the file's unit to the canonical one
  std::vector<std::string> conversions_;    ///< one note per converted column (or the trial numbering)
  bool auto_trials_ = false;                ///< no trial column: numbered where time_s restarts
  bool no_pressure_column_ = false;         ///< angles only: the scene's protocol gives the pressure
  long auto_trial_ = 1;
  double last_row_time_ = -INFINITY;
  std::size_t width_ = 0;
  std::vector<TrialState> trials_;
  std::map<int, std::size_t> trial_index_;  // ordered: the output is sorted by trial number
  int last_trial_index_ = -1;
};

}  // namespace

namespace {
/// The field separator of a file whose header (first non-blank line) has no comma: ';' (how
/// spreadsheets save "CSV" in locales with a decimal comma) or a tab; 0 for a comma-separated file.
char foreign_separator(std::string_view text) {
  csv::LineCursor lines(text);
  csv::Line line;
  while (lines.next(line)) {
    if (csv::trim(line.text).empty()) continue;
    if (line.text.find(',') != std::string_view::npos) return 0;
    if (line.text.find(';') != std::string_view::npos) return ';';
    if (line.text.find('\t') != std::string_view::npos) return '\t';
    return 0;
  }
  return 0;
}
}  // namespace

Recording parse_measurements_csv(std::string_view text, const std::string& source) {
  const char sep = foreign_separator(text);
  if (sep == 0) return CanonicalReader(text, source).read();
  // A ';'- or tab-separated file: its commas can only be decimal marks ("0,25"). One character
  // for one, so every line and column number in a message is the file's own.
  std::string comma_separated(text);
  long decimal_commas = 0;
  for (char& c : comma_separated) {
    if (c == ',') c = '.', ++decimal_commas;
    else if (c == sep) c = ',';
  }
  Recording rec = CanonicalReader(comma_separated, source).read();
  rec.warnings.insert(rec.warnings.begin(),
                      source + ": read as " + (sep == ';' ? "';'" : "tab") + "-separated" +
                          (decimal_commas > 0 ? ", with ',' as the decimal mark" : "") +
                          " (the header has no commas); check the values in the report");
  return rec;
}

Recording read_measurements_csv(const std::string& path) {
  const std::string text = csv::read_file(path);
  return parse_measurements_csv(text, path);
}

std::string format_measurements_csv(const Recording& rec) {
  std::vector<const TrialRecording*> order;
  std::size_t rows = 0;
  for (const TrialRecording& tr : rec.trials) {
    order.push_back(&tr);
    rows += tr.pressure_kPa.t_s.size() + tr.angle_deg.t_s.size();
  }
  std::stable_sort(order.begin(), order.end(),
                   [](const TrialRecording* a, const TrialRecording* b) { return a->trial < b->trial; });

  std::string out = "trial,time_s,pressure_kPa,angle_deg\n";
  out.reserve(out.size() + rows * 40);
  for (const TrialRecording* tr : order) {
    const std::string trial = std::to_string(tr->trial) + ",";
    const Series& p = tr->pressure_kPa;
    const Series& a = tr->angle_deg;
    std::size_t i = 0, j = 0;
    while (i < p.t_s.size() || j < a.t_s.size()) {
      const bool take_p = i < p.t_s.size() && (j >= a.t_s.size() || p.t_s[i] <= a.t_s[j]);
      const bool take_a = j < a.t_s.size() && (i >= p.t_s.size() || a.t_s[j] <= p.t_s[i]);
      out += trial;
      out += csv::number_text(take_p ? p.t_s[i] : a.t_s[j]);
      out += ',';
      if (take_p) out += csv::number_text(p.value[i++]);
      out += ',';
      if (take_a) out += csv::number_text(a.value[j++]);
      out += '\n';
    }
  }
  return out;
}

void write_measurements_csv(const std::string& path, const Recording& rec) {
  write_file_atomic(path, format_measurements_csv(rec));
}

}  // namespace pneufem

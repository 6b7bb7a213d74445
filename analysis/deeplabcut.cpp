#include "analysis/deeplabcut.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>

#include "analysis/csv_scan.h"
#include "core/errors.h"
#include "core/message_text.h"

namespace pneufem {

namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

void validate(const DlcMapping& map) {
  auto check_list = [](const std::vector<std::string>& parts, const char* name) {
    if (parts.size() < 2)
      throw InputError(std::string("DeepLabCut mapping: ") + name + " lists " + std::to_string(parts.size()) +
                       " body part(s); give at least 2 points rigidly attached to that end (their order sets the "
                       "direction of the line)");
    for (std::size_t i = 0; i < parts.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (parts[i] == parts[j])
          throw InputError(std::string("DeepLabCut mapping: ") + name + " lists '" + parts[i] +
                           "' twice; list each body part once");
  };
  check_list(map.fixed_parts, "fixed_parts");
  check_list(map.tip_parts, "tip_parts");
  for (const std::string& f : map.fixed_parts)
    if (std::find(map.tip_parts.begin(), map.tip_parts.end(), f) != map.tip_parts.end())
      throw InputError("DeepLabCut mapping: body part '" + f +
                       "' is in both fixed_parts and tip_parts; a point belongs to one end only");
  if (!(map.likelihood_cut >= 0.0 && map.likelihood_cut <= 1.0))
    throw InputError("DeepLabCut mapping: likelihood_cut = " + csv::number_text(map.likelihood_cut) +
                     " must lie in [0, 1] (DeepLabCut's likelihood is a probability; 0.9 is usual)");
  if (!(std::isfinite(map.fps) && map.fps > 0.0))
    throw InputError("DeepLabCut mapping: fps = " + csv::number_text(map.fps) +
                     " must be a positive frame rate (the paper's camera ran at 30 fps)");
  if (!std::isfinite(map.t0_s))
    throw InputError("DeepLabCut mapping: t0_s must be finite (the time of frame 0, in s)");
  if (map.zero_frames < 1)
    throw InputError("DeepLabCut mapping: zero_frames = " + std::to_string(map.zero_frames) +
                     " must be >= 1 (1 = zero at the first kept frame)");
  if (map.zero_raw_deg && !std::isfinite(*map.zero_raw_deg))
    throw InputError("DeepLabCut mapping: zero_raw_deg must be finite");
}

/// Columns of one body part (0-based field indices, -1 when absent).
struct PartColumns {
  std::array<int, 3> xyl{-1, -1, -1};
};

struct Point {
  double X = 0.0, Y = 0.0;  // image coordinates with Y = -y (Y up)
};

/// Unit direction of the least-squares line through `pts`, oriented from the first point towards
/// the last; false when the points (or the first and last) coincide.
bool line_direction(const std::vector<Point>& pts, double& dx, double& dy) {
  double cx = 0.0, cy = 0.0;
  for (const Point& p : pts) {
    cx += p.X;
    cy += p.Y;
  }
  cx /= static_cast<double>(pts.size());
  cy /= static_cast<double>(pts.size());
  double sxx = 0.0, syy = 0.0, sxy = 0.0;
  for (const Point& p : pts) {
    sxx += (p.X - cx) * (p.X - cx);
    syy += (p.Y - cy) * (p.Y - cy);
    sxy += (p.X - cx) * (p.Y - cy);
  }
  const double ex = pts.back().X - pts.front().X, ey = pts.back().Y - pts.front().Y;
  const double scale = std::abs(cx) + std::abs(cy) + 1.0;
  if (std::hypot(ex, ey) <= 1e-9 * scale) return false;
  // Principal axis of the 2x2 scatter matrix: angle phi with tan(2 phi) = 2 sxy / (sxx - syy).
  const double phi = 0.5 * std::atan2(2.0 * sxy, sxx - syy);
  dx = std::cos(phi);
  dy = std::sin(phi);
  if (dx * ex + dy * ey < 0.0) {
    dx = -dx;
    dy = -dy;
  }
  return true;
}

/// The representative of `wrapped` (mod 360) closest to `previous`.
double unwrap_deg(double wrapped, double previous) {
  return wrapped + 360.0 * std::round((previous - wrapped) / 360.0);
}

class DlcReader {
 public:
  DlcReader(std::string_view text, const std::string& source, const DlcMapping& map)
      : text_(text), source_(source), map_(map) {}

  Recording read() {
    validate(map_);
    csv::LineCursor lines(text_);
    csv::Line line;
    line.number = read_header(lines);

    std::vector<double> t, raw;
    std::vector<Point> fixed(map_.fixed_parts.size()), tip(map_.tip_parts.size());
    FrameCounts n;
    while (lines.next(line)) {
      if (csv::trim(line.text).empty()) continue;
      const long frame = frame_row(line, n);
      Status status = Status::ok;
      for (std::size_t k = 0; k < fixed.size(); ++k) status = worst(status, point(line, fixed_cols_[k], fixed[k]));
      for (std::size_t k = 0; k < tip.size(); ++k) status = worst(status, point(line, tip_cols_[k], tip[k]));
      if (status == Status::untracked) {
        ++n.untracked;
        continue;
      }
      if (status == Status::low) {
        if (n.low++ == 0) n.first_low_line = line.number;
        continue;
      }
      double fx = 0.0, fy = 0.0, tx = 0.0, ty = 0.0;
      if (!line_direction(fixed, fx, fy) || !line_direction(tip, tx, ty)) {
        ++n.degenerate;
        continue;
      }
      double a = std::atan2(fx * ty - fy * tx, fx * tx + fy * ty) * kDegPerRad;
      if (map_.positive == AngleSense::clockwise) a = -a;
      if (!raw.empty()) a = unwrap_deg(a, raw.back());
      t.push_back(map_.t0_s + static_cast<double>(frame) / map_.fps);
      raw.push_back(a);
    }
    if (n.frames == 0)
      csv::fail(source_, line.number + 1, 1, "no frame rows after the header rows",
                "give DeepLabCut's CSV output of a video analysis");
    if (raw.empty())
      csv::fail(source_, n.first_data_line, 1,
                "none of the " + std::to_string(n.frames) + " frames has all of the mapped body parts tracked above "
                    "likelihood " + csv::number_text(map_.likelihood_cut),
                "check that fixed_parts and tip_parts name the intended body parts, or lower likelihood_cut");

    Recording rec;
    rec.source = source_;
    if (n.low + n.untracked + n.degenerate > 0) rec.warnings.push_back(dropped_warning(n));
    const double zero = zero_reference(raw);
    TrialRecording tr;
    tr.trial = map_.trial;
    tr.angle_deg.t_s = std::move(t);
    tr.angle_deg.value.reserve(raw.size());
    for (double a : raw) tr.angle_deg.value.push_back(a - zero);
    rec.trials.push_back(std::move(tr));
    return rec;
  }

 private:
  /// The rows read so far: frames, and the frames dropped by why (with the first low one's line).
  struct FrameCounts {
    int frames = 0, low = 0, untracked = 0, degenerate = 0, first_low_line = 0;
    long previous_frame = 0;
    int previous_line = 0, first_data_line = 0;
  };

  /// Splits a frame row into fields_ and returns its frame index, checked: the header's width, an
  /// integer, after the previous frame's. Counts it in `n`.
  long frame_row(const csv::Line& line, FrameCounts& n) {
    if (n.first_data_line == 0) n.first_data_line = line.number;
    csv::split(line.text, fields_);
    if (fields_.size() != width_)
      csv::fail(source_, line.number, static_cast<int>(std::min(fields_.size(), width_)) + 1,
                "the row has " + std::to_string(fields_.size()) + " fields, the header rows " + std::to_string(width_),
                "give every frame the same columns as the header (frame, then x, y, likelihood per body part)");
    long frame = 0;
    if (csv::parse_int(fields_[0], frame) != csv::Number::ok)
      csv::fail(source_, line.number, 1, "frame index " + csv::quoted(fields_[0]) + " is not an integer",
                "give DeepLabCut's CSV from analyze_videos (its first column is the frame number)");
    if (n.frames > 0 && frame <= n.previous_frame)
      csv::fail(source_, line.number, 1,
                "frame " + std::to_string(frame) + " does not follow frame " + std::to_string(n.previous_frame) +
                    " (line " + std::to_string(n.previous_line) + ")",
                "keep the rows in frame order, one row per frame");
    n.previous_frame = frame;
    n.previous_line = line.number;
    ++n.frames;
    return frame;
  }

  /// The warning that lists the dropped frames by why.
  std::string dropped_warning(const FrameCounts& n) const {
    const int dropped = n.low + n.untracked + n.degenerate;
    std::string w = source_ + ": trial " + std::to_string(map_.trial) + ": dropped " + std::to_string(dropped) +
                    " of " + std::to_string(n.frames) + " frames:";
    if (n.low > 0)
      w += ' ' + std::to_string(n.low) + " with a mapped body part below likelihood " +
           csv::number_text(map_.likelihood_cut) + " (first at line " + std::to_string(n.first_low_line) + ");";
    if (n.untracked > 0) w += ' ' + std::to_string(n.untracked) + " with empty or NaN coordinates;";
    if (n.degenerate > 0) w += ' ' + std::to_string(n.degenerate) + " with coincident points of one end;";
    w.back() = '.';
    return w;
  }

  /// Zero reference (see the header): the raw angle that maps to 0 - map.zero_raw_deg (the raw
  /// angles then shifted to the first frame's branch nearest it) or the median of the first
  /// map.zero_frames kept frames.
  double zero_reference(std::vector<double>& raw) const {
    if (map_.zero_raw_deg) {
      const double zero = *map_.zero_raw_deg;
      const double shift = unwrap_deg(raw.front(), zero) - raw.front();  // first frame's branch nearest zero
      for (double& a : raw) a += shift;
      return zero;
    }
    std::vector<double> head(raw.begin(),
                             raw.begin() + static_cast<std::ptrdiff_t>(std::min<std::size_t>(
                                               raw.size(), static_cast<std::size_t>(map_.zero_frames))));
    const std::size_t mid = head.size() / 2;
    std::nth_element(head.begin(), head.begin() + static_cast<std::ptrdiff_t>(mid), head.end());
    double zero = head[mid];
    if (head.size() % 2 == 0)
      zero = 0.5 * (zero + *std::max_element(head.begin(), head.begin() + static_cast<std::ptrdiff_t>(mid)));
    return zero;
  }

  enum class Status { ok = 0, low = 1, untracked = 2 };
  static Status worst(Status a, Status b) { return static_cast<int>(a) >= static_cast<int>(b) ? a : b; }

  std::string column_name(std::size_t f) const {
    static const std::array<const char*, 3> coord = {"x", "y", "likelihood"};
    for (const auto& [part, cols] : parts_)
      for (std::size_t c = 0; c < 3; ++c)
        if (cols.xyl[c] == static_cast<int>(f)) return printable(part, 40) + " " + coord[c];
    return "field " + std::to_string(f + 1);
  }

  /// Reads one body part of the current row into `p`.
  Status point(const csv::Line& line, const PartColumns& cols, Point& p) const {
    std::array<double, 3> v{};
    Status status = Status::ok;
    for (std::size_t c = 0; c < 3; ++c) {
      const std::size_t f = static_cast<std::size_t>(cols.xyl[c]);
      switch (csv::parse_double(fields_[f], v[c])) {
        case csv::Number::ok: break;
        case csv::Number::empty:
        case csv::Number::not_finite: status = Status::untracked; break;
        case csv::Number::not_a_number:
          csv::fail(source_, line.number, static_cast<int>(f) + 1,
                    column_name(f) + " = " + csv::quoted(fields_[f]) + " is not a number",
                    "give DeepLabCut's numeric output (pixel coordinates and likelihoods)");
      }
    }
    if (status != Status::ok) return status;
    p.X = v[0];
    p.Y = -v[1];  // image y points down; Y = -y makes (X, Y) right-handed as seen on the screen
    return v[2] < map_.likelihood_cut ? Status::low : Status::ok;
  }

  /// Reads `scorer`, optional `individuals`, `bodyparts`, `coords` and resolves the mapped parts;
  /// returns the number of the last header line.
  int read_header(csv::LineCursor& lines) {
    csv::Line line;
    auto next_row = [&](const char* expected, bool optional) -> bool {
      if (!lines.next(line))
        csv::fail(source_, line.number + 1, 1,
                  line.number == 0 ? std::string("the file is empty")
                                   : std::string("the file ends inside the header rows"),
                  "give DeepLabCut's CSV: rows 'scorer', 'bodyparts', 'coords', then one row per frame");
      csv::split(line.text, fields_);
      const std::string first = csv::header_name(fields_[0]);
      if (first == expected) return true;
      if (optional) return false;
      csv::fail(source_, line.number, 1,
                "expected the header row '" + std::string(expected) + "', found " + csv::quoted(fields_[0]),
                "give DeepLabCut's CSV as written by analyze_videos (header rows scorer, bodyparts, coords)");
    };
    next_row("scorer", false);
    width_ = fields_.size();
    auto check_width = [&]() {
      if (fields_.size() != width_)
        csv::fail(source_, line.number, static_cast<int>(std::min(fields_.size(), width_)) + 1,
                  "the header row has " + std::to_string(fields_.size()) + " fields, the scorer row " +
                      std::to_string(width_),
                  "give header rows of equal width, as DeepLabCut writes them");
    };
    if (next_row("individuals", true)) {
      check_width();
      next_row("bodyparts", false);
    } else if (csv::header_name(fields_[0]) != "bodyparts") {
      csv::fail(source_, line.number, 1, "expected the header row 'bodyparts', found " + csv::quoted(fields_[0]),
                "give DeepLabCut's CSV as written by analyze_videos (header rows scorer, bodyparts, coords)");
    }
    check_width();
    const int parts_line = line.number;
    std::vector<std::string> parts;
    for (std::string_view f : fields_) parts.emplace_back(csv::trim(f));
    next_row("coords", false);
    check_width();
    const int coords_line = line.number;
    for (std::size_t f = 1; f < width_; ++f) {
      const std::string coord = csv::header_name(fields_[f]);
      const int c = coord == "x" ? 0 : coord == "y" ? 1 : coord == "likelihood" ? 2 : -1;
      if (c < 0)
        csv::fail(source_, coords_line, static_cast<int>(f) + 1,
                  "coordinate " + csv::quoted(fields_[f]) + " is not x, y or likelihood",
                  "give DeepLabCut's 2-D output (x, y, likelihood per body part)");
      PartColumns& pc = parts_[parts[f]];
      if (pc.xyl[static_cast<std::size_t>(c)] >= 0)
        csv::fail(source_, coords_line, static_cast<int>(f) + 1,
                  "body part '" + printable(parts[f], 40) + "' has a second '" + printable(coord, 40) +
                      "' column (field " +
                      std::to_string(pc.xyl[static_cast<std::size_t>(c)] + 1) + ")",
                  "a multi-animal file must track one actuator: export one individual, or rename the body parts");
      pc.xyl[static_cast<std::size_t>(c)] = static_cast<int>(f);
    }
    auto resolve = [&](const std::vector<std::string>& names, std::vector<PartColumns>& out, const char* list) {
      for (const std::string& n : names) {
        const auto it = parts_.find(n);
        if (it == parts_.end()) {
          std::string have;
          for (const auto& [part, cols] : parts_) have += (have.empty() ? "" : ", ") + part;
          csv::fail(source_, parts_line, 1,
                    std::string(list) + " names body part '" + n + "', which is not in the file (it has: " +
                        printable(have, 120) + ")",
                    "use the body-part names of the DeepLabCut project (case-sensitive)");
        }
        for (std::size_t c = 0; c < 3; ++c)
          if (it->second.xyl[c] < 0)
            csv::fail(source_, coords_line, 1,
                      "body part '" + n + "' has no '" + std::array<const char*, 3>{"x", "y", "likelihood"}[c] +
                          "' column",
                      "give DeepLabCut's 2-D output (x, y, likelihood per body part)");
        out.push_back(it->second);
      }
    };
    resolve(map_.fixed_parts, fixed_cols_, "fixed_parts");
    resolve(map_.tip_parts, tip_cols_, "tip_parts");
    return coords_line;
  }

  std::string_view text_;
  const std::string& source_;
  const DlcMapping& map_;
  std::vector<std::string_view> fields_;
  std::size_t width_ = 0;
  std::map<std::string, PartColumns> parts_;
  std::vector<PartColumns> fixed_cols_, tip_cols_;
};

}  // namespace

Recording parse_deeplabcut_csv(std::string_view text, const std::string& source, const DlcMapping& map) {
  return DlcReader(text, source, map).read();
}

Recording read_deeplabcut_csv(const std::string& path, const DlcMapping& map) {
  validate(map);  // mapping errors before file errors: they are fixed in a different place
  const std::string text = csv::read_file(path);
  return parse_deeplabcut_csv(text, path, map);
}

}  // namespace pneufem

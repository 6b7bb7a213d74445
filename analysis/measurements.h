#pragma once
// Measurements in: a user's recording of the staircase experiment (seed paper, "Data Collection
// and Control": inlet pressure sampled at 400 Hz, bending angle from DeepLabCut video at 30 fps,
// ten trials). The two streams keep their own time stamps; nothing is resampled here.
//
// Canonical CSV (what `read_measurements_csv` reads and `write_measurements_csv` writes):
//
//     trial,time_s,pressure_kPa,angle_deg
//     1,0,0.02,0.1
//     1,0.0025,0.01,
//     1,0.0333333,,0.12
//
//  * header names are case-insensitive and may come in any order; other columns are ignored;
//    a unit may be written in brackets ("Time (s)", "pressure [kPa]"), and columns in other units
//    are converted on reading, with a warning naming the column and the factor: time_ms, time_min;
//    pressure_Pa, pressure_hPa, pressure_mbar, pressure_bar, pressure_MPa, pressure_psi;
//    angle_rad; trial_number for trial. A name without a unit ("pressure") is an error;
//  * without a pressure column (and no other column named pressure...) only angles were recorded:
//    Recording::pressure_recorded is false and the pressure series are empty (a note says so);
//    compare and diagnose then drive the model with the scene's own [load] from time_s = 0;
//  * without a trial column the trials are numbered 1, 2, ... where time_s restarts (a note says so);
//    a continuous log whose time_s never restarts is split where its pressure is released (the
//    first sample settled at the rest level after a fall from above half the peak; each trial's
//    time_s then starts at 0 there; a note gives the times);
//    an optional UTF-8 byte-order mark and CRLF line ends are accepted;
//  * a file whose header has no commas but ';' or tabs (how spreadsheets in decimal-comma locales
//    save CSV) is read with that separator and ',' as the decimal mark, with a note;
//  * one row per time stamp; the pressure and angle streams have different rates, so either cell
//    may be empty (a row with both empty is skipped with a warning);
//  * time_s restarts (typically at 0) for every trial; within a trial the pressure samples must
//    be in time order and so must the angle samples (the streams may be interleaved in any way);
//    a repeated time stamp keeps the last sample, with one warning per trial and stream;
//  * every malformed input throws InputError "<file>:<line>:<column>: <what>; <what to do>",
//    column being the 1-based field index followed by the column's name.
#include <string>
#include <string_view>
#include <vector>

namespace pneufem {

/// One sampled signal: t_s strictly increasing, value[i] sampled at t_s[i].
struct Series {
  std::vector<double> t_s, value;
};

struct TrialRecording {
  int trial = 0;
  Series pressure_kPa;  ///< gauge pressure at the actuator inlet
  Series angle_deg;     ///< bending angle, signed, unwrapped (see deeplabcut.h for the convention)
};

struct Recording {
  std::vector<TrialRecording> trials;  ///< sorted by trial number, each number once
  std::string source;                  ///< file the data came from
  /// false: the file has no pressure column (angles of a commanded protocol only); every trial's
  /// pressure series is empty until app/simulate/drive.h's fill_commanded_pressure samples the scene's load.
  bool pressure_recorded = true;
  std::vector<std::string> warnings;   ///< "<file>: ..." notes that did not stop the read
};

/// Reads a canonical CSV file (format above). Throws InputError on malformed input.
Recording read_measurements_csv(const std::string& path);

/// Parses canonical CSV text; `source` names it in messages (and becomes Recording::source).
Recording parse_measurements_csv(std::string_view text, const std::string& source);

/// Canonical CSV text of `rec`: per trial (ascending), rows in time order, one row per distinct
/// time stamp carrying whichever streams have a sample there. Numbers are written in the
/// shortest form that reads back bit-for-bit, so parse(format(r)) == r.
std::string format_measurements_csv(const Recording& rec);

/// Writes format_measurements_csv(rec) atomically (temporary file, then rename).
void write_measurements_csv(const std::string& path, const Recording& rec);

}  // namespace pneufem

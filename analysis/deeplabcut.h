#pragma once
// Bending angle from DeepLabCut tracks (seed paper, "Data Collection and Control": the actuator
// hangs vertically in a rig, a camera films it at 30 fps, DeepLabCut tracks several points; "the
// bending is considered to be the angle between the fixed end and the moving end", with multiple
// points for reliability).
//
// Input: DeepLabCut's CSV output — header rows `scorer`, optionally `individuals`, `bodyparts`,
// `coords` (x, y, likelihood per body part), then one row per frame: frame index, then x, y,
// likelihood of every body part, in image pixels (x to the right, y DOWN).
//
// Angle convention (the same quantity as the model's angle, engine/angle.h: the rotation of the
// free end relative to the fixed end, in the bending plane, continuous past 180 deg):
//  * `fixed_parts` are >= 2 points rigidly attached to the fixed end (clamp or base), `tip_parts`
//    >= 2 points rigidly attached to the free end segment. Each list is ORDERED: its direction
//    runs from the first listed point to the last (a least-squares line through all points, so
//    extra points average out tracking noise). Either list may run along the actuator (base ->
//    tip) or across it along the end face; because of the zero reference below, only rigidity
//    matters, not which feature is chosen. Choose points as far apart as the part allows.
//  * Image y points down, so points are taken as (X, Y) = (x, -y); then the raw angle is the
//    signed angle from the fixed direction to the tip direction, counter-clockwise positive AS
//    SEEN ON THE SCREEN. `positive = clockwise` flips the sign (the camera may face either side of
//    the actuator; pick the sense in which the actuator bends under pressure, towards its fabric).
//  * The raw angle is unwrapped frame to frame (the branch nearest the previous kept frame), so a
//    curl beyond 180 deg stays continuous.
//  * Zero: by default the median raw angle over the first `zero_frames` kept frames (the
//    actuator at rest before the staircase; a median, so one mistracked frame cannot offset the
//    whole trial; zero_frames = 1 is "zero at the first valid frame"), or an explicit
//    `zero_raw_deg` (the raw angle that counts as zero, e.g. 0 when both lists run along the
//    straight actuator at rest, which keeps a pre-bent rest shape visible).
// Because both directions are measured in the same image, a rolled camera or a rig that is not
// exactly vertical changes nothing. The motion must stay in the image plane (a pneu-net bends in
// one plane; point the camera along the bending axis).
//
// A frame is dropped when any needed body part has likelihood below `likelihood_cut`, has empty
// or NaN coordinates, or when a list's points coincide; the counts go into Recording::warnings.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "analysis/measurements.h"

namespace pneufem {

enum class AngleSense { counterclockwise, clockwise };

struct DlcMapping {
  std::vector<std::string> fixed_parts;  ///< >= 2 body parts on the fixed end, ordered
  std::vector<std::string> tip_parts;    ///< >= 2 body parts on the free end segment, ordered
  double likelihood_cut = 0.9;           ///< frames with a needed part below this are dropped
  double fps = 30.0;                     ///< video frame rate; t = t0_s + frame / fps
  int trial = 1;                         ///< trial number of the returned recording
  double t0_s = 0.0;                     ///< time of frame 0 on the pressure record's clock
  AngleSense positive = AngleSense::counterclockwise;  ///< as seen on the screen
  std::optional<double> zero_raw_deg;    ///< explicit zero; unset: median of the first frames
  int zero_frames = 15;                  ///< kept frames whose median raw angle is zero (0.5 s)
};

/// Reads a DeepLabCut CSV and returns a recording with one trial (`map.trial`) holding only the
/// angle stream. Throws InputError "<file>:<line>:<column>: <what>; <what to do>" on malformed
/// input, and InputError naming the DlcMapping field when the mapping is invalid.
Recording read_deeplabcut_csv(const std::string& path, const DlcMapping& map);

/// Same from text; `source` names it in messages.
Recording parse_deeplabcut_csv(std::string_view text, const std::string& source, const DlcMapping& map);

}  // namespace pneufem

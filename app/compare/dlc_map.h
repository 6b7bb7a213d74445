#pragma once
// `compare --dlc-map MAP.toml`: bending angles from DeepLabCut tracks (analysis/deeplabcut.h)
// instead of the angle column of the --data CSV, which then only needs the pressure (its header
// still names angle_deg; the cells may be empty). The map
// names the body parts once and one DeepLabCut CSV per trial:
//
//     fixed_parts = ["clamp_left", "clamp_right"]   # >= 2, ordered (see deeplabcut.h)
//     tip_parts   = ["tip_top", "tip_bottom"]       # >= 2, ordered
//     likelihood_cut = 0.9                          # optional (default 0.9)
//     fps = 30.0                                    # optional (default 30)
//     positive = "counterclockwise"                 # or "clockwise", as seen on the screen
//     zero_raw_deg = 0.0                            # optional; default: median of the first frames
//     zero_frames = 15                              # optional
//     [[trials]]
//     trial = 1
//     file = "trial1DLC_resnet50.csv"               # relative to the map file
//     t0_s = 0.0                                    # time of frame 0 on the pressure clock (optional)
//
// Every trial of the map must have pressure in --data; trials of --data without a map entry keep
// their CSV angles. Errors name the map file, line and key.
#include <string>

#include "analysis/measurements.h"

namespace pneufem {

/// `pressure` with the angle stream of each mapped trial replaced by the tracked angle.
Recording merge_deeplabcut(const Recording& pressure, const std::string& map_path);

}  // namespace pneufem

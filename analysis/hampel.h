#pragma once
// Outlier frames in the tracked angle: a Hampel filter (Hampel 1974; Pearson, "Outliers in process
// modeling and identification", IEEE TCST 10(1), 2002). Sample i is flagged when
//
//     |x_i - med_i| > k * S_i,   S_i = max(1.4826 * MAD_i, sigma),
//
// med_i and MAD_i being the median and the median absolute deviation of the w = 2 h + 1 samples
// centred on i (shifted inwards at the ends), 1.4826 making MAD a standard deviation for Gaussian
// noise, and sigma the series' own noise level, 1.4826 * MAD(first differences) / sqrt(2).
//
// Why this rule: tracking glitches (a body part jumping to a look-alike for a frame or two) are
// isolated spikes; the median of a window is not moved by up to h of them, so they stand out
// against it, whereas a mean would be dragged along. The step response itself is preserved: on
// any monotone stretch (the rise after a pressure step) the window median IS the centre sample,
// so nothing is flagged there, and a pressure step lasts seconds, far longer than the window
// (7 frames = 0.23 s at 30 fps). The floor sigma stops a window whose 7 samples happen to agree
// closely (MAD ~ 0) from flagging ordinary noise. k = 5 instead of the textbook 3 because a
// 7-sample MAD is a rough scale estimate: on Gaussian noise (measured over 2e6 frames) k = 3
// flags 0.25 % of clean frames, a dozen per 160-s trial, k = 5 about one in 10^6, while real
// glitches (tens of degrees against ~0.3 deg of noise) are still caught.
#include <cstddef>
#include <vector>

#include "analysis/measurements.h"

namespace pneufem {

struct HampelOptions {
  int half_window = 3;   ///< h: the window is 2 h + 1 samples (frames)
  double k = 5.0;        ///< threshold in robust standard deviations
  bool replace = false;  ///< false: drop flagged samples; true: replace them by the window median
};

struct HampelResult {
  Series series;                     ///< the filtered series
  std::vector<std::size_t> flagged;  ///< indices (into the input) of the flagged samples
};

/// Hampel filter of one series (see above). Series with fewer than 2 h + 1 samples are returned
/// unchanged. Samples that are not flagged are copied bit-for-bit.
HampelResult hampel_filter(const Series& s, const HampelOptions& opt = {});

/// Filters the angle stream of every trial in place and appends one warning per trial that had
/// flagged frames. Returns the total number of flagged frames.
int filter_angle_outliers(Recording& rec, const HampelOptions& opt = {});

}  // namespace pneufem

#include "analysis/hampel.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "analysis/robust.h"
#include "core/errors.h"

namespace pneufem {


HampelResult hampel_filter(const Series& s, const HampelOptions& opt) {
  if (opt.half_window < 1 || !(opt.k > 0.0))
    throw InputError("Hampel filter: half_window = " + std::to_string(opt.half_window) + " and k = " +
                     std::to_string(opt.k) + " must be >= 1 and > 0 (3 frames and 5 sigma are the defaults)");
  if (s.t_s.size() != s.value.size())
    throw InputError("Hampel filter: the series has " + std::to_string(s.t_s.size()) + " times but " +
                     std::to_string(s.value.size()) + " values");
  HampelResult out;
  const std::size_t n = s.value.size();
  const std::size_t h = static_cast<std::size_t>(opt.half_window), w = 2 * h + 1;
  if (n < w) {
    out.series = s;
    return out;
  }

  const double sigma = robust::difference_noise(s.value);  // the floor of the local scale

  std::vector<double> win(w), dev(w);
  out.series.t_s.reserve(n);
  out.series.value.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t lo = std::min(i >= h ? i - h : 0, n - w);  // window shifted inwards at the ends
    std::copy(s.value.begin() + static_cast<std::ptrdiff_t>(lo), s.value.begin() + static_cast<std::ptrdiff_t>(lo + w),
              win.begin());
    const double med = robust::median(win);
    for (std::size_t j = 0; j < w; ++j) dev[j] = std::abs(s.value[lo + j] - med);
    const double scale = std::max(robust::kMadToSigma * robust::median(dev), sigma);
    if (std::abs(s.value[i] - med) > opt.k * scale) {
      out.flagged.push_back(i);
      if (!opt.replace) continue;
      out.series.t_s.push_back(s.t_s[i]);
      out.series.value.push_back(med);
      continue;
    }
    out.series.t_s.push_back(s.t_s[i]);
    out.series.value.push_back(s.value[i]);
  }
  return out;
}

int filter_angle_outliers(Recording& rec, const HampelOptions& opt) {
  int total = 0;
  for (TrialRecording& tr : rec.trials) {
    HampelResult r = hampel_filter(tr.angle_deg, opt);
    if (r.flagged.empty()) continue;
    total += static_cast<int>(r.flagged.size());
    std::string w = rec.source + ": trial " + std::to_string(tr.trial) + ": " + std::to_string(r.flagged.size()) +
                    " outlier angle frame(s) " + (opt.replace ? "replaced by the local median" : "dropped") +
                    " (Hampel filter, " + std::to_string(2 * opt.half_window + 1) + " frames, k = " +
                    std::to_string(opt.k).substr(0, 4) + "), first at time_s = " +
                    std::to_string(tr.angle_deg.t_s[r.flagged.front()]);
    rec.warnings.push_back(w);
    tr.angle_deg = std::move(r.series);
  }
  return total;
}

}  // namespace pneufem

#include "analysis/steps.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "analysis/csv_scan.h"
#include "analysis/robust.h"
#include "core/errors.h"

namespace pneufem {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void validate(const Series& s, const StepOptions& opt) {
  if (!(opt.window_s > 0.0 && opt.k_noise > 0.0 && opt.min_change_fraction >= 0.0 && opt.min_hold_s >= 0.0 &&
        opt.fit_fraction > 0.5 && opt.fit_fraction < 1.0))
    throw InputError("step detection: options must satisfy window_s > 0, k_noise > 0, min_change_fraction >= 0, "
                     "min_hold_s >= 0 and 0.5 < fit_fraction < 1 (defaults 0.1 s, 6, 0.02, 0.5 s, 0.9)");
  if (s.t_s.size() != s.value.size())
    throw InputError("step detection: the pressure series has " + std::to_string(s.t_s.size()) + " times but " +
                     std::to_string(s.value.size()) + " values");
  for (std::size_t i = 0; i < s.t_s.size(); ++i) {
    if (!std::isfinite(s.t_s[i]) || !std::isfinite(s.value[i]))
      throw InputError("step detection: pressure sample " + std::to_string(i) + " is not finite");
    if (i > 0 && !(s.t_s[i] > s.t_s[i - 1]))
      throw InputError("step detection: pressure time stamps must increase (sample " + std::to_string(i) +
                       " at t = " + csv::number_text(s.t_s[i]) + " s)");
  }
}

/// Centred running median over [i - h, i + h] (clipped at the ends); a sorted window is updated
/// by one insertion and one removal per sample, O(n w).
std::vector<double> running_median(const std::vector<double>& p, std::size_t h) {
  const std::size_t n = p.size();
  std::vector<double> out(n), win;
  win.reserve(2 * h + 1);
  auto insert = [&](double v) { win.insert(std::upper_bound(win.begin(), win.end(), v), v); };
  auto erase = [&](double v) { win.erase(std::lower_bound(win.begin(), win.end(), v)); };
  for (std::size_t j = 0; j <= std::min(h, n - 1); ++j) insert(p[j]);
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) {
      if (i + h < n) insert(p[i + h]);
      if (i > h) erase(p[i - h - 1]);
    }
    const std::size_t m = win.size();
    out[i] = m % 2 ? win[m / 2] : 0.5 * (win[m / 2 - 1] + win[m / 2]);
  }
  return out;
}

/// Median of p over the samples [a, b] (inclusive).
double median_range(const std::vector<double>& p, std::size_t a, std::size_t b) {
  std::vector<double> v(p.begin() + static_cast<std::ptrdiff_t>(a), p.begin() + static_cast<std::ptrdiff_t>(b + 1));
  return robust::median(v);
}

struct Plateau {
  std::size_t first = 0, last = 0;  // sample indices, inclusive
  double level = 0.0;
};

/// Level of a plateau: median over its second half (settled, see steps.h).
double plateau_level(const std::vector<double>& p, const Plateau& pl) {
  return median_range(p, pl.first + (pl.last - pl.first) / 2, pl.last);
}

/// Least-squares fit of the departure hinge (steps.h, item 5) to z(t) = sgn (p - L_A) >= 0-going.
/// With f = 1 - exp(-(t - t0) / tau) after t0 and the best amplitude A = sum(f z) / sum(f f), the
/// residual is sum(z^2) - score, score = sum(f z)^2 / sum(f f); so the fit maximises the score.
class HingeFit {
 public:
  HingeFit(std::vector<double> t, std::vector<double> z, double tau_min, double tau_max)
      : t_(std::move(t)), z_(std::move(z)), log_lo_(std::log(tau_min)), log_hi_(std::log(tau_max)) {}

  /// Best t0 in [t_lo, t_hi] (coarse grid of `grid` points, then golden-section refinement).
  double best_t0(double t_lo, double t_hi, int grid) const {
    double best_t = t_lo, best = -1.0;
    const double step = grid > 1 ? (t_hi - t_lo) / (grid - 1) : 0.0;
    for (int g = 0; g < grid; ++g) {
      const double t0 = t_lo + g * step;
      const double sc = best_over_tau(t0);
      if (sc > best) {
        best = sc;
        best_t = t0;
      }
    }
    if (step <= 0.0) return best_t;
    return golden_max([this](double t0) { return best_over_tau(t0); }, std::max(t_lo, best_t - step),
                      std::min(t_hi, best_t + step), 40);
  }

 private:
  double score(double t0, double tau) const {
    double sfz = 0.0, sff = 0.0;
    for (std::size_t k = 0; k < t_.size(); ++k) {
      if (t_[k] <= t0) continue;
      const double f = -std::expm1(-(t_[k] - t0) / tau);
      sfz += f * z_[k];
      sff += f * f;
    }
    return (sff > 0.0 && sfz > 0.0) ? sfz * sfz / sff : 0.0;  // A > 0: a change towards the new level
  }

  /// Max over tau of the score at t0: a log-spaced scan, then golden section around the best.
  double best_over_tau(double t0) const {
    constexpr int kScan = 16;
    const double dl = (log_hi_ - log_lo_) / (kScan - 1);
    int best_i = 0;
    double best = -1.0;
    for (int i = 0; i < kScan; ++i) {
      const double sc = score(t0, std::exp(log_lo_ + i * dl));
      if (sc > best) {
        best = sc;
        best_i = i;
      }
    }
    const double lo = log_lo_ + std::max(0, best_i - 1) * dl, hi = log_lo_ + std::min(kScan - 1, best_i + 1) * dl;
    const double l = golden_max([&](double u) { return score(t0, std::exp(u)); }, lo, hi, 24);
    return std::max(best, score(t0, std::exp(l)));
  }

  /// Argmax of a unimodal f on [a, b] by golden-section search.
  template <class F>
  static double golden_max(F f, double a, double b, int iterations) {
    constexpr double r = 0.6180339887498949;
    double c = b - r * (b - a), d = a + r * (b - a);
    double fc = f(c), fd = f(d);
    for (int it = 0; it < iterations; ++it) {
      if (fc >= fd) {
        b = d;
        d = c;
        fd = fc;
        c = b - r * (b - a);
        fc = f(c);
      } else {
        a = c;
        c = d;
        fc = fd;
        d = a + r * (b - a);
        fd = f(d);
      }
    }
    return fc >= fd ? c : d;
  }

  std::vector<double> t_, z_;
  double log_lo_, log_hi_;
};

class Detector {
 public:
  Detector(const Series& s, const StepOptions& opt) : t_(s.t_s), p_(s.value), opt_(opt) {}

  StepDetection run() {
    StepDetection out;
    const std::size_t n = p_.size();
    if (n == 0) return out;
    if (n < 2) {
      out.steps.push_back({t_.front(), t_.back(), p_.front()});
      return out;
    }
    std::vector<double> dts(n - 1);
    for (std::size_t i = 1; i < n; ++i) dts[i - 1] = t_[i] - t_[i - 1];
    dt_ = robust::median(dts);
    out.rate_Hz = 1.0 / dt_;
    out.noise_kPa = robust::difference_noise(p_);
    h_ = std::max<std::size_t>(2, static_cast<std::size_t>(std::lround(0.5 * opt_.window_s / dt_)));
    w_ = 2 * h_ + 1;
    if (n < 2 * w_ + 1) {
      out.steps.push_back({t_.front(), t_.back(), median_range(p_, 0, n - 1)});
      out.warnings.push_back("the pressure record has only " + std::to_string(n) +
                             " samples, too few to find steps; treated as one step");
      return out;
    }
    M_ = running_median(p_, h_);

    // Change statistic D(i) = M(i + h + 1) - M(i - h - 1): medians of the w samples after and before i.
    std::vector<double> D(n, 0.0);
    for (std::size_t i = w_; i + w_ < n; ++i) D[i] = M_[i + h_ + 1] - M_[i - h_ - 1];
    std::vector<double> inner(D.begin() + static_cast<std::ptrdiff_t>(w_), D.end() - static_cast<std::ptrdiff_t>(w_));
    const double sigma_D = robust::kMadToSigma * robust::mad(inner);
    const auto [mlo, mhi] = std::minmax_element(M_.begin(), M_.end());
    T_ = std::max({opt_.k_noise * sigma_D, opt_.min_change_fraction * (*mhi - *mlo),
                   1e-12 * (1.0 + std::max(std::abs(*mlo), std::abs(*mhi)))});
    out.threshold_kPa = T_;

    std::vector<Plateau> plateaus = find_plateaus(D);
    if (plateaus.empty()) {
      out.steps.push_back({t_.front(), t_.back(), median_range(p_, 0, n - 1)});
      out.warnings.push_back("no plateau of at least " + csv::number_text(opt_.min_hold_s) +
                             " s found; the record is treated as one step");
      return out;
    }

    for (std::size_t j = 0; j < plateaus.size(); ++j) {
      Step s;
      s.level_kPa = plateaus[j].level;
      s.t_start_s = j == 0 ? t_.front() : out.steps.back().t_end_s;
      if (j + 1 < plateaus.size()) {
        s.t_end_s = departure(plateaus[j], plateaus[j + 1].level, plateaus[j + 1].last);
      } else {
        s.t_end_s = t_.back();
        const Plateau& last = plateaus[j];
        if (last.last + 1 < n) {  // a final change that reaches no plateau of its own
          const double tail = median_range(p_, n - std::min(n - last.last - 1, w_), n - 1);
          if (std::abs(tail - last.level) > T_) s.t_end_s = departure(last, tail, n - 1);
        }
      }
      out.steps.push_back(s);
      drift_warning(plateaus[j], j, out);
    }
    return out;
  }

 private:
  std::vector<Plateau> find_plateaus(const std::vector<double>& D) const {
    const std::size_t n = D.size();
    std::vector<Plateau> runs;
    for (std::size_t i = 0; i < n;) {
      if (std::abs(D[i]) > T_) {
        ++i;
        continue;
      }
      std::size_t j = i;
      while (j + 1 < n && std::abs(D[j + 1]) <= T_) ++j;
      if (t_[j] - t_[i] >= opt_.min_hold_s) runs.push_back({i, j, 0.0});
      i = j + 1;
    }
    std::vector<Plateau> merged;
    for (Plateau pl : runs) {
      pl.level = plateau_level(p_, pl);
      if (!merged.empty() && std::abs(pl.level - merged.back().level) <= T_) {
        merged.back().last = pl.last;  // the excursion in between was a disturbance, not a step
        merged.back().level = plateau_level(p_, merged.back());
        continue;
      }
      merged.push_back(pl);
    }
    return merged;
  }

  /// Departure time from plateau A towards `level_B`; the rise is looked for before sample i_max.
  double departure(const Plateau& A, double level_B, std::size_t i_max) const {
    const double sgn = level_B > A.level ? 1.0 : -1.0;
    const double change = std::abs(level_B - A.level);
    auto zm = [&](std::size_t i) { return sgn * (M_[i] - A.level); };
    // Half-way crossing of the smoothed record (the median is unbiased on a monotone rise).
    std::size_t i50 = A.last >= A.first + w_ ? A.last - w_ : A.first;
    while (i50 < i_max && zm(i50) < 0.5 * change) ++i50;
    // Back to where the smoothed record last sat at the old level, then w baseline samples more.
    std::size_t iz = i50;
    const std::size_t floor_i = A.first + (A.last - A.first) / 2;
    while (iz > floor_i && zm(iz) > 0.0) --iz;
    const std::size_t is = iz > floor_i + w_ ? iz - w_ : floor_i;
    std::size_t ie = i50;
    while (ie < i_max && zm(ie) < opt_.fit_fraction * change) ++ie;
    if (i50 <= is || ie <= is) return t_[std::min(i50, i_max)];

    std::vector<double> t, z;
    for (std::size_t i = is; i <= ie; ++i) {
      t.push_back(t_[i] - t_[is]);  // relative times: no cancellation in exp()
      z.push_back(sgn * (p_[i] - A.level));
    }
    const double span = t.back();
    HingeFit fit(std::move(t), std::move(z), 0.25 * dt_, 100.0 * span);
    const int grid = static_cast<int>(std::min<std::size_t>(i50 - is + 1, 48));
    return t_[is] + fit.best_t0(0.0, t_[i50] - t_[is], grid);
  }

  void drift_warning(const Plateau& pl, std::size_t j, StepDetection& out) const {
    const auto b = M_.begin() + static_cast<std::ptrdiff_t>(pl.first + (pl.last - pl.first) / 2);
    const auto [lo, hi] = std::minmax_element(b, M_.begin() + static_cast<std::ptrdiff_t>(pl.last + 1));
    if (*hi - *lo > 3.0 * T_)
      out.warnings.push_back("step " + std::to_string(j + 1) + " (level " + csv::number_text(pl.level) +
                             " kPa): the settled pressure drifts by " + csv::number_text(*hi - *lo) +
                             " kPa; a slow ramp or a leak is not split into steps");
  }

  const std::vector<double>& t_;
  const std::vector<double>& p_;
  const StepOptions& opt_;
  double dt_ = 0.0, T_ = 0.0;
  std::size_t h_ = 0, w_ = 0;
  std::vector<double> M_;
};

}  // namespace

StepDetection detect_steps(const Series& pressure_kPa, const StepOptions& opt) {
  validate(pressure_kPa, opt);
  return Detector(pressure_kPa, opt).run();
}

std::vector<TrialSteps> detect_steps(const Recording& rec, const StepOptions& opt) {
  std::vector<TrialSteps> out;
  for (const TrialRecording& tr : rec.trials) {
    TrialSteps ts;
    ts.trial = tr.trial;
    const std::string prefix = rec.source + ": trial " + std::to_string(tr.trial) + ": ";
    if (tr.pressure_kPa.t_s.empty()) {
      ts.detection.warnings.push_back(prefix + "no pressure samples, no steps");
      out.push_back(std::move(ts));
      continue;
    }
    try {
      ts.detection = detect_steps(tr.pressure_kPa, opt);
    } catch (const InputError& e) {
      throw InputError(prefix + e.what());
    }
    for (std::string& w : ts.detection.warnings) w = prefix + w;
    out.push_back(std::move(ts));
  }
  return out;
}

double value_at(const Series& s, double t) {
  if (s.t_s.empty() || !(t >= s.t_s.front() && t <= s.t_s.back())) return kNaN;
  const auto it = std::lower_bound(s.t_s.begin(), s.t_s.end(), t);
  const std::size_t j = static_cast<std::size_t>(it - s.t_s.begin());
  if (s.t_s[j] == t) return s.value[j];
  const double t0 = s.t_s[j - 1], t1 = s.t_s[j];
  const double a = (t - t0) / (t1 - t0);
  return (1.0 - a) * s.value[j - 1] + a * s.value[j];
}

double median_in(const Series& s, double t0, double t1) {
  const auto b = std::lower_bound(s.t_s.begin(), s.t_s.end(), t0);
  const auto e = std::upper_bound(s.t_s.begin(), s.t_s.end(), t1);
  if (b >= e) return kNaN;
  std::vector<double> v(s.value.begin() + (b - s.t_s.begin()), s.value.begin() + (e - s.t_s.begin()));
  return robust::median(v);
}

}  // namespace pneufem

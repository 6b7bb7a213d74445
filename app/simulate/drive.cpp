#include "app/simulate/drive.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <sstream>
#include <utility>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include "analysis/hampel.h"
#include "analysis/steps.h"
#include "app/simulate/reduced.h"
#include "core/errors.h"
#include "core/progress.h"
#include "engine/assembly.h"
#include "engine/quasi_static.h"
#include "scenes/build_model.h"
#include "scenes/pressure_lag.h"
#include "scenes/scene_settings.h"
#include "viz/vtk_output.h"

namespace pneufem {

namespace {

constexpr double kMadToSigma = 1.4826;  // MAD -> standard deviation for Gaussian noise

double median_of(std::vector<double>& v) {
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  const double upper = v[mid];
  if (v.size() % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid)));
}

/// White-noise sigma of a sampled signal from its first differences (a step changes only a few
/// differences, so the MAD ignores it): 1.4826 MAD(diff) / sqrt(2).
double difference_noise(const std::vector<double>& x) {
  if (x.size() < 3) return 0.0;
  std::vector<double> d;
  d.reserve(x.size() - 1);
  for (std::size_t i = 1; i < x.size(); ++i) d.push_back(x[i] - x[i - 1]);
  const double m = median_of(d);
  for (double& v : d) v = std::abs(v - m);
  return kMadToSigma * median_of(d) / std::sqrt(2.0);
}

/// Running median with a symmetric window of up to 2 h + 1 samples, shrunk at the ends so the
/// window stays centred (then a monotone record passes through unchanged, ends included).
std::vector<double> running_median(const std::vector<double>& x, int h) {
  const std::ptrdiff_t n = static_cast<std::ptrdiff_t>(x.size());
  std::vector<double> out(x.size()), w;
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const std::ptrdiff_t m = std::min<std::ptrdiff_t>({h, i, n - 1 - i});
    w.assign(x.begin() + (i - m), x.begin() + (i + m + 1));
    out[static_cast<std::size_t>(i)] = median_of(w);
  }
  return out;
}


/// Linear interpolation of (t, v) at x, clamped to the end values outside [t.front(), t.back()].
double interp_clamped(const std::vector<double>& t, const std::vector<double>& v, double x) {
  if (t.empty()) return std::numeric_limits<double>::quiet_NaN();
  if (x <= t.front()) return v.front();
  if (x >= t.back()) return v.back();
  const std::size_t i = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), x) - t.begin());
  const double w = (x - t[i - 1]) / (t[i] - t[i - 1]);
  return (1.0 - w) * v[i - 1] + w * v[i];
}

/// Values at the knots t[keep] of the continuous piecewise-linear function closest (least squares)
/// to the samples (t, x). Why: RDP keeps individual (median-filtered) samples as breakpoints, so a
/// 16 s plateau is drawn between two samples, each off by the filtered noise (~0.05 kPa for a
/// 0.1 kPa sensor); near the limit point (the angle rises ~5°/kPa at 45 kPa) that alone put 0.3-0.6°
/// of error into the model driven by a noise-free-angle recording. Fitted, a plateau's value is the
/// average of its hundreds of samples. A record that is piecewise linear with these knots (a
/// noise-free staircase) is reproduced exactly. Tridiagonal SPD normal equations (each interval
/// holds at least its two end samples), solved by the Thomas algorithm.
std::vector<double> fit_knot_values(const std::vector<double>& t, const std::vector<double>& x,
                                    const std::vector<char>& keep) {
  std::vector<std::size_t> knot;
  for (std::size_t i = 0; i < t.size(); ++i)
    if (keep[i]) knot.push_back(i);
  const std::size_t m = knot.size();
  if (m == 1) return {x[knot[0]]};
  std::vector<double> diag(m, 0.0), off(m, 0.0), rhs(m, 0.0);  // off[k] couples k and k + 1
  for (std::size_t k = 0; k + 1 < m; ++k) {
    const double ta = t[knot[k]], tb = t[knot[k + 1]];
    // Samples of [ta, tb); the last knot's own sample closes the last interval.
    const std::size_t end = (k + 2 == m) ? knot[k + 1] + 1 : knot[k + 1];
    for (std::size_t i = knot[k]; i < end; ++i) {
      const double w = tb > ta ? (t[i] - ta) / (tb - ta) : 0.0;
      diag[k] += (1 - w) * (1 - w);
      off[k] += (1 - w) * w;
      diag[k + 1] += w * w;
      rhs[k] += (1 - w) * x[i];
      rhs[k + 1] += w * x[i];
    }
  }
  for (std::size_t k = 1; k < m; ++k) {  // forward elimination
    const double f = off[k - 1] / diag[k - 1];
    diag[k] -= f * off[k - 1];
    rhs[k] -= f * rhs[k - 1];
  }
  std::vector<double> v(m);
  v[m - 1] = rhs[m - 1] / diag[m - 1];
  for (std::size_t k = m - 1; k-- > 0;) v[k] = (rhs[k] - off[k] * v[k + 1]) / diag[k];
  return v;
}

struct Candidate {
  double abs_residual = -1.0;
  WorstState info;
  Eigen::VectorXd u;
  std::vector<double> state;
};

}  // namespace

Series simplify_pressure(const Series& p, double tolerance_kPa, double median_window_s, double* used_kPa) {
  const std::size_t n = p.t_s.size();
  if (n < 2) {
    if (used_kPa) *used_kPa = std::max(tolerance_kPa, 0.0);
    return p;
  }
  std::vector<double> dt;
  for (std::size_t i = 1; i < n; ++i) dt.push_back(p.t_s[i] - p.t_s[i - 1]);
  const double rate_Hz = 1.0 / median_of(dt);
  const int h = std::max(2, static_cast<int>(std::lround(0.5 * median_window_s * rate_Hz)));
  const std::vector<double> smooth = running_median(p.value, h);
  const double tol = tolerance_kPa > 0 ? tolerance_kPa : std::max(3.0 * difference_noise(p.value), 0.05);
  if (used_kPa) *used_kPa = tol;
  const std::vector<char> keep = rdp_keep(p.t_s, smooth, tol);
  Series out;
  for (std::size_t i = 0; i < n; ++i)
    if (keep[i]) out.t_s.push_back(p.t_s[i]);
  out.value = fit_knot_values(p.t_s, smooth, keep);
  return out;
}

namespace {
/// The model is driven by gauge pressure (0 = atmospheric, the actuator at rest). Two mistakes
/// would otherwise surface as a misleading "limit point" failure of the first state: an absolute
/// pressure record (it rests at ~101 kPa: every trial stays above 50 kPa, which no staircase from
/// rest does) and a record in Pa labelled kPa (it reaches tens of thousands; a soft actuator bursts
/// far below 2 MPa). Both are InputErrors naming the sample and what to do.
void check_gauge_pressure(const Recording& rec) {
  double lowest = std::numeric_limits<double>::infinity(), highest = -lowest;
  int low_trial = 0, high_trial = 0;
  double low_t = 0.0, high_t = 0.0;
  for (const TrialRecording& tr : rec.trials)
    for (std::size_t i = 0; i < tr.pressure_kPa.t_s.size(); ++i) {
      const double p = tr.pressure_kPa.value[i];
      if (p < lowest) lowest = p, low_trial = tr.trial, low_t = tr.pressure_kPa.t_s[i];
      if (p > highest) highest = p, high_trial = tr.trial, high_t = tr.pressure_kPa.t_s[i];
    }
  auto where = [](int trial, double t) {
    std::ostringstream s;
    s << "trial " << trial << ", time_s = " << t;
    return s.str();
  };
  if (lowest >= 50.0 && std::isfinite(lowest)) {
    std::ostringstream m;
    m << rec.source << ": the pressure never falls below " << lowest << " kPa (lowest sample at " << where(low_trial, low_t)
      << "), so the actuator never rests: this looks like ABSOLUTE pressure. pneufem drives the chamber with gauge "
         "pressure (0 = atmospheric); subtract the atmospheric pressure (about 101.3 kPa) from pressure_kPa";
    throw InputError(m.str());
  }
  if (highest > 2000.0) {
    std::ostringstream m;
    m << rec.source << ": pressure_kPa reaches " << highest << " kPa (at " << where(high_trial, high_t)
      << "), far beyond what a soft actuator carries: if the column is in Pa, name it pressure_Pa (it is then "
         "converted on reading)";
    throw InputError(m.str());
  }
}
}  // namespace

void fill_commanded_pressure(Recording& rec, const Scene& scene) {
  if (rec.pressure_recorded) return;
  const LoadHistory load = inlet_load(scene);
  if (load.trials.empty()) throw InputError("[load]: the scene's protocol has no trials to drive " + rec.source + " with");
  // 200 Hz and every breakpoint: the running median passes a monotone piece unchanged and RDP then
  // keeps exactly the protocol's corners, so the drive solves the protocol's own pressures.
  constexpr double kRate_Hz = 200.0;
  std::ostringstream late;
  for (std::size_t k = 0; k < rec.trials.size(); ++k) {
    TrialRecording& tr = rec.trials[k];
    const TrialLoad& tl = load.trials[std::min(k, load.trials.size() - 1)];
    const double first = tr.angle_deg.t_s.empty() ? 0.0 : std::min(0.0, tr.angle_deg.t_s.front());
    const double last = tr.angle_deg.t_s.empty() ? tl.duration() : std::max(tl.duration(), tr.angle_deg.t_s.back());
    if (last > tl.duration() + 1.0 && late.tellp() == 0)
      late << "trial " << tr.trial << " has frames up to time_s = " << last << ", after the protocol's trial ends ("
           << tl.duration() << " s)";
    std::vector<double> t;
    for (long i = static_cast<long>(std::floor(first * kRate_Hz)); i / kRate_Hz <= last; ++i) t.push_back(i / kRate_Hz);
    for (double b : tl.time_s) t.push_back(b);
    if (t.back() < last) t.push_back(last);
    std::sort(t.begin(), t.end());
    t.erase(std::unique(t.begin(), t.end(), [](double a, double b) { return b - a < 1e-9; }), t.end());
    tr.pressure_kPa.t_s.clear();
    tr.pressure_kPa.value.clear();
    for (double ti : t) {
      tr.pressure_kPa.t_s.push_back(ti);
      tr.pressure_kPa.value.push_back(tl.pressure(ti) * 1e-3);  // before 0: the start, after the end: the last level
    }
  }
  std::ostringstream w;
  w << rec.source << ": no pressure column: the model is driven by the scene's [load] (" << load.description
    << "; the recording's k-th trial by the protocol's k-th"
    << (load.trials.size() < rec.trials.size() ? ", trials beyond load.trials by its last" : "")
    << "), time_s = 0 being the start of the protocol's trial";
  // The reader's note ("no pressure column") becomes this one, which says what was done.
  const auto note = std::find_if(rec.warnings.begin(), rec.warnings.end(),
                                 [&](const std::string& m) { return m.rfind(rec.source + ": no pressure column", 0) == 0; });
  if (note != rec.warnings.end()) *note = w.str();
  else rec.warnings.push_back(w.str());
  if (late.tellp() > 0)
    rec.warnings.push_back(rec.source + ": " + late.str() +
                           ": those frames are compared with the last level held; trim the recording or describe the "
                           "whole protocol in [load]");
  rec.pressure_recorded = true;
}

LoadHistory measured_load(const Recording& rec, const DriveOptions& opt, double rest_s, bool rate_dependent,
                          std::vector<double>& t_offset_s, double* used_tolerance_kPa) {
  if (rec.trials.empty()) throw InputError(rec.source + ": the recording has no trials; nothing to simulate");
  if (!(opt.max_report_gap_s > 0)) throw InputError("max_report_gap_s must be > 0");
  if (!rec.pressure_recorded)
    throw InputError(rec.source + ": the recording has no pressure column; the model needs the pressure it was driven "
                                  "with (fill_commanded_pressure takes it from the scene's [load])");
  check_gauge_pressure(rec);
  LoadHistory h;
  h.rest_between_trials_s = rest_s;
  t_offset_s.clear();
  double tol_max = 0.0;
  for (const TrialRecording& tr : rec.trials) {
    if (tr.pressure_kPa.t_s.size() < 2)
      throw InputError(rec.source + ": trial " + std::to_string(tr.trial) +
                       " has fewer than 2 pressure samples; the model is driven by the measured pressure, so every "
                       "trial needs a pressure_kPa record (remove the trial or add its pressure)");
    double tol = 0.0;
    const Series bp = simplify_pressure(tr.pressure_kPa, opt.pressure_tolerance_kPa, opt.median_window_s, &tol);
    tol_max = std::max(tol_max, tol);
    const double t0 = bp.t_s.front();
    t_offset_s.push_back(t0);
    TrialLoad tl;
    for (std::size_t i = 0; i < bp.t_s.size(); ++i) {
      const double t = bp.t_s[i] - t0, p_Pa = bp.value[i] * 1e3;
      if (i > 0) {
        const double ta = tl.time_s.back(), pa = tl.pressure_Pa.back();
        const bool changes = std::abs(p_Pa - pa) > tol * 1e3;
        if (t - ta > opt.max_report_gap_s && (rate_dependent || changes)) {
          const int m = static_cast<int>(std::ceil((t - ta) / opt.max_report_gap_s));
          for (int j = 1; j < m; ++j) {
            const double w = static_cast<double>(j) / m;
            tl.time_s.push_back(ta + w * (t - ta));
            tl.pressure_Pa.push_back(pa + w * (p_Pa - pa));
          }
        }
      }
      tl.time_s.push_back(t);
      tl.pressure_Pa.push_back(p_Pa);
    }
    tl.output_s = tl.time_s;  // every breakpoint is a reported state
    h.trials.push_back(std::move(tl));
  }
  if (used_tolerance_kPa) *used_tolerance_kPa = tol_max;
  char d[96];
  std::snprintf(d, sizeof d, " (%zu trials, RDP tolerance %.3g kPa)", rec.trials.size(), tol_max);
  h.description = "measured pressure of " + rec.source + d;
  return h;
}

namespace {
using StateObserver = std::function<void(const StateRecord&, const Eigen::VectorXd&, const std::vector<double>&)>;

/// The reduced model through `load` (app/simulate/reduced.h), each report to `observe` (with the
/// full displacement and history when checked, empty vectors otherwise). Returns "" when its angles
/// stand, else why the full FEM must replace them: a report whose estimated angle error exceeds
/// solver.reduced_check_deg, or a reduced run that failed (the FEM, not the reduction, is the
/// judge of whether the actuator can follow the load). Without DriveOptions::reduced_fallback a
/// failure propagates and an estimate above the tolerance is only recorded. Bad input (a scene the reduced model cannot
/// run) propagates as InputError.
std::string drive_reduced(const Scene& scene, BuiltModel& bm, const LoadHistory& load, const DriveOptions& opt,
                          const StateObserver& observe, const std::function<void()>& clear_reports, DriveResult& result) {
  if (opt.progress) std::fprintf(stderr, "  reduced model: elastic path and basis ...\n");
  // The scene's own protocol (bm.load before the recording replaces it) and the recording's peak.
  const double peak_Pa = std::max(opt.reduced_peak_Pa, elastic_reference_peak_Pa(peak_pressure(bm.load), peak_pressure(load)));
  const std::unique_ptr<ReducedSetup> setup = reduced_setup(scene, peak_Pa, bm.solver.reduced, opt.cache_dir);
  result.reduced_offline_s = setup->offline_s;
  result.reduced_basis_source = setup->basis_source;
  bm.load = load;  // the measured pressure replaces the scene's protocol (run_reduced runs bm.load)
  ReducedRunResult rr;
  try {
    // With a fallback, a failed check first enriches the basis (app/simulate/reduced.h); each
    // enriched run replaces the reports the observer has seen.
    std::function<void(const ReducedRunResult::Enrichment&)> restart;
    if (opt.reduced_check && opt.reduced_fallback) restart = [&](const ReducedRunResult::Enrichment&) { clear_reports(); };
    rr = run_reduced(*setup, bm, observe, opt.reduced_check, restart);
  } catch (const PhysicsError& e) {
    if (!opt.reduced_fallback) throw;
    return std::string("the reduced model failed: ") + e.what();
  }
  result.states = rr.stats.states;
  result.reduced_enrichments = static_cast<int>(rr.enrichments.size());
  result.reduced_worst_check_deg = opt.reduced_check ? rr.worst_check_deg : -1.0;
  if (opt.reduced_check && opt.reduced_fallback) {
    std::string why = reduced_check_failure(rr, bm.solver.reduced_check_deg);
    if (!why.empty()) return why;
  }
  result.model = "reduced";
  return "";
}
}  // namespace

double elastic_reference_peak_Pa(double scene_peak_Pa, double recorded_peak_Pa) {
  constexpr double kProtocolHeadroom = 1.1;  // overshoot and sensor noise above the commanded peak
  constexpr double kProtocolLowest = 0.8;    // a recording peaking lower follows a protocol of its own
  if (scene_peak_Pa > 0.0 && recorded_peak_Pa >= kProtocolLowest * scene_peak_Pa &&
      recorded_peak_Pa <= kProtocolHeadroom * scene_peak_Pa)
    return kProtocolHeadroom * scene_peak_Pa;
  const double p = std::max(recorded_peak_Pa, 1e3);
  const double step = 0.5 * std::pow(10.0, std::floor(std::log10(p)));  // 5 kPa for 10-100 kPa
  return step * std::ceil(p / step);
}

namespace {

/// The load that drives the model through a recording: its measured pressure (measured_load),
/// through the scene's chamber-pressure lag (load.pressure_lag_s, first or with load.pressure_lag2_s
/// second order) exactly as the scene's own load is (same 0.05 kPa breakpoint tolerance as
/// build_model uses for a CSV inlet), then opt.chamber_pressure. The lag's breakpoints become
/// reported states too, so the lagged rise after each step is resolved at the frames rather than
/// bridged by one straight line. `offset` receives each trial's start time in the recording.
LoadHistory recording_load(const Scene& scene, const Recording& rec, const DriveOptions& opt, bool rate_dependent,
                           std::vector<double>& offset, DriveResult& result) {
  LoadHistory load = measured_load(rec, opt, load_settings(scene).rest_s, rate_dependent, offset, &result.tolerance_kPa);
  const PressureLag lag = scene_pressure_lag(scene);
  if (lag.on()) {
    LoadHistory lagged = apply_pressure_lag(load, lag, 0.05e3);
    for (TrialLoad& tl : lagged.trials) {
      std::vector<double>& out = tl.output_s;
      out.insert(out.end(), tl.time_s.begin(), tl.time_s.end());
      std::sort(out.begin(), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
    }
    load = std::move(lagged);
  }
  if (opt.chamber_pressure)
    for (TrialLoad& tl : load.trials)
      for (double& p : tl.pressure_Pa) p = opt.chamber_pressure(p);
  return load;
}

/// Runs `load` through the reduced model (when the scene asks for it and it stands) or the full
/// quasi-static FEM, each report to `observe`. A PhysicsError with opt.partial_on_failure is kept in
/// result.failure and result.failure_time_s; returns the index of the trial that stopped early
/// (the trial count when none did).
std::size_t drive_load(const Scene& scene, BuiltModel& bm, const Assembler& asmb, const LoadHistory& load,
                       std::size_t trials, const DriveOptions& opt, const StateObserver& observe,
                       const std::function<void()>& clear_traces, ProgressMeter& progress, DriveResult& result) {
  try {
    const bool reduced =
        bm.solver.mode == SolverSettings::Mode::QuasiStatic && bm.solver.model == SolverSettings::Model::Reduced;
    const std::string fallback = reduced ? drive_reduced(scene, bm, load, opt, observe, clear_traces, result) : std::string();
    if (!fallback.empty()) {
      clear_traces();
      result.model = "full (fallback: " + fallback + ")";
      progress.message("  " + result.model);
    }
    if (!reduced || !fallback.empty()) {
      // A recording is compared frame by frame and its measured trials differ: every trial is solved.
      QuasiStaticOptions qs = bm.solver.quasi_static;
      qs.cycle_jump.on = false;
      QuasiStaticRun run(asmb, qs);
      try {
        run.run(load, observe);
      } catch (...) {
        result.states = run.stats().states;
        throw;
      }
      result.states = run.stats().states;
    }
  } catch (const PhysicsError& e) {
    if (!opt.partial_on_failure) throw;
    result.failure = e.what();
    std::size_t failed_trial = 0;
    while (failed_trial + 1 < trials && !result.trials[failed_trial + 1].states_angle_deg.t_s.empty()) ++failed_trial;
    const Series& solved = result.trials[failed_trial].states_angle_deg;
    result.failure_time_s = solved.t_s.empty() ? 0.0 : solved.t_s.back();
    return failed_trial;
  }
  return trials;
}

/// The model's angle at every frame of the recording, interpolated between the solved states.
/// After an early stop, frames past the last solved state of the failed trial (and all frames of
/// later trials) have no model value (NaN).
void model_at_frames(const Recording& rec, std::size_t failed_trial, DriveResult& result) {
  for (std::size_t k = 0; k < rec.trials.size(); ++k) {
    TrialTrace& tt = result.trials[k];
    const Series& frames = rec.trials[k].angle_deg;
    tt.angle_deg.t_s = frames.t_s;
    tt.angle_deg.value.reserve(frames.t_s.size());
    const Series& solved = tt.states_angle_deg;
    const double t_end = k < failed_trial    ? INFINITY
                         : k == failed_trial ? (solved.t_s.empty() ? -INFINITY : solved.t_s.back())
                                             : -INFINITY;
    for (double t : frames.t_s)
      tt.angle_deg.value.push_back(t <= t_end && !solved.t_s.empty() ? interp_clamped(solved.t_s, solved.value, t) : NAN);
  }
}

/// The worst states (largest |model - measured|) as worst_N.vtu in opt.vtu_dir, listed in result.worst.
void write_worst_states(std::vector<Candidate>& worst, const BuiltModel& bm, const Assembler& asmb,
                        const DriveOptions& opt, DriveResult& result) {
  std::filesystem::create_directories(opt.vtu_dir);
  for (std::size_t i = 0; i < worst.size(); ++i) {
    Candidate& c = worst[i];
    c.info.file = (std::filesystem::path(opt.vtu_dir) / ("worst_" + std::to_string(i + 1) + ".vtu")).string();
    const TrialTrace& tt = *std::find_if(result.trials.begin(), result.trials.end(),
                                         [&](const TrialTrace& x) { return x.trial == c.info.trial; });
    write_vtu(c.info.file, bm.model, compute_fields(asmb, c.u, c.state), c.info.time_s, c.info.trial,
              interp_clamped(tt.states_pressure_kPa.t_s, tt.states_pressure_kPa.value, c.info.time_s), c.info.model_deg);
    result.worst.push_back(c.info);
  }
}

}  // namespace

DriveResult simulate_recording(const Scene& scene, const Recording& rec, const DriveOptions& opt) {
  const auto wall0 = std::chrono::steady_clock::now();
  const int threads = opt.threads > 0 ? opt.threads : tbb::info::default_concurrency();
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);

  std::unique_ptr<BuiltModel> bm = build_model(scene);
  const Assembler asmb(bm->model);
  const bool rate_dependent = asmb.state_size() > 0;
  std::vector<double> offset;
  DriveResult result;
  const LoadHistory load = recording_load(scene, rec, opt, rate_dependent, offset, result);

  // Measured angles without outlier frames, only to pick the worst states for VTU output.
  const bool want_vtu = !opt.vtu_dir.empty() && opt.vtu_worst > 0;
  std::vector<Series> measured;
  if (want_vtu)
    for (const TrialRecording& tr : rec.trials) measured.push_back(hampel_filter(tr.angle_deg).series);
  std::vector<Candidate> worst;

  result.trials.resize(rec.trials.size());
  for (std::size_t k = 0; k < rec.trials.size(); ++k) result.trials[k].trial = rec.trials[k].trial;
  // Progress (core/progress.h): the share of the recording's time solved.
  ProgressMeter progress(opt.progress_label, opt.progress                     ? ProgressMeter::Mode::Terminal
                                             : opt.progress_log_every_s > 0.0 ? ProgressMeter::Mode::Log
                                                                              : ProgressMeter::Mode::Off,
                         opt.progress_log_every_s);
  std::vector<double> before(load.trials.size() + 1, 0.0);  // the recording's time before each trial
  for (std::size_t k = 0; k < load.trials.size(); ++k) before[k + 1] = before[k] + load.trials[k].duration();
  // Each reported state: into the trial's traces, the progress line, and (with VTU output) the
  // list of the opt.vtu_worst states farthest from the measured angle, largest first.
  auto observe = [&](const StateRecord& r, const Eigen::VectorXd& u, const std::vector<double>& state) {
    const std::size_t k = static_cast<std::size_t>(r.trial - 1);
    TrialTrace& tt = result.trials[k];
    const double t = r.time_s + offset[k];
    tt.states_angle_deg.t_s.push_back(t);
    tt.states_angle_deg.value.push_back(r.angle_deg);
    tt.states_pressure_kPa.t_s.push_back(t);
    tt.states_pressure_kPa.value.push_back(r.pressure_Pa * 1e-3);
    if (progress.mode() != ProgressMeter::Mode::Off) {
      char d[160];
      std::snprintf(d, sizeof d, "trial %d (%zu/%zu), t = %.1f s, %.1f kPa, %.2f deg", tt.trial, k + 1, rec.trials.size(), t,
                    r.pressure_Pa * 1e-3, r.angle_deg);
      progress.update(before.back() > 0.0 ? (before[k] + r.time_s) / before.back() : 0.0, d);
    }
    if (!want_vtu || u.size() == 0) return;  // an unchecked reduced run has no full fields
    const double meas = value_at(measured[k], t);
    if (!std::isfinite(meas)) return;
    const double a = std::abs(r.angle_deg - meas);
    if (static_cast<int>(worst.size()) == opt.vtu_worst && a <= worst.back().abs_residual) return;
    Candidate c{a, WorstState{tt.trial, t, r.angle_deg, meas, ""}, u, state};
    const auto pos = std::upper_bound(worst.begin(), worst.end(), a,
                                      [](double v, const Candidate& x) { return v > x.abs_residual; });
    worst.insert(pos, std::move(c));
    if (static_cast<int>(worst.size()) > opt.vtu_worst) worst.pop_back();
  };
  auto clear_traces = [&] {
    for (TrialTrace& tt : result.trials) tt.states_angle_deg = tt.states_pressure_kPa = Series();
    worst.clear();
  };
  const std::size_t failed_trial =
      drive_load(scene, *bm, asmb, load, rec.trials.size(), opt, observe, clear_traces, progress, result);
  progress.done();
  result.mesh = bm->stats;

  model_at_frames(rec, failed_trial, result);
  if (want_vtu && !worst.empty()) write_worst_states(worst, *bm, asmb, opt, result);
  result.scene_text = "# [load] is replaced by the " + load.description + "; rest between trials = load.rest_s\n" +
                      scene.to_toml();
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return result;
}

}  // namespace pneufem

#include "engine/quasi_static.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <istream>
#include <ostream>
#include <sstream>

#include "core/errors.h"
#include "engine/angle.h"
#include "engine/history_step.h"

namespace pneufem {

// ------------------------------------------------------------------ checkpoint (binary)
namespace {
constexpr std::uint64_t kMagic = 0x31504b4346454e50ULL;   // "PNEFCKP1"
constexpr std::uint64_t kMagic2 = 0x32504b4346454e50ULL;  // "PNEFCKP2": + error-control memory
constexpr std::uint64_t kMagic3 = 0x33504b4346454e50ULL;  // "PNEFCKP3": + ramp-start memory
constexpr std::uint64_t kMagic4 = 0x34504b4346454e50ULL;  // "PNEFCKP4": + drive-control memory
constexpr std::uint64_t kMagic5 = 0x35504b4346454e50ULL;  // "PNEFCKP5": + cycle-jump memory and counts
constexpr std::uint64_t kMagic6 = 0x36504b4346454e50ULL;  // "PNEFCKP6": + drive control's unchecked damage

template <class T>
void put(std::ostream& os, const T& v) {
  os.write(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <class T>
void get(std::istream& is, T& v) {
  is.read(reinterpret_cast<char*>(&v), sizeof(T));
  if (!is) throw InputError("checkpoint: file is truncated");
}
void put_vec(std::ostream& os, const double* d, std::uint64_t n) {
  put(os, n);
  os.write(reinterpret_cast<const char*>(d), static_cast<std::streamsize>(n * sizeof(double)));
}
std::vector<double> get_vec(std::istream& is) {
  std::uint64_t n = 0;
  get(is, n);
  if (n > (1ULL << 34)) throw InputError("checkpoint: corrupt vector length");
  std::vector<double> v(n);
  is.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(double)));
  if (!is) throw InputError("checkpoint: file is truncated");
  return v;
}

void put_records(std::ostream& os, const std::vector<StateRecord>& recs) {
  put(os, static_cast<std::uint64_t>(recs.size()));
  for (const StateRecord& r : recs) {
    put(os, static_cast<std::int64_t>(r.trial));
    put(os, static_cast<std::uint64_t>(r.extrapolated ? 1 : 0));
    for (double v : {r.time_s, r.global_time_s, r.pressure_Pa, r.angle_deg, r.cavity_volume_m3, r.plane_rms_m}) put(os, v);
  }
}
std::vector<StateRecord> get_records(std::istream& is) {
  std::uint64_t n = 0;
  get(is, n);
  if (n > (1ULL << 32)) throw InputError("checkpoint: corrupt report count");
  std::vector<StateRecord> recs(n);
  for (StateRecord& r : recs) {
    std::int64_t trial = 0;
    std::uint64_t extrapolated = 0;
    get(is, trial);
    get(is, extrapolated);
    r.trial = static_cast<int>(trial);
    r.extrapolated = extrapolated != 0;
    for (double* v : {&r.time_s, &r.global_time_s, &r.pressure_Pa, &r.angle_deg, &r.cavity_volume_m3, &r.plane_rms_m}) get(is, *v);
  }
  return recs;
}

}  // namespace

void QuasiStaticCheckpoint::write(std::ostream& os) const {
  put(os, kMagic6);
  put(os, static_cast<std::uint64_t>(next_segment));
  put(os, dt_suggest_s);
  put(os, last_angle_deg);
  put_vec(os, u.data(), static_cast<std::uint64_t>(u.size()));
  put_vec(os, state.data(), state.size());
  put_vec(os, path_p.data(), path_p.size());
  for (const auto& v : path_u) put_vec(os, v.data(), static_cast<std::uint64_t>(v.size()));
  put(os, stats.states);
  put(os, stats.rejected_steps);
  put(os, stats.relaxation_iterations);
  put(os, stats.wall_s);
  put_vec(os, hist_prev.data(), hist_prev.size());
  put_vec(os, hist_cur.data(), hist_cur.size());
  put(os, h_prev_s);
  put(os, rate_prev_Pa_s);
  put(os, ramp_start_dp_Pa[0]);
  put(os, ramp_start_dp_Pa[1]);
  put_vec(os, drive_prev.data(), drive_prev.size());
  put_vec(os, drive_cur.data(), drive_cur.size());
  put(os, static_cast<std::uint64_t>(damage_grew ? 1 : 0));
  put(os, stats.cycle_jumps);
  put(os, stats.trials_extrapolated);
  put(os, static_cast<std::uint64_t>(cycle_ends.size()));
  for (const std::vector<double>& h : cycle_ends) put_vec(os, h.data(), h.size());
  put(os, static_cast<std::uint64_t>(cycle_reports.size()));
  for (const std::vector<StateRecord>& r : cycle_reports) put_records(os, r);
  put_records(os, trial_reports);
  put_vec(os, unchecked_damage.data(), unchecked_damage.size());
}

QuasiStaticCheckpoint QuasiStaticCheckpoint::read(std::istream& is, std::size_t dofs, std::size_t state_size) {
  QuasiStaticCheckpoint c;
  std::uint64_t magic = 0, seg = 0;
  get(is, magic);
  if (magic != kMagic && magic != kMagic2 && magic != kMagic3 && magic != kMagic4 && magic != kMagic5 && magic != kMagic6) throw InputError("checkpoint: not a pneufem checkpoint (bad magic number)");
  get(is, seg);
  c.next_segment = static_cast<std::size_t>(seg);
  get(is, c.dt_suggest_s);
  get(is, c.last_angle_deg);
  const std::vector<double> u = get_vec(is);
  c.u = Eigen::Map<const Eigen::VectorXd>(u.data(), static_cast<Eigen::Index>(u.size()));
  c.state = get_vec(is);
  c.path_p = get_vec(is);
  for (std::size_t i = 0; i < c.path_p.size(); ++i) {
    const std::vector<double> v = get_vec(is);
    c.path_u.emplace_back(Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size())));
  }
  get(is, c.stats.states);
  get(is, c.stats.rejected_steps);
  get(is, c.stats.relaxation_iterations);
  get(is, c.stats.wall_s);
  if (magic == kMagic2 || magic == kMagic3 || magic == kMagic4 || magic == kMagic5 || magic == kMagic6) {
    c.hist_prev = get_vec(is);
    c.hist_cur = get_vec(is);
    get(is, c.h_prev_s);
    get(is, c.rate_prev_Pa_s);
  }
  if (magic == kMagic3 || magic == kMagic4 || magic == kMagic5 || magic == kMagic6) {
    get(is, c.ramp_start_dp_Pa[0]);
    get(is, c.ramp_start_dp_Pa[1]);
  }
  if (magic == kMagic4 || magic == kMagic5 || magic == kMagic6) {
    c.drive_prev = get_vec(is);
    c.drive_cur = get_vec(is);
    std::uint64_t grew = 0;
    get(is, grew);
    c.damage_grew = grew != 0;
  }
  if (magic == kMagic5 || magic == kMagic6) {
    get(is, c.stats.cycle_jumps);
    get(is, c.stats.trials_extrapolated);
    std::uint64_t n = 0;
    get(is, n);
    if (n > 3) throw InputError("checkpoint: corrupt cycle-jump memory");
    for (std::uint64_t k = 0; k < n; ++k) c.cycle_ends.push_back(get_vec(is));
    get(is, n);
    if (n > 3) throw InputError("checkpoint: corrupt cycle-jump memory");
    for (std::uint64_t k = 0; k < n; ++k) c.cycle_reports.push_back(get_records(is));
    c.trial_reports = get_records(is);
  }
  if (magic == kMagic6) c.unchecked_damage = get_vec(is);
  if (static_cast<std::size_t>(c.u.size()) != dofs || c.state.size() != state_size ||
      (!c.drive_cur.empty() && c.drive_cur.size() != c.hist_cur.size() * 3) ||
      (!c.unchecked_damage.empty() && !c.hist_cur.empty() && c.unchecked_damage.size() * 2 != c.hist_cur.size()) ||
      std::any_of(c.cycle_ends.begin(), c.cycle_ends.end(), [&](const std::vector<double>& h) { return h.size() != state_size; }))
    throw InputError("checkpoint: it belongs to a different model (dofs or material history size differ); "
                     "resume with the run's own scene.toml");
  return c;
}

// ------------------------------------------------------------------ run
QuasiStaticRun::QuasiStaticRun(const Assembler& assembler, QuasiStaticOptions options)
    : asm_(assembler), opt_(options), newton_(assembler, options.newton) {
  u_ = Eigen::VectorXd::Zero(asm_.num_dofs());
  state_ = asm_.initial_state();
  rate_dependent_ = !state_.empty();
  if (!(opt_.time_tol > 0.0) || !std::isfinite(opt_.time_tol))
    throw InputError("quasi-static run: time_tol must be a finite number > 0");
  if (!(opt_.min_dt_s > 0.0) || !(opt_.max_dt_s >= opt_.min_dt_s) || !std::isfinite(opt_.max_dt_s))
    throw InputError("quasi-static run: need 0 < min_dt_s <= max_dt_s (finite)");
  if (opt_.cycle_jump.on) {
    if (!(opt_.cycle_jump.tol > 0.0) || !(opt_.cycle_jump.change > 0.0))
      throw InputError("quasi-static run: cycle jumping needs tol > 0 and change > 0");
    if (opt_.cycle_jump.order != 1 && opt_.cycle_jump.order != 2)
      throw InputError("quasi-static run: cycle jumping's order must be 1 (linear) or 2 (three-point), got " +
                       std::to_string(opt_.cycle_jump.order));
    std::string law;
    if (!model_jumps_cycles(asm_, law))
      throw InputError("cycle jumping: the material '" + law + "' does not say how its history extrapolates over "
                       "trials (Material::jumps_cycles); switch cycle jumping off for this model");
  }
  if (opt_.time_control == TimeControl::Drive && rate_dependent_) {
    // Each point's law's linear drive, as an index into the distinct kinds (a few per model).
    drive_kind_.assign(static_cast<std::size_t>(asm_.num_points()), -1);
    for (int p = 0; p < asm_.num_points(); ++p) {
      const Material::LinearDrive d = asm_.model().material_of(asm_.element_of_point(p)).linear_drive();
      if (d.terms == 0) continue;
      auto it = std::find(drive_kinds_.begin(), drive_kinds_.end(), d);
      if (it == drive_kinds_.end()) it = drive_kinds_.insert(drive_kinds_.end(), d);
      drive_kind_[static_cast<std::size_t>(p)] = static_cast<int>(it - drive_kinds_.begin());
    }
  }
}

double QuasiStaticRun::drive_step(double h, double ed, const std::vector<double>& c_kind, double target, double lo,
                                  double hi) const {
  auto predicted = [&](double x) {
    double e = ed * (x / h) * (x / h);
    double ev = 0.0;
    for (std::size_t k = 0; k < drive_kinds_.size(); ++k) ev = std::max(ev, linear_drive_error(drive_kinds_[k], c_kind[k], x));
    return e + ev;
  };
  if (predicted(hi) <= target) return hi;
  if (predicted(lo) >= target) return lo;
  // The prediction increases with the step: bisection in log h, to 0.1 % of the step.
  double a = lo, b = hi;
  while (b > 1.001 * a) {
    const double m = std::sqrt(a * b);
    (predicted(m) <= target ? a : b) = m;
  }
  return a;
}

double QuasiStaticRun::first_hold_step() const {
  const std::vector<double> hs = hist_cur_.empty() ? asm_.history_scalars(state_) : hist_cur_;
  std::vector<double> c(drive_kinds_.size(), 0.0);
  for (std::size_t p = 0; p < drive_kind_.size(); ++p)
    if (drive_kind_[p] >= 0) c[static_cast<std::size_t>(drive_kind_[p])] = std::max(c[static_cast<std::size_t>(drive_kind_[p])], hs[2 * p + 1]);
  for (std::size_t k = 0; k < c.size(); ++k) {
    const Material::LinearDrive& d = drive_kinds_[k];
    const double tau_min = *std::min_element(d.tau_s.begin(), d.tau_s.begin() + d.terms);
    c[k] *= d.recovery / (tau_min * tau_min);  // the bound |D''| <= recovery v / tau_min^2
  }
  return drive_step(1.0, 0.0, c, 0.9 * opt_.time_tol, opt_.min_dt_s, opt_.max_dt_s);
}

std::vector<QuasiStaticRun::Segment> QuasiStaticRun::segments(const LoadHistory& load) {
  std::vector<Segment> out;
  double g = 0.0;
  for (std::size_t k = 0; k < load.trials.size(); ++k) {
    const TrialLoad& tl = load.trials[k];
    const int tr = static_cast<int>(k);
    if (k > 0) {
      // Release to zero at the end of the previous trial, rest, then the new trial's start.
      const double p_end = load.trials[k - 1].pressure_Pa.back();
      out.push_back({tr, 0, 0, g, g, p_end, 0.0, false});
      if (load.rest_between_trials_s > 0) {
        out.push_back({tr, 0, 0, g, g + load.rest_between_trials_s, 0.0, 0.0, false});
        g += load.rest_between_trials_s;
      }
      out.push_back({tr, 0, 0, g, g, 0.0, tl.pressure(0.0), false});
    }
    std::vector<double> times = tl.time_s;
    times.insert(times.end(), tl.output_s.begin(), tl.output_s.end());
    std::sort(times.begin(), times.end());
    times.erase(std::unique(times.begin(), times.end(), [](double a, double b) { return std::abs(a - b) < 1e-12; }),
                times.end());
    auto is_output = [&](double t) {
      return std::any_of(tl.output_s.begin(), tl.output_s.end(), [&](double o) { return std::abs(o - t) < 1e-12; });
    };
    if (is_output(times.front())) {
      const double t = times.front();
      out.push_back({tr, t, t, g + t, g + t, tl.pressure(t), tl.pressure(t), true});
    }
    for (std::size_t i = 1; i < times.size(); ++i)
      out.push_back({tr, times[i - 1], times[i], g + times[i - 1], g + times[i], tl.pressure(times[i - 1]),
                     tl.pressure(times[i]), is_output(times[i])});
    g += tl.duration();
  }
  return out;
}

void QuasiStaticRun::equilibrium(double p0, double p1, double t0, double t1) {
  if (opt_.method == EquilibriumMethod::Newton) {
    newton_.advance(p0, p1, t0, t1, state_, u_);
  } else {
    std::vector<double> trial(state_.size());
    RelaxationReport r = relax(asm_, p1, TimeStep{t1, t1 - t0}, state_, trial, u_, opt_.relaxation);
    stats_.relaxation_iterations += r.iterations;
    if (!r.converged) {
      std::ostringstream s;
      s << "dynamic relaxation did not converge at p = " << p1 * 1e-3 << " kPa, t = " << t1 << " s in "
        << r.iterations << " iterations (residual " << r.residual_N << " N). Hint: raise "
        << "solver.relaxation_max_iterations or use solver.method = \"newton\".";
      throw PhysicsError(s.str(), -1, t1);
    }
    state_.swap(trial);
    asm_.update_nonlocal(u_, state_);
  }
  ++stats_.states;
}

void QuasiStaticRun::solve_instant_segment(const Segment& s) {
  const double span = s.g1 - s.g0;
  const bool drive_control = opt_.time_control == TimeControl::Drive;
  const bool solved = span > 0.0 || s.p0 != s.p1;
  if (solved) equilibrium(s.p0, s.p1, s.g0, s.g1);
  if (drive_control && !solved) return;  // nothing changed: the control's memory is still valid
  hist_prev_.clear();  // a jump or an elastic state: the history memory is stale
  hist_cur_.clear();
  drive_prev_.clear();
  drive_cur_.clear();
  damage_grew_ = false;  // rates start afresh after a jump (a release stops the damage)
  if (drive_control) unchecked_.assign(unchecked_.size(), 0.0);  // a new trial's budget
  ramp_start_dp_[0] = ramp_start_dp_[1] = 0.0;  // a release: the next ramps start a new climb
}

PhysicsError QuasiStaticRun::stalled(const Segment& s, double t, double last_h, double last_change,
                                     int last_element) const {
  std::ostringstream m;
  m << "physical time stepping stalled: " << opt_.max_segment_steps << " steps in the load segment "
    << s.g0 << " -> " << s.g1 << " s (global time; pressure " << s.p0 * 1e-3 << " -> " << s.p1 * 1e-3
    << " kPa) reached only t = " << t << " s; last step " << last_h << " s with a history change of "
    << last_change << " (time_tol " << opt_.time_tol << ")";
  if (last_element >= 0) m << ", fastest at " << asm_.model().mesh.element_label(last_element);
  m << ". Hint: "
    << "damage or viscous strain there changes faster than time_tol per min_dt_s (a point running away: "
       "check the damage constants, e.g. a smaller fatigue rate or a saturating law, fatigue.n > 1), or "
       "raise solver.time_tol / solver.max_segment_steps if the history is meant to change this fast";
  return PhysicsError(m.str(), last_element, t);
}

struct QuasiStaticRun::StepMeasure {
  std::vector<double> hist_new;       ///< the history's scalars after the step
  std::vector<double> drive_new;      ///< drive control: the linear drives after the step
  std::vector<double> unchecked_new;  ///< drive control: the points' unchecked budgets after the step
  double change = 0.0;                ///< the largest change of a point's history
  double measure = 0.0;               ///< what time_tol bounds: the change or the error estimate
  double order = 1.0;                 ///< how the measure scales with h
  int worst_point = -1;               ///< the point of the measure (-1: none)
  bool estimate = false;              ///< the measure is an error estimate (a previous step is known)
  double ed_max = 0.0;                ///< drive control: the largest damage error (predicts the next step)
  std::vector<double> c_kind;         ///< drive control: the largest |D''| per drive kind
  bool damage_grew = false;           ///< drive control: a point's damage changed
};

QuasiStaticRun::StepMeasure QuasiStaticRun::measure_step(const std::vector<double>& state_saved, double h,
                                                         bool hold_start) {
  // Error control with a previous step at the same load rate bounds the local-error estimate;
  // otherwise time_tol bounds the change. `order`: how the measure scales with h.
  StepMeasure sm;
  sm.hist_new = asm_.history_scalars(state_);
  if (hist_cur_.empty()) hist_cur_ = asm_.history_scalars(state_saved);
  if (opt_.time_control == TimeControl::Drive) {
    measure_drive_step(state_saved, h, hold_start, sm);
    return sm;
  }
  const bool error_control = opt_.time_control == TimeControl::Error;
  sm.estimate = error_control && !hist_prev_.empty() && h_prev_ > 0.0;
  static const std::vector<double> kNoPrevious;
  const HistoryStep hs =
      history_step(sm.estimate ? hist_prev_ : kNoPrevious, hist_cur_, sm.hist_new, sm.estimate ? h / h_prev_ : 0.0);
  sm.change = hs.change, sm.measure = sm.estimate ? hs.error : hs.change, sm.order = sm.estimate ? 2.0 : 1.0;
  sm.worst_point = sm.estimate ? hs.error_point : hs.change_point;
  return sm;
}

void QuasiStaticRun::measure_drive_step(const std::vector<double>& state_saved, double h, bool hold_start,
                                        StepMeasure& sm) {
  const std::vector<double>& hist_new = sm.hist_new;
  double &change = sm.change, &measure = sm.measure, &ed_max = sm.ed_max;
  int& worst_point = sm.worst_point;
  std::vector<double>& c_kind = sm.c_kind;
  std::vector<double>& drive_new = sm.drive_new;
  std::vector<double>& unchecked_new = sm.unchecked_new;
  drive_new = asm_.linear_drives(state_);
  if (drive_cur_.empty()) drive_cur_ = asm_.linear_drives(state_saved);
  const bool estimate = sm.estimate = !hist_prev_.empty() && !drive_prev_.empty() && h_prev_ > 0.0;
  c_kind.assign(drive_kinds_.size(), 0.0);
  const double r = estimate ? h / h_prev_ : 0.0;
  // Only the damage's change counts on a hold's first step: the viscous strain's is bounded by
  // the step's length (first_hold_step).
  const bool damage_only = hold_start && !estimate;
  const int n = static_cast<int>(hist_new.size() / 2);
  if (unchecked_.size() != static_cast<std::size_t>(n)) unchecked_.assign(static_cast<std::size_t>(n), 0.0);
  unchecked_new = unchecked_;
  int change_point = -1;
  sm.damage_grew = false;
  for (int p = 0; p < n; ++p) {
    const std::size_t i = 2 * static_cast<std::size_t>(p);
    const double dd = hist_new[i] - hist_cur_[i];
    const double c = std::abs(dd) + std::abs(hist_new[i + 1] - hist_cur_[i + 1]);
    if (c > change) change = c, change_point = p;
    if (dd != 0.0) sm.damage_grew = true;
    double m = 0.0;
    const int kind = drive_kind_[static_cast<std::size_t>(p)];
    // The stress (in viscous-strain units) this step's damage change can move: |dd| |S0_undamaged|
    // / (2 mu_inf) = |dd| max(|D|, |D'|) / (1 - d'), and whether the point's unchecked budget
    // (engine/quasi_static.h) still covers it.
    double moved = 0.0;
    if (dd != 0.0 && kind >= 0) {
      double n0 = 0.0, n1 = 0.0;
      for (std::size_t j = 6 * static_cast<std::size_t>(p); j < 6 * static_cast<std::size_t>(p) + 6; ++j)
        n0 += drive_cur_[j] * drive_cur_[j], n1 += drive_new[j] * drive_new[j];
      moved = std::abs(dd) * std::sqrt(std::max(n0, n1)) / std::max(1e-12, 1.0 - hist_new[i]);
    }
    const bool damaging = dd != 0.0 || (estimate && hist_cur_[i] != hist_prev_[i]);
    const bool within_budget = kind >= 0 && unchecked_[static_cast<std::size_t>(p)] + moved <= opt_.time_tol;
    const bool proxy = estimate && damaging && !within_budget;
    if (estimate && damaging && !proxy) unchecked_new[static_cast<std::size_t>(p)] += moved;
    if (proxy) {
      // A damaging point: Milne's estimate on damage and viscous strain, as the error control.
      for (std::size_t k = i; k < i + 2; ++k)
        m += std::abs((hist_new[k] - hist_cur_[k]) - r * (hist_cur_[k] - hist_prev_[k]));
      m *= r / (1.0 + r);
      ed_max = std::max(ed_max, m);
    } else if (estimate) {
      const int k = kind;
      if (k >= 0) {
        double c2 = 0.0;
        for (std::size_t j = 6 * static_cast<std::size_t>(p); j < 6 * static_cast<std::size_t>(p) + 6; ++j) {
          const double d2 = 2.0 * ((drive_new[j] - drive_cur_[j]) / h - (drive_cur_[j] - drive_prev_[j]) / h_prev_) / (h + h_prev_);
          c2 += d2 * d2;
        }
        const double curvature = std::sqrt(c2);
        c_kind[static_cast<std::size_t>(k)] = std::max(c_kind[static_cast<std::size_t>(k)], curvature);
        m += linear_drive_error(drive_kinds_[static_cast<std::size_t>(k)], curvature, h);
      }
    } else {
      m = damage_only ? std::abs(dd) : c;
    }
    if (m > measure) measure = m, worst_point = p;
  }
  if (!estimate && worst_point < 0) worst_point = change_point;
}

double QuasiStaticRun::next_step(double h, const StepMeasure& sm, bool rejected) const {
  const bool drive_estimate = opt_.time_control == TimeControl::Drive && sm.estimate;
  if (rejected) {
    if (drive_estimate)
      return std::max(opt_.min_dt_s, drive_step(h, sm.ed_max, sm.c_kind, 0.9 * opt_.time_tol, 0.2 * h, h));
    return std::max(opt_.min_dt_s, h * std::max(0.2, std::pow(0.9 * opt_.time_tol / sm.measure, 1.0 / sm.order)));
  }
  if (drive_estimate)
    return std::clamp(drive_step(h, sm.ed_max, sm.c_kind, 0.9 * opt_.time_tol, 0.5 * h, 2.0 * h), opt_.min_dt_s,
                      opt_.max_dt_s);
  const double grow =
      sm.measure > 0.0 ? std::clamp(std::pow(0.9 * opt_.time_tol / sm.measure, 1.0 / sm.order), 0.5, 2.0) : 2.0;
  return std::clamp(h * grow, opt_.min_dt_s, opt_.max_dt_s);
}

QuasiStaticRun::SegmentStart QuasiStaticRun::start_segment(const Segment& s) {
  if (dt_suggest_ <= 0.0) dt_suggest_ = std::clamp(0.1, opt_.min_dt_s, opt_.max_dt_s);
  SegmentStart st;
  st.rate = (s.p1 - s.p0) / (s.g1 - s.g0);
  // A kink of the load (its rate changes): the last step's rate says nothing about this one.
  const bool kink = std::abs(st.rate - rate_prev_) > 1e-9 * (std::abs(st.rate) + std::abs(rate_prev_));
  if (kink) hist_prev_.clear(), drive_prev_.clear();
  // A ramp that starts after a hold would otherwise be tried in the hold's long step, i.e. over the
  // whole ramp: a full Newton solve of the load increment, then rejected for its history change
  // and cut down by at most 5x per try (2-3 rejected solves per ramp of the staircase, ~27 % of a
  // trial's Newton iterations at h = 6). The previous ramp's start in the same direction, as a
  // pressure increment, is a far better first guess: ramps of a climb get harder, so it is at
  // worst rejected as a short step. Forgotten at a release (span 0), where a new climb starts.
  // Only ramps after a hold (rate 0, as in a staircase) use and set it: between the segments of
  // a sampled pressure record the rate changes at every sample, and an increment learnt on a slow
  // segment would needlessly shorten the next fast one.
  st.dir = st.rate > 0.0 ? 1 : 0;
  st.ramp_start = kink && st.rate != 0.0 && rate_prev_ == 0.0;
  if (st.ramp_start && ramp_start_dp_[st.dir] > 0.0)
    dt_suggest_ = std::max(opt_.min_dt_s, std::min(dt_suggest_, ramp_start_dp_[st.dir] / std::abs(st.rate)));
  // Drive control: a hold or rest with no curvature known yet starts from the relaxation times.
  st.hold_start = opt_.time_control == TimeControl::Drive && st.rate == 0.0 && !drive_kinds_.empty() && !damage_grew_ &&
                  (hist_prev_.empty() || drive_prev_.empty());
  if (st.hold_start) dt_suggest_ = first_hold_step();
  return st;
}

void QuasiStaticRun::accept_step(StepMeasure& sm, double h, double rate) {
  const bool drive_control = opt_.time_control == TimeControl::Drive;
  if (opt_.time_control == TimeControl::Error || drive_control) {
    hist_prev_ = std::move(hist_cur_);
    h_prev_ = h;
  }
  if (drive_control) {
    drive_prev_ = std::move(drive_cur_);
    drive_cur_ = std::move(sm.drive_new);
    unchecked_ = std::move(sm.unchecked_new);
    damage_grew_ = sm.damage_grew;
  }
  hist_cur_ = std::move(sm.hist_new);
  rate_prev_ = rate;
}

// One loop, on purpose: a step's save of u_, state_ and the Newton path, its solve, its measure and
// its rejection (restore) or acceptance share that saved state; the parts with a name of their own
// (the instant segment, the segment's start, the measures, the next step, the acceptance, the stall
// message) are functions.
void QuasiStaticRun::solve_segment(const Segment& s) {
  // A segment starts from what a checkpoint holds, and the factorisation is not in it: forgetting
  // it here makes a resumed run continue bit for bit from any segment boundary (engine/quasi_static.h).
  newton_.forget_factor();
  const double span = s.g1 - s.g0;
  if (!rate_dependent_ || span <= 0.0) return solve_instant_segment(s);
  auto p_at = [&](double g) { return s.p0 + (s.p1 - s.p0) * (g - s.g0) / span; };
  const SegmentStart start = start_segment(s);
  bool first_step = true;
  double t = s.g0;
  long steps = 0;
  double last_change = 0.0, last_h = 0.0;
  int last_element = -1;
  while (t < s.g1 - 1e-12 * (1.0 + std::abs(s.g1))) {
    if (++steps > opt_.max_segment_steps) throw stalled(s, t, last_h, last_change, last_element);
    // A step is "minimal" when the control already asks for min_dt_s: it is then accepted whatever
    // the history change (or the run stops if its equilibrium fails). Testing h instead would loop
    // forever when the sliver rule below stretches a minimal step just above min_dt_s: rejected,
    // retried at min_dt_s, stretched again (seen in the 10-trial story runs before 2026-11-23).
    const bool minimal = dt_suggest_ <= opt_.min_dt_s * (1.0 + 1e-9);
    double h = std::min(dt_suggest_, s.g1 - t);
    if (s.g1 - (t + h) < 0.25 * h) h = s.g1 - t;  // do not leave a sliver
    const bool by_control = h == dt_suggest_;  // not cut or stretched to the segment's end
    const Eigen::VectorXd u_saved = u_;
    const std::vector<double> state_saved = state_;
    const StaticSolver::Path path_saved = newton_.path();
    auto reject = [&] {
      u_ = u_saved;
      state_ = state_saved;
      newton_.set_path(path_saved);
      ++stats_.rejected_steps;
    };
    try {
      equilibrium(p_at(t), p_at(t + h), t, t + h);
    } catch (const PhysicsError& e) {
      // A shorter physical step keeps the history change (and the equilibrium shift) smaller.
      if (minimal || h <= opt_.min_dt_s * (1.0 + 1e-9)) throw;
      if (opt_.newton.verbose)
        std::fprintf(stderr, "  physical step t = %.6g s, h = %.3g s, p = %.4g kPa: equilibrium failed (rejected): %s\n",
                     t + h, h, p_at(t + h) * 1e-3, e.what());
      reject();
      dt_suggest_ = std::max(opt_.min_dt_s, 0.25 * h);
      continue;
    }
    StepMeasure sm = measure_step(state_saved, h, start.hold_start);
    last_element = sm.worst_point >= 0 ? asm_.element_of_point(sm.worst_point) : -1;
    last_change = sm.change;
    last_h = h;
    const bool too_far = sm.measure > 2.0 * opt_.time_tol && !minimal && h > opt_.min_dt_s * (1.0 + 1e-9);
    if (opt_.newton.verbose)
      std::fprintf(stderr, "  physical step t = %.6g s, h = %.3g s, p = %.4g kPa: history %s %.3g (tol %.3g) at %s%s\n",
                   t + h, h, p_at(t + h) * 1e-3, sm.estimate ? "error estimate" : "change", sm.measure, opt_.time_tol,
                   last_element >= 0 ? asm_.model().mesh.element_label(last_element).c_str() : "-", too_far ? " (rejected)" : "");
    dt_suggest_ = next_step(h, sm, too_far);
    if (too_far) {
      reject();
      continue;
    }
    // The ramp's first step, when the control (not the segment's end) set its length: the step
    // the control would now take, as a pressure increment, starts the next ramp.
    if (start.ramp_start && first_step && by_control) ramp_start_dp_[start.dir] = dt_suggest_ * std::abs(start.rate);
    first_step = false;
    accept_step(sm, h, start.rate);
    t += h;
  }
}

namespace {
/// (2') of engine/cycle_jump.h: the largest second difference of the last three trials' reported
/// angles over the last trial's largest |angle|, at least 1 deg (a structure that hardly bends, such
/// as a test block, is not judged relative to the round-off of its angle); 0 without three trials.
double report_second_difference(const std::vector<std::vector<StateRecord>>& trials) {
  if (trials.size() < 3) return 0.0;
  const std::vector<StateRecord>&a = trials[0], &b = trials[1], &c = trials[2];
  double d2 = 0.0, scale = 1.0;
  for (std::size_t r = 0; r < c.size() && r < a.size() && r < b.size(); ++r) {
    d2 = std::max(d2, std::abs(c[r].angle_deg - 2.0 * b[r].angle_deg + a[r].angle_deg));
    scale = std::max(scale, std::abs(c[r].angle_deg));
  }
  return d2 / scale;
}

/// True when every trial of `load` repeats the first one's load and reports.
bool trials_repeat(const LoadHistory& load) {
  const TrialLoad& t0 = load.trials.front();
  for (const TrialLoad& t : load.trials) {
    if (t.time_s != t0.time_s || t.pressure_Pa != t0.pressure_Pa || t.output_s != t0.output_s) return false;
  }
  return true;
}
}  // namespace

std::size_t QuasiStaticRun::end_of_trial(const std::vector<Segment>& segs, std::size_t i, const Observer& observer) {
  cycle_ends_.push_back(state_);
  if (cycle_ends_.size() > 3) cycle_ends_.erase(cycle_ends_.begin());
  cycle_reports_.push_back(std::move(trial_reports_));
  trial_reports_.clear();
  if (cycle_reports_.size() > 3) cycle_reports_.erase(cycle_reports_.begin());
  const int trial = segs[i].trial;  // 0-based, just ended
  const int last_trial = segs.back().trial;
  if (cycle_ends_.size() < 3 || last_trial - trial < 2) return i;
  // (2) and (3) of cycle_jump.h: the one-cycle prediction of this trial's end against the computed one.
  const std::vector<double> predicted = jump_history(asm_, cycle_ends_[0], cycle_ends_[1], 1.0);
  const std::vector<double> share = energy_shares(asm_, u_, state_);  // at the trial's end, loaded
  const double e1 = history_jump_error(asm_, share, predicted, cycle_ends_[2]);
  const double c1 = history_jump_error(asm_, share, cycle_ends_[1], cycle_ends_[2]);
  const double ea = report_second_difference(cycle_reports_);
  const int n = cycles_to_jump(std::max(e1, ea), c1, opt_.cycle_jump, last_trial - trial - 1);
  if (opt_.newton.verbose)
    std::fprintf(stderr, "  cycle jump after trial %d: one-cycle error %.3g (reported angles %.3g), change %.3g -> skip %d trials\n",
                 trial + 1, e1, ea, c1, n);
  if (n < 1) return i;
  // (1') through the three trial ends, controlled by the linear rule's estimate (local extrapolation);
  // the linear jump itself is made only when it is the rule or is printed beside (1').
  if (opt_.cycle_jump.order == 1) {
    state_ = jump_history(asm_, cycle_ends_[1], cycle_ends_[2], n);
  } else {
    state_ = jump_history(asm_, cycle_ends_[0], cycle_ends_[1], cycle_ends_[2], n);
    if (opt_.newton.verbose)
      std::fprintf(stderr, "  cycle jump: the three-point rule differs from the linear one by %.3g (weighted as (2))\n",
                   history_jump_error(asm_, share, jump_history(asm_, cycle_ends_[1], cycle_ends_[2], n), state_));
  }
  // The skipped trials' reports, extrapolated linearly in the trial count from the last two trials.
  const std::vector<StateRecord>& a = cycle_reports_[cycle_reports_.size() - 2];
  const std::vector<StateRecord>& b = cycle_reports_.back();
  std::vector<StateRecord> last;
  std::size_t j = i + 1;
  for (int m = 1; m <= n; ++m) {
    last.clear();
    for (; j < segs.size() && segs[j].trial == trial + m; ++j) {
      const Segment& s = segs[j];
      if (!s.report) continue;
      const std::size_t r = last.size();
      StateRecord rec;
      rec.trial = s.trial + 1;
      rec.extrapolated = true;
      rec.time_s = s.t1;
      rec.global_time_s = s.g1;
      rec.pressure_Pa = s.p1;
      rec.angle_deg = b[r].angle_deg + m * (b[r].angle_deg - a[r].angle_deg);
      rec.cavity_volume_m3 = b[r].cavity_volume_m3 + m * (b[r].cavity_volume_m3 - a[r].cavity_volume_m3);
      rec.plane_rms_m = b[r].plane_rms_m;
      last.push_back(rec);
      last_angle_ = rec.angle_deg;
      if (observer) observer(rec, Eigen::VectorXd(), std::vector<double>());
    }
  }
  ++stats_.cycle_jumps;
  stats_.trials_extrapolated += n;
  // The extrapolated end of the last skipped trial starts the next run of consecutive trial ends.
  cycle_ends_.assign(1, state_);
  cycle_reports_.assign(1, std::move(last));
  return j - 1;
}

std::string QuasiStaticRun::failure_note() const {
  // Points a damage law has declared failed explain most stalls of damaged runs: say where.
  if (state_.empty()) return "";
  const Assembler::RegionFailures f = asm_.failed_points(state_);
  int total = 0, worst = -1;
  for (std::size_t r = 0; r < f.failed.size(); ++r) {
    total += f.failed[r];
    if (f.failed[r] > 0 && (worst < 0 || f.failed[r] * f.points[worst] > f.failed[worst] * f.points[r]))
      worst = static_cast<int>(r);
  }
  if (total == 0) return "";
  std::ostringstream m;
  const std::vector<std::string>& names = asm_.model().mesh.region_names;
  m << " [" << total << " material points had failed (damage >= d_fail) by then";
  if (!names.empty() && f.failed.size() == names.size())
    m << "; the largest share in region '" << names[static_cast<std::size_t>(worst)] << "', " << f.failed[worst]
      << " of its " << f.points[worst] << " points";
  else
    m << ", of " << f.points[0];
  m << ": a damage law is destroying that part, so the structure gives way (check its constants)]";
  return m.str();
}

void QuasiStaticRun::restore(const QuasiStaticCheckpoint& c) {
  dt_suggest_ = c.dt_suggest_s;
  last_angle_ = c.last_angle_deg;
  u_ = c.u;
  state_ = c.state;
  newton_.set_path({c.path_p, c.path_u});
  stats_ = c.stats;
  hist_prev_ = c.hist_prev;
  hist_cur_ = c.hist_cur;
  h_prev_ = c.h_prev_s;
  rate_prev_ = c.rate_prev_Pa_s;
  ramp_start_dp_[0] = c.ramp_start_dp_Pa[0];
  ramp_start_dp_[1] = c.ramp_start_dp_Pa[1];
  drive_prev_ = c.drive_prev;
  drive_cur_ = c.drive_cur;
  damage_grew_ = c.damage_grew;
  unchecked_ = c.unchecked_damage;
  cycle_ends_ = c.cycle_ends;
  cycle_reports_ = c.cycle_reports;
  trial_reports_ = c.trial_reports;
}

QuasiStaticCheckpoint QuasiStaticRun::checkpoint(std::size_t next_segment) const {
  QuasiStaticCheckpoint c;
  c.next_segment = next_segment;
  c.dt_suggest_s = dt_suggest_;
  c.last_angle_deg = last_angle_;
  c.u = u_;
  c.state = state_;
  const StaticSolver::Path path = newton_.path();
  c.path_p = path.p;
  c.path_u = path.u;
  c.stats = stats_;
  c.hist_prev = hist_prev_;
  c.hist_cur = hist_cur_;
  c.h_prev_s = h_prev_;
  c.rate_prev_Pa_s = rate_prev_;
  c.ramp_start_dp_Pa[0] = ramp_start_dp_[0];
  c.ramp_start_dp_Pa[1] = ramp_start_dp_[1];
  c.drive_prev = drive_prev_;
  c.drive_cur = drive_cur_;
  c.damage_grew = damage_grew_;
  c.unchecked_damage = unchecked_;
  c.cycle_ends = cycle_ends_;
  c.cycle_reports = cycle_reports_;
  c.trial_reports = trial_reports_;
  return c;
}

StateRecord QuasiStaticRun::report(const Segment& s) {
  StateRecord rec;
  rec.trial = s.trial + 1;
  rec.time_s = s.t1;
  rec.global_time_s = s.g1;
  rec.pressure_Pa = s.p1;
  const AngleResult a = bending_angle(asm_.model(), u_);
  rec.angle_deg = unwrap_deg(a.angle_deg, last_angle_);
  last_angle_ = rec.angle_deg;
  rec.plane_rms_m = a.plane_rms_m;
  rec.cavity_volume_m3 = asm_.cavity_volume(u_);
  return rec;
}

void QuasiStaticRun::run(const LoadHistory& load, const Observer& observer, const CheckpointSink& sink,
                         const QuasiStaticCheckpoint* resume) {
  const auto wall0 = std::chrono::steady_clock::now();
  const std::vector<Segment> segs = segments(load);
  // Cycle jumping needs a history to extrapolate and a repeated cycle to extrapolate over.
  const bool jumping = opt_.cycle_jump.on && rate_dependent_ && load.trials.size() > 3;
  if (jumping && !trials_repeat(load))
    throw InputError("cycle jumping: the trials of the load history differ (pressures, times or reports); it "
                     "extrapolates over repetitions of one cycle only. Switch cycle jumping off for this load");
  std::size_t first = 0;
  double wall_before = 0.0;
  if (resume) {
    first = resume->next_segment;
    restore(*resume);
    wall_before = stats_.wall_s;
  }
  // The run starts from u = 0, which is an equilibrium only without load. When the load history
  // starts loaded (a recording whose first pressure sample is not 0) or the rig has gravity, the
  // first state is solved before anything is reported: otherwise a report at t = 0 (the first frame
  // of a recording) would carry the unloaded shape, and the frames up to the next state an
  // interpolation from it (seen as a 0 -> sag ramp over the first 0.25 s of a gravity recording).
  if (!resume && !segs.empty()) {
    const Segment& s0 = segs.front();
    if (s0.p0 != 0.0 || !asm_.model().gravity_m_s2.isZero()) {
      try {
        equilibrium(0.0, s0.p0, s0.g0, s0.g0);
      } catch (const PhysicsError& e) {
        throw PhysicsError(std::string(e.what()) + failure_note(), e.element(), e.time_s());
      }
    }
  }
  for (std::size_t i = first; i < segs.size(); ++i) {
    const Segment& s = segs[i];
    try {
      solve_segment(s);
    } catch (const PhysicsError& e) {
      std::string msg = e.what();
      msg += failure_note();
      throw PhysicsError(msg, e.element(), e.time_s());
    }
    if (s.report) {
      const StateRecord rec = report(s);
      if (observer) observer(rec, u_, state_);
      if (jumping) trial_reports_.push_back(rec);
    }
    if (jumping && (i + 1 == segs.size() || segs[i + 1].trial != s.trial)) i = end_of_trial(segs, i, observer);
    stats_.wall_s = wall_before + std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    if (sink) sink(checkpoint(i + 1));
  }
  stats_.wall_s = wall_before + std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
}

}  // namespace pneufem

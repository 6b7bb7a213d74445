#include "app/synth/command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <set>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include "app/diagnose/effect_catalog.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/output_dir.h"
#include "core/progress.h"
#include "core/json_writer.h"
#include "core/version.h"
#include "engine/assembly.h"
#include "scenes/build_model.h"
#include "scenes/pressure_lag.h"
#include "scenes/scene_settings.h"

namespace pneufem {

namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Portable standard normal draws (Box-Muller on 53-bit uniforms): std::normal_distribution is
/// implementation-defined, and the data must be identical wherever it is generated.
class Noise {
 public:
  Noise(std::uint64_t seed, int trial, int stream) {
    std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                      static_cast<std::uint32_t>(trial), static_cast<std::uint32_t>(stream)};
    rng_.seed(seq);
  }
  double uniform() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }  // [0, 1)
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - uniform(), u2 = uniform();  // u1 in (0, 1]
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * kPi * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * kPi * u2);
  }

 private:
  std::mt19937_64 rng_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};


void check(bool ok, const std::string& option, const std::string& what) {
  if (!ok) throw InputError(option + ": " + what);
}

/// Linear interpolation of the (sorted) record times/angles at t.
double interpolate(const std::vector<double>& ts, const std::vector<double>& vs, double t) {
  if (t <= ts.front()) return vs.front();
  if (t >= ts.back()) return vs.back();
  const std::size_t i = static_cast<std::size_t>(std::upper_bound(ts.begin(), ts.end(), t) - ts.begin());
  const double w = (t - ts[i - 1]) / (ts[i] - ts[i - 1]);
  return (1.0 - w) * vs[i - 1] + w * vs[i];
}

std::string noise_json(const SynthOptions& o) {
  json::Object j;
  j.add("pressure_rate_Hz", o.pressure_rate_Hz)
      .add("angle_rate_Hz", o.angle_rate_Hz)
      .add("controller_natural_Hz", o.controller_hz)
      .add("controller_damping_ratio", o.controller_damping)
      .add("pressure_noise_kPa", o.pressure_noise_kPa)
      .add("angle_noise_deg", o.angle_noise_deg)
      .add("outlier_fraction", o.outlier_fraction)
      .add("outlier_min_deg", o.outlier_min_deg)
      .add("outlier_max_deg", o.outlier_max_deg)
      .add("report_every_s", o.report_every_s)
      .add("inlet_tolerance_kPa", o.inlet_tolerance_kPa);
  return j.str(2);
}

/// "key" of a "key=value" override.
std::string key_of(const std::string& set) { return set.substr(0, set.find('=')); }

/// truth.json's entry of one hidden effect: the truth as the simulation saw it. A --set (in
/// `user_keys`) may override a hidden effect's constant, so each parameter is read back from the
/// resolved scene where it maps to one scalar key (found by perturbing the parameter and seeing
/// which override changes); otherwise, when one of its keys was overridden, the value is unknown to
/// the catalog and written as null rather than wrong; so is a parameter whose key was replaced by
/// another representation (`replaced_keys`: a hidden rig angle under a --set gravity vector).
std::string effect_truth_json(const CandidateEffect& c, const std::vector<std::string>& sets, const Scene& base,
                              const Scene& resolved, const std::set<std::string>& user_keys,
                              const std::set<std::string>& replaced_keys, const std::vector<std::string>& user_sets) {
  json::Object params;
  std::vector<double> truth;
  for (const CandidateParameter& p : c.params) truth.push_back(p.truth);
  for (std::size_t i = 0; i < c.params.size(); ++i) {
    std::vector<double> bumped = truth;
    bumped[i] = truth[i] * 1.37 + 0.11;
    const std::vector<std::string> other = c.sets(base, bumped);
    std::vector<std::string> keys;
    for (std::size_t j = 0; j < sets.size() && j < other.size(); ++j)
      if (sets[j] != other[j]) keys.push_back(key_of(sets[j]));
    bool overridden = false, replaced = false;
    for (const std::string& k : keys) overridden = overridden || user_keys.count(k) > 0;
    for (const std::string& k : keys) replaced = replaced || replaced_keys.count(k) > 0;
    // The parameter is the key's value itself when one key changes and it holds exactly truth[i].
    bool direct = false;
    if (keys.size() == 1)
      for (const std::string& set : sets)
        if (key_of(set) == keys[0]) {
          char* end = nullptr;
          const std::string v = set.substr(keys[0].size() + 1);
          const double x = std::strtod(v.c_str(), &end);
          direct = end && *end == '\0' && std::abs(x - truth[i]) <= 1e-12 * std::abs(truth[i]);
        }
    if (replaced)
      params.add(c.params[i].name, std::string("null"));
    else if (!overridden)
      params.add(c.params[i].name, truth[i]);
    else if (direct)
      params.add(c.params[i].name, resolved.number(keys[0]));
    else
      params.add(c.params[i].name, std::string("null"));
  }
  // The overrides as the simulation applied them: a --set of the same key replaces the catalog's.
  std::string keys = "[";
  for (std::size_t i = 0; i < sets.size(); ++i) {
    std::string applied = sets[i];
    for (const std::string& u : user_sets)
      if (key_of(u) == key_of(sets[i])) applied = u;
    keys += (i ? ", " : "") + json::quote(applied);
  }
  json::Object e;
  e.add("truth", params.str(6)).add("sets", keys + "]");
  return e.str(4);
}

}  // namespace

CommandedSteps commanded_steps(const TrialLoad& trial) {
  CommandedSteps out;
  double prev = 0.0;
  for (std::size_t i = 0; i < trial.step_start_s.size(); ++i) {
    const double level_kPa = trial.step_level_Pa[i] * 1e-3;
    if (level_kPa != prev) {
      out.t_s.push_back(trial.step_start_s[i]);
      out.jump_kPa.push_back(level_kPa - prev);
    }
    prev = level_kPa;
  }
  return out;
}

double controller_pressure_kPa(const std::vector<double>& t_cmd, const std::vector<double>& dL, double f_n,
                               double zeta, double t) {
  const double w = 2.0 * kPi * f_n, wd = w * std::sqrt(1.0 - zeta * zeta), c = zeta / std::sqrt(1.0 - zeta * zeta);
  double p = 0.0;
  for (std::size_t k = 0; k < t_cmd.size(); ++k) {
    const double s = t - t_cmd[k];
    if (s < 0.0) continue;
    p += dL[k] * (1.0 - std::exp(-zeta * w * s) * (std::cos(wd * s) + c * std::sin(wd * s)));
  }
  return p;
}

std::vector<std::string> parse_hidden(const std::string& spec) {
  std::vector<std::string> out;
  std::string cur;
  for (std::size_t i = 0; i <= spec.size(); ++i) {
    if (i == spec.size() || spec[i] == ',') {
      cur.erase(0, cur.find_first_not_of(" \t"));
      cur.erase(cur.find_last_not_of(" \t") + 1);
      if (cur.empty()) throw InputError("--hidden " + spec + ": empty effect name; give EFFECT[,EFFECT...] or none");
      if (cur == "none") {
        if (spec.find(',') != std::string::npos) throw InputError("--hidden " + spec + ": 'none' cannot be combined with effects");
      } else {
        candidate_effect(cur);  // throws listing the valid names
        if (std::find(out.begin(), out.end(), cur) != out.end())
          throw InputError("--hidden " + spec + ": '" + cur + "' is given twice");
        out.push_back(cur);
      }
      cur.clear();
    } else {
      cur += spec[i];
    }
  }
  return out;
}

namespace {

void check_options(const SynthOptions& o) {
  check(!o.out_csv.empty(), "--out", "give the output file, e.g. --out data.csv");
  check_output_file(o.out_csv, "--out");  // before the model runs: a bad --out fails now
  check(o.pressure_rate_Hz > 0 && std::isfinite(o.pressure_rate_Hz), "--pressure-rate", "must be > 0 Hz");
  check(o.angle_rate_Hz > 0 && std::isfinite(o.angle_rate_Hz), "--angle-rate", "must be > 0 Hz");
  check(o.controller_hz > 0 && std::isfinite(o.controller_hz), "--controller-hz", "must be > 0 Hz");
  check(o.controller_damping > 0 && o.controller_damping < 1, "--controller-damping",
        "must lie in (0, 1) (an underdamped controller; 0.65 gives ~7 % overshoot)");
  check(o.pressure_noise_kPa >= 0, "--pressure-noise", "must be >= 0 kPa");
  check(o.angle_noise_deg >= 0, "--angle-noise", "must be >= 0 deg");
  check(o.outlier_fraction >= 0 && o.outlier_fraction <= 1, "--outliers", "must lie in [0, 1]");
  check(o.outlier_min_deg >= 0 && o.outlier_max_deg >= o.outlier_min_deg, "--outlier-range", "needs 0 <= min <= max deg");
  check(o.report_every_s > 0, "--report-every", "must be > 0 s");
  check(o.inlet_tolerance_kPa > 0, "--inlet-tolerance", "must be > 0 kPa");
}

/// The scene with the hidden effects (their overrides in res.hidden_sets), their names and what
/// truth.json says of each.
struct HiddenScene {
  Scene scene;
  std::vector<std::string> hidden;
  json::Object effects;
};

// 1. The scene with the hidden effects; --set last so it overrides a hidden effect's value.
HiddenScene hidden_scene(const SynthOptions& o, SynthResult& res) {
  const Scene base = Scene::load(o.scene_path, o.sets);
  std::vector<std::string> hidden = o.hidden;
  hidden.erase(std::remove(hidden.begin(), hidden.end(), std::string("none")), hidden.end());
  std::vector<std::pair<const CandidateEffect*, std::vector<std::string>>> effect_sets;
  for (const std::string& name : hidden) {
    const CandidateEffect& c = candidate_effect(name);
    std::vector<double> values;
    for (const CandidateParameter& p : c.params) values.push_back(p.truth);
    effect_sets.emplace_back(&c, c.sets(base, values));
    res.hidden_sets.insert(res.hidden_sets.end(), effect_sets.back().second.begin(), effect_sets.back().second.end());
  }
  std::set<std::string> user_keys;
  for (const std::string& set : o.sets) user_keys.insert(key_of(set));
  // Hidden gravity is a rig angle (in the actuator's frame); a gravity vector given with --set replaces
  // it, as any --set replaces a hidden effect's constant (the two cannot be combined in a scene), and
  // its angle is then unknown to the catalog (null in truth.json).
  std::vector<std::string> user_sets = o.sets;
  std::set<std::string> replaced_keys;
  if (user_keys.count("gravity.g_m_s2") && !user_keys.count("gravity.rig_angle_deg")) {
    user_sets.push_back("gravity.rig_angle_deg=-1.0");
    replaced_keys.insert("gravity.rig_angle_deg");
  }
  HiddenScene h{base.with(res.hidden_sets).with(user_sets), hidden, {}};
  for (const auto& [c, sets] : effect_sets)
    h.effects.add(c->name, effect_truth_json(*c, sets, base, h.scene, user_keys, replaced_keys, user_sets));
  if (load_settings(h.scene).protocol != LoadSettings::Protocol::Staircase)
    h.scene.fail("load.protocol", "synth commands the staircase protocol through its controller model; use \"staircase\"");
  if (solver_settings(h.scene).mode != SolverSettings::Mode::QuasiStatic)
    h.scene.fail("solver.mode", "synth runs the quasi-static model; use \"quasi_static\"");
  return h;
}

/// The controller's inlet: per trial the commanded steps (start times t_cmd, jumps dL in kPa) and
/// the piecewise-linear fit of the controller's response to them.
struct ControllerInlet {
  LoadHistory inlet;
  std::vector<std::vector<double>> t_cmd, dL;

  double pressure_kPa(std::size_t k, const SynthOptions& o, double t) const {
    return controller_pressure_kPa(t_cmd[k], dL[k], o.controller_hz, o.controller_damping, t);
  }
};

// 2. True inlet per trial and its piecewise-linear fit. The commanded steps are those of the
// scene's staircase, built where every command builds it (inlet_load, before any chamber lag).
ControllerInlet controller_inlet(const LoadHistory& commanded, const SynthOptions& o) {
  ControllerInlet ci{commanded, std::vector<std::vector<double>>(commanded.trials.size()),
                     std::vector<std::vector<double>>(commanded.trials.size())};
  for (std::size_t k = 0; k < commanded.trials.size(); ++k) {
    const TrialLoad& c = commanded.trials[k];
    const CommandedSteps steps = commanded_steps(c);
    ci.t_cmd[k] = steps.t_s;
    ci.dL[k] = steps.jump_kPa;
    const double T = c.duration();
    const long n = static_cast<long>(std::floor(T * o.pressure_rate_Hz + 1e-9));
    std::vector<double> ts, ps;
    for (long i = 0; i <= n; ++i) ts.push_back(static_cast<double>(i) / o.pressure_rate_Hz);
    if (ts.back() < T) ts.push_back(T);
    for (double t : ts) ps.push_back(controller_pressure_kPa(ci.t_cmd[k], ci.dL[k], o.controller_hz, o.controller_damping, t));
    const std::vector<char> keep = rdp_keep(ts, ps, o.inlet_tolerance_kPa);
    TrialLoad& tl = ci.inlet.trials[k];
    tl.time_s.clear();
    tl.pressure_Pa.clear();
    for (std::size_t i = 0; i < ts.size(); ++i)
      if (keep[i]) {
        tl.time_s.push_back(ts[i]);
        tl.pressure_Pa.push_back(ps[i] * 1e3);
      }
  }
  return ci;
}

// 3. The chamber's pressure (the inlet through the scene's lag, first or second order) with a
// report at every breakpoint (t = 0 included) and in holds every o.report_every_s.
LoadHistory chamber_history(const Scene& scene, const LoadHistory& commanded, const LoadHistory& inlet,
                            const SynthOptions& o) {
  const PressureLag lag = scene_pressure_lag(scene);  // first or second order (load.pressure_lag2_s)
  LoadHistory chamber = lag.on() ? apply_pressure_lag(inlet, lag, o.inlet_tolerance_kPa * 1e3) : inlet;
  for (TrialLoad& tl : chamber.trials) {
    std::vector<double> out = tl.time_s;  // a state at every breakpoint (t = 0 included) ...
    for (double t = o.report_every_s; t < tl.duration(); t += o.report_every_s) out.push_back(t);  // ... and in holds
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end(), [](double a, double b) { return std::abs(a - b) < 1e-9; }), out.end());
    tl.output_s = out;
  }
  chamber.description = "synth: " + commanded.description + " through a second-order controller" +
                        (lag.on() ? " and a chamber lag" : "");
  return chamber;
}

/// The model's angle at its reports, per trial.
struct ModelAngles {
  std::vector<std::vector<double>> t_s, angle_deg;
};

ModelAngles solve_angles(const BuiltModel& bm, const LoadHistory& chamber, const SynthOptions& o, SynthResult& res) {
  ModelAngles m{std::vector<std::vector<double>>(chamber.trials.size()), std::vector<std::vector<double>>(chamber.trials.size())};
  const Assembler asmb(bm.model);
  QuasiStaticRun run(asmb, bm.solver.quasi_static);
  ProgressMeter progress("synth", o.progress                     ? ProgressMeter::Mode::Terminal
                                  : o.progress_log_every_s > 0.0 ? ProgressMeter::Mode::Log
                                                                 : ProgressMeter::Mode::Off,
                         o.progress_log_every_s);
  std::vector<double> before(chamber.trials.size() + 1, 0.0);  // the protocol's time before each trial
  for (std::size_t k = 0; k < chamber.trials.size(); ++k) before[k + 1] = before[k] + chamber.trials[k].duration();
  run.run(chamber, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) {
    m.t_s[r.trial - 1].push_back(r.time_s);
    m.angle_deg[r.trial - 1].push_back(r.angle_deg);
    char d[96];
    std::snprintf(d, sizeof d, "trial %d/%zu, %.1f kPa, %.2f deg", r.trial, chamber.trials.size(), r.pressure_Pa * 1e-3, r.angle_deg);
    progress.update(before.back() > 0.0 ? (before[static_cast<std::size_t>(r.trial - 1)] + r.time_s) / before.back() : 0.0, d);
  });
  res.states = run.stats().states;
  return m;
}

// 4. Sampling and noise of trial k (0-based): its data and truth recordings into `res`.
void sample_trial(std::size_t k, double T, const ControllerInlet& ci, const ModelAngles& m, const SynthOptions& o,
                  SynthResult& res) {
  const int trial = static_cast<int>(k) + 1;
  TrialRecording data, truth;
  data.trial = truth.trial = trial;
  Noise pn(o.seed, trial, 0), an(o.seed, trial, 1), on(o.seed, trial, 2);
  const long np = static_cast<long>(std::floor(T * o.pressure_rate_Hz + 1e-9));
  for (long i = 0; i <= np; ++i) {
    const double t = static_cast<double>(i) / o.pressure_rate_Hz;
    const double p = ci.pressure_kPa(k, o, t);
    data.pressure_kPa.t_s.push_back(t);
    data.pressure_kPa.value.push_back(p + o.pressure_noise_kPa * pn.normal());
  }
  const long na = static_cast<long>(std::floor(T * o.angle_rate_Hz + 1e-9));
  for (long j = 0; j <= na; ++j) {
    const double t = static_cast<double>(j) / o.angle_rate_Hz;
    const double a = interpolate(m.t_s[k], m.angle_deg[k], t);
    truth.pressure_kPa.t_s.push_back(t);
    truth.pressure_kPa.value.push_back(ci.pressure_kPa(k, o, t));
    truth.angle_deg.t_s.push_back(t);
    truth.angle_deg.value.push_back(a);
    double noisy = a + o.angle_noise_deg * an.normal();
    // Outlier draws come from their own stream, so --outliers does not change the other noise.
    const double u = on.uniform(), mag = on.uniform(), sign = on.uniform();
    if (u < o.outlier_fraction) {
      noisy += (sign < 0.5 ? -1.0 : 1.0) * (o.outlier_min_deg + mag * (o.outlier_max_deg - o.outlier_min_deg));
      ++res.outliers;
    }
    data.angle_deg.t_s.push_back(t);
    data.angle_deg.value.push_back(noisy);
  }
  res.data.trials.push_back(std::move(data));
  res.truth.trials.push_back(std::move(truth));
}

/// OUT.csv, OUT.truth.csv and OUT.truth.json.
void write_outputs(const SynthOptions& o, const HiddenScene& h, SynthResult& res,
                   std::chrono::steady_clock::time_point wall0) {
  const fs::path out(o.out_csv);
  prepare_output_file(o.out_csv, "--out");  // its directory, checked before the model ran, is made now
  const fs::path stem = out.parent_path() / out.stem();
  res.data.source = out.string();
  res.truth.source = stem.string() + ".truth.csv";
  write_measurements_csv(out.string(), res.data);
  write_measurements_csv(stem.string() + ".truth.csv", res.truth);
  std::string names = "[";
  for (std::size_t i = 0; i < h.hidden.size(); ++i) names += (i ? ", " : "") + json::quote(h.hidden[i]);
  names += "]";
  res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  json::Object j;
  j.add_str("pneufem_version", version_string())
      .add_str("command_line", o.command_line)
      .add("seed", static_cast<double>(o.seed))
      .add("hidden", names)
      .add("effects", h.effects.str(2))
      .add("sampling_and_noise", noise_json(o))
      .add("outlier_frames", static_cast<double>(res.outliers))
      .add("solved_states", static_cast<double>(res.states))
      .add_str("data_csv", out.filename().string())
      .add_str("truth_csv", out.stem().string() + ".truth.csv")
      .add("scene", h.scene.to_json());
  write_file_atomic(stem.string() + ".truth.json", j.str() + "\n");
}

}  // namespace

SynthResult run_synth(const SynthOptions& o) {
  const auto wall0 = std::chrono::steady_clock::now();
  check_options(o);
  SynthResult res;
  const HiddenScene h = hidden_scene(o, res);

  const int threads = o.threads > 0 ? o.threads : tbb::info::default_concurrency();
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  std::unique_ptr<BuiltModel> bm = build_model(h.scene);  // validates everything, staircase metadata

  // The lag is applied to the controller's inlet (chamber_history), not to the commanded steps.
  const LoadHistory commanded = inlet_load(h.scene);
  const ControllerInlet ci = controller_inlet(commanded, o);
  const LoadHistory chamber = chamber_history(h.scene, commanded, ci.inlet, o);
  const ModelAngles m = solve_angles(*bm, chamber, o, res);
  for (std::size_t k = 0; k < chamber.trials.size(); ++k) sample_trial(k, chamber.trials[k].duration(), ci, m, o, res);
  write_outputs(o, h, res, wall0);
  return res;
}

}  // namespace pneufem

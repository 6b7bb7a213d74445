#include "app/sweep/command.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>
#include <tbb/info.h>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/output_dir.h"
#include "core/progress.h"
#include "core/json_writer.h"
#include "core/version.h"
#include "scenes/build_model.h"
#include "scenes/scene_settings.h"
#include "scenes/scene.h"
#include "app/sweep/plot.h"

namespace pneufem {

namespace fs = std::filesystem;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr const char* kParamForm =
    "expected KEY=LO:HI:N[:log], e.g. --param materials.silicone.fatigue.tau_s=100:1000:5:log";
constexpr std::size_t kMaxPoints = 100000;

std::optional<double> parse_double(const std::string& s) {
  if (s.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::optional<long long> parse_int(const std::string& s) {
  if (s.empty()) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (end != s.c_str() + s.size() || errno != 0) return std::nullopt;
  return v;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return {};
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// --- reading the run outputs (summary.json and metrics.json of a point's run directory) ---

/// The JSON document in file `p`; null when the file is missing or is not valid JSON.
nlohmann::json read_json(const fs::path& p) {
  nlohmann::json j = nlohmann::json::parse(slurp(p), nullptr, /*allow_exceptions=*/false);
  return j.is_discarded() ? nlohmann::json() : j;
}

/// The member `key` of `object`, or null when `object` is not an object or lacks it.
const nlohmann::json& member(const nlohmann::json& object, const char* key) {
  static const nlohmann::json kNull;
  if (!object.is_object()) return kNull;
  const auto it = object.find(key);
  return it == object.end() ? kNull : *it;
}

/// A number of a run output; json::num writes a non-finite one as null, read back as NaN.
double number_or_nan(const nlohmann::json& v) { return v.is_number() ? v.get<double>() : kNaN; }

/// summary.json's "status" ("ok" or the error that stopped the run), when it has one.
std::optional<std::string> run_status(const nlohmann::json& summary) {
  const nlohmann::json& status = member(summary, "status");
  if (!status.is_string()) return std::nullopt;
  return status.get<std::string>();
}

/// One row of a run's angles.csv (trial,time_s,pressure_kPa,angle_deg): a report.
struct ReportAngle {
  int trial = 0;
  double time_s = 0.0, angle_deg = 0.0;
};

/// The reports of angles.csv, in order; rows that do not read as four numbers are left out.
std::vector<ReportAngle> read_angles(const fs::path& angles_csv) {
  std::ifstream in(angles_csv);
  std::string line;
  std::getline(in, line);  // header
  std::vector<ReportAngle> reports;
  for (ReportAngle r; std::getline(in, line);) {
    double p = 0;
    if (std::sscanf(line.c_str(), "%d,%lf,%lf,%lf", &r.trial, &r.time_s, &p, &r.angle_deg) == 4) reports.push_back(r);
  }
  return reports;
}

/// Which model made a finished run's reports, from its summary.json: the reduced_model entry is
/// there only when the reduced model was asked for, and its fallback says whether the full FEM
/// replaced it ("full FEM: <reason>").
std::string model_that_ran(const nlohmann::json& summary) {
  const nlohmann::json& fallback = member(member(summary, "reduced_model"), "fallback");
  if (!fallback.is_string()) return "full";
  std::string why = fallback.get<std::string>();
  if (why == "none") return "reduced";
  const std::string prefix = "full FEM: ";
  if (why.rfind(prefix, 0) == 0) why.erase(0, prefix.size());
  return "full (fallback: " + why + ")";
}

/// The last non-empty lines of a log, joined, at most `max_chars` (the reason a worker failed).
std::string log_tail(const fs::path& log, std::size_t max_lines = 3, std::size_t max_chars = 400) {
  std::vector<std::string> lines;
  std::istringstream in(slurp(log));
  for (std::string l; std::getline(in, l);) {
    if (const auto cr = l.rfind('\r'); cr != std::string::npos) l = l.substr(cr + 1);  // progress lines
    if (l.find_first_not_of(" \t") != std::string::npos) lines.push_back(l);
  }
  std::string s;
  for (std::size_t i = lines.size() > max_lines ? lines.size() - max_lines : 0; i < lines.size(); ++i)
    s += (s.empty() ? "" : " | ") + lines[i];
  if (s.size() > max_chars) s = "..." + s.substr(s.size() - max_chars);
  return s;
}

std::string point_name(int index) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%04d", index);
  return buf;
}

/// Fills a point's outcome from its run directory. `exit_code` < 0: not run now (resume check).
void read_point(SweepPoint& pt, const fs::path& dir, int exit_code, double measured_s) {
  const nlohmann::json summary = read_json(dir / "summary.json");
  const std::optional<std::string> status = run_status(summary);
  const double total_s = number_or_nan(member(member(summary, "timings"), "total_s"));
  pt.wall_s = std::isfinite(total_s) ? total_s : measured_s;
  pt.nrmse.clear();  // metrics.json (analysis/paper_metrics.h): {"trials": [{"trial", "nrmse", ...}], ...}
  const nlohmann::json metrics = read_json(dir / "metrics.json");
  const nlohmann::json& trials = member(metrics, "trials");
  if (trials.is_array())
    for (const nlohmann::json& t : trials) pt.nrmse.push_back(number_or_nan(member(t, "nrmse")));
  const std::vector<ReportAngle> reports = read_angles(dir / "angles.csv");
  pt.final_angle_deg = reports.empty() ? kNaN : reports.back().angle_deg;
  if (status && *status == "ok" && exit_code <= 0) {
    pt.status = "ok";
    pt.model = model_that_ran(summary);
    pt.error.clear();
    return;
  }
  pt.status = "failed";
  pt.model.clear();
  if (status && *status != "ok") {
    pt.error = *status;
  } else {
    const std::string tail = log_tail(dir / "log.txt");
    pt.error = (exit_code >= 128 ? "killed by signal " + std::to_string(exit_code - 128)
                                 : "exit code " + std::to_string(exit_code)) +
               (tail.empty() ? "" : ": " + tail);
  }
}

/// Fills a --fem-points comparison from the point's run directory and its FEM run in DIR/fem:
/// the FEM's NRMSE, and the largest angle difference over the reports, which both runs make at
/// the same times (the protocol's, whatever the model).
void read_fem_comparison(SweepPoint& pt, const fs::path& dir, int exit_code) {
  SweepPoint fem_run;
  read_point(fem_run, dir / "fem", exit_code, 0.0);
  FemComparison& c = pt.fem.emplace();
  c.status = fem_run.status;
  c.error = fem_run.error;
  c.final_nrmse = final_nrmse(fem_run);
  if (c.status != "ok") return;
  const std::vector<ReportAngle> point = read_angles(dir / "angles.csv"), fem = read_angles(dir / "fem" / "angles.csv");
  const auto same_report = [](const ReportAngle& a, const ReportAngle& b) {
    return a.trial == b.trial && std::abs(a.time_s - b.time_s) <= 1e-5;  // angles.csv writes 6 decimals
  };
  if (point.empty() || point.size() != fem.size() || !std::equal(point.begin(), point.end(), fem.begin(), same_report)) {
    c.status = "failed";
    c.error = "the FEM run's reports (" + std::to_string(fem.size()) + ") are not those of the point's run (" +
              std::to_string(point.size()) + "): nothing to compare";
    return;
  }
  double worst = 0.0;
  for (std::size_t k = 0; k < point.size(); ++k) worst = std::max(worst, std::abs(point[k].angle_deg - fem[k].angle_deg));
  c.max_abs_diff_deg = std::round(worst * 1e6) / 1e6;  // the angles' 6 decimals, without the subtraction's noise
}

/// The worker's exit code (128 + signal when it was killed).
int exit_code_of(int wait_status) {
  if (WIFEXITED(wait_status)) return WEXITSTATUS(wait_status);
  if (WIFSIGNALED(wait_status)) return 128 + WTERMSIG(wait_status);
  return 1;
}

/// Starts `argv` with stdout and stderr going to `log`. The worker dies with the sweep (a killed
/// sweep must not leave workers writing into directories the next invocation reruns).
pid_t launch(const std::vector<std::string>& argv, const fs::path& log) {
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const std::string log_path = log.string();
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("sweep: cannot start a worker process (fork failed): " + std::string(strerror(errno)));
  if (pid == 0) {
    // Child: async-signal-safe calls only until exec.
    const int fd = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
      close(fd);
    }
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(137);
    execv(args[0], args.data());
    const char msg[] = "sweep: cannot execute the pneufem binary\n";
    (void)!write(STDERR_FILENO, msg, sizeof msg - 1);
    _exit(127);
  }
  return pid;
}

/// Holds DIR/.sweep.lock for the lifetime of the sweep: two sweeps must not share a directory.
class DirLock {
 public:
  explicit DirLock(const fs::path& dir) {
    const std::string path = (dir / ".sweep.lock").string();
    fd_ = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw InputError("--out " + dir.string() + ": cannot create " + path + " (is the directory writable?)");
    if (flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      close(fd_);
      if (err != EWOULDBLOCK)  // ENOLCK, ENOSYS, EOPNOTSUPP: the file system does not lock
        throw InputError("--out " + dir.string() + ": the file system refuses file locks (flock: " + strerror(err) +
                         "), which the sweep and its shared caches need; on Lustre mount with -o flock, or choose "
                         "an --out on a file system that locks (docs/commands.md, sweeps on SLURM)");
      throw InputError("--out " + dir.string() +
                       ": another pneufem sweep is running in this directory; wait for it or choose another --out");
    }
  }
  ~DirLock() { close(fd_); }
  DirLock(const DirLock&) = delete;
  DirLock& operator=(const DirLock&) = delete;

 private:
  int fd_ = -1;
};

std::string csv_num(double v, const char* fmt = nullptr) {
  if (!std::isfinite(v)) return "";
  if (!fmt) return json::num(v);
  char buf[32];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

std::string csv_quote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += "\"\"";
    else if (c == '\n' || c == '\r') out += ' ';
    else out += c;
  }
  return out + "\"";
}

std::size_t max_trials(const std::vector<SweepPoint>& points) {
  std::size_t k = 0;
  for (const SweepPoint& p : points) k = std::max(k, p.nrmse.size());
  return k;
}

std::string sweep_csv(const std::vector<ParamSpec>& params, const std::vector<SweepPoint>& points) {
  const std::size_t K = max_trials(points);
  std::string s = "point";
  for (const ParamSpec& p : params) s += "," + (p.key.find_first_of(",\"") == std::string::npos ? p.key : csv_quote(p.key));
  const bool fem = std::any_of(points.begin(), points.end(), [](const SweepPoint& q) { return q.fem.has_value(); });
  s += ",status,model,wall_s,final_nrmse";
  for (std::size_t k = 1; k <= K; ++k) s += ",nrmse_trial_" + std::to_string(k);
  s += ",final_angle_deg";
  if (fem) s += ",fem_final_nrmse,max_abs_reduced_minus_fem_deg";
  s += ",error\n";
  // Field by field (appending, not concatenating temporaries).
  const auto field = [&s](const std::string& f) {
    s += ',';
    s += f;
  };
  for (const SweepPoint& pt : points) {
    s += std::to_string(pt.index);
    for (const std::string& t : pt.texts) field(t);
    const bool done = pt.status != "pending";
    field(pt.status);
    field(pt.model.find_first_of(",\"") == std::string::npos ? pt.model : csv_quote(pt.model));
    field(done ? csv_num(pt.wall_s, "%.3f") : "");
    field(csv_num(final_nrmse(pt)));
    for (std::size_t k = 0; k < K; ++k) field(k < pt.nrmse.size() ? csv_num(pt.nrmse[k]) : "");
    field(done ? csv_num(pt.final_angle_deg) : "");
    if (fem) {
      field(pt.fem ? csv_num(pt.fem->final_nrmse) : "");
      field(pt.fem ? csv_num(pt.fem->max_abs_diff_deg) : "");
    }
    // A failed FEM re-run is the point's error too (its own run succeeded, or there is no FEM run).
    std::string error = pt.error;
    if (pt.fem && pt.fem->status == "failed" && pt.status == "ok") error = "FEM re-run: " + pt.fem->error;
    field(error.empty() ? "" : csv_quote(error));
    s += '\n';
  }
  return s;
}

/// A file-name friendly form of a scene key.
std::string file_key(const std::string& key) {
  std::string s = key;
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-') c = '_';
  return s;
}

std::string sweep_json(const SweepOptions& o, const std::vector<ParamSpec>& params, const SweepResult& r,
                       const std::vector<std::string>& plots) {
  json::Object head;
  std::string ps = "[";
  for (std::size_t j = 0; j < params.size(); ++j) {
    json::Object q;
    q.add_str("key", params[j].key).add_str("spec", params[j].text).add("lo", params[j].lo).add("hi", params[j].hi);
    q.add("n", o.lhs > 0 ? json::num(o.lhs) : json::num(params[j].n)).add("log", params[j].log ? "true" : "false");
    q.add("integer", params[j].integer ? "true" : "false");
    ps += (j ? ", " : "") + q.str(4);
  }
  ps += "]";
  std::string sets = "[";
  for (std::size_t i = 0; i < o.sets.size(); ++i) sets += (i ? ", " : "") + json::quote(o.sets[i]);
  sets += "]";
  const bool have_nrmse = std::any_of(r.points.begin(), r.points.end(), [](const SweepPoint& q) { return !q.nrmse.empty(); });
  const SweepPoint* best = nullptr;
  for (const SweepPoint& q : r.points)
    if (q.status == "ok" && std::isfinite(final_nrmse(q)) && (!best || final_nrmse(q) < final_nrmse(*best))) best = &q;
  std::string pts = "[";
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    const SweepPoint& q = r.points[i];
    json::Object values;
    for (std::size_t j = 0; j < params.size(); ++j) values.add(params[j].key, q.values[j]);
    json::Object e;
    e.add("point", q.index)
        .add_str("dir", "points/" + point_name(q.index))
        .add("values", values.str(6))
        .add_str("status", q.status)
        .add_str("model", q.model)
        .add("skipped", q.skipped ? "true" : "false")
        .add("wall_s", q.status == "pending" ? kNaN : q.wall_s)
        .add("final_nrmse", final_nrmse(q))
        .add("nrmse_trials", json::array(q.nrmse))
        .add("final_angle_deg", q.final_angle_deg)
        .add_str("error", q.error);
    if (q.fem) {
      json::Object fem;
      fem.add_str("dir", "points/" + point_name(q.index) + "/fem")
          .add_str("status", q.fem->status)
          .add("final_nrmse", q.fem->final_nrmse)
          .add("max_abs_reduced_minus_fem_deg", q.fem->max_abs_diff_deg)
          .add_str("error", q.fem->error);
      e.add("fem", fem.str(6));
    }
    pts += (i ? ",\n    " : "\n    ") + e.str(4);
  }
  pts += "\n  ]";
  std::string plot_list = "[";
  for (std::size_t i = 0; i < plots.size(); ++i) plot_list += (i ? ", " : "") + json::quote(plots[i]);
  plot_list += "]";
  head.add_str("pneufem_version", version_string())
      .add_str("command_line", o.command_line)
      .add_str("scene", o.scene_path.empty() ? "(built-in default)" : o.scene_path)
      .add_str("mode", o.lhs > 0 ? "lhs" : "grid")
      .add("seed", o.lhs > 0 ? json::num(static_cast<double>(o.seed)) : "null")
      .add("params", ps)
      .add("sets", sets)
      .add_str("model", r.model)
      .add_str("model_reason", r.model_reason)
      .add("offline_parts", r.offline_parts)
      .add("fem_points", json::array(std::vector<double>(o.fem_points.begin(), o.fem_points.end())))
      .add("jobs", o.jobs)
      .add_str("scheduler", o.scheduler)
      .add("threads_per_job", o.threads_per_job)
      .add("points_total", static_cast<double>(r.points.size()))
      .add("ok", r.ok)
      .add("failed", r.failed)
      .add("skipped", r.skipped)
      .add("fem_failed", r.fem_failed)
      .add("wall_s", r.wall_s)
      .add_str("metric", have_nrmse ? "final_nrmse" : "final_angle_deg")
      .add("best_point", best ? json::num(best->index) : "null")
      .add("plots", plot_list)
      .add("points", pts);
  return head.str() + "\n";
}

/// DIR/sweep_<key>.svg of each parameter and DIR/sweep.json.
void write_plots_and_json(const SweepOptions& recorded, const fs::path& out, const std::vector<ParamSpec>& params,
                          const SweepResult& result) {
  std::vector<std::string> plots;
  for (std::size_t j = 0; j < params.size(); ++j) {
    const std::string name = "sweep_" + file_key(params[j].key) + ".svg";
    sweep_figure(params, j, result.points).save((out / name).string());
    plots.push_back(name);
  }
  write_file_atomic((out / "sweep.json").string(), sweep_json(recorded, params, result, plots));
}

void say(std::FILE* log, const std::string& line) {
  if (!log) return;
  std::fprintf(log, "%s\n", line.c_str());
  std::fflush(log);
}

std::string describe(const std::vector<ParamSpec>& params, const SweepPoint& pt) {
  std::string s;
  for (std::size_t j = 0; j < params.size(); ++j) s += (j ? " " : "") + params[j].key + "=" + pt.texts[j];
  return s;
}

// --- the model the workers run ---

/// What the reduced model's offline part of a point depends on (app/simulate/reduced.h).
struct OfflineKeys {
  /// The actuator: the elastic reference without [load], [output] and [solver]. Points with one
  /// actuator differ only in effect constants, gravity or protocol, and can share a basis.
  std::string actuator;
  /// The offline part itself, the cache key of reduced_setup but for the executable and the mesh
  /// bytes (both fixed by the scene): the elastic reference with its solver (Newton tolerance,
  /// basis options) and the chambers' peak pressure, which sets the traced range.
  std::string offline;
};

/// The offline keys of a point's scene; none when its load cannot be built (the point will fail
/// in its worker and say why).
std::optional<OfflineKeys> offline_keys(const Scene& scene) {
  try {
    const Scene reference = elastic_reference_scene(scene);
    double peak_Pa = 0.0;
    for (const TrialLoad& trial : chamber_load(scene).trials)
      for (double p : trial.pressure_Pa) peak_Pa = std::max(peak_Pa, p);
    return OfflineKeys{reference.model_toml_without({"load", "output", "solver"}),
                       reference.model_toml_without({"load", "output"}) + "\npeak_Pa = " + json::num(peak_Pa)};
  } catch (const InputError&) {
    return std::nullopt;
  }
}

/// The model of a sweep's workers and its offline parts.
struct ModelPlan {
  bool reduced = false;
  std::string why;          ///< for the log and sweep.json
  std::vector<int> offline;  ///< per point: its offline part (0, 1, ...), -1 = unknown; reduced only
  int offline_parts = 0;
};

/// The swept keys that change the actuator, for the log: each key in which the first point of
/// another actuator differs from point `a`, set alone on point `a`'s scene; all of those keys
/// when none does it alone.
std::string keys_changing_actuator(const Scene& base, const std::vector<ParamSpec>& params,
                                   const std::vector<std::vector<std::string>>& overrides,
                                   const std::vector<std::optional<OfflineKeys>>& keys, std::size_t a) {
  std::size_t b = a;
  while (b < keys.size() && (!keys[b] || keys[b]->actuator == keys[a]->actuator)) ++b;
  std::vector<std::string> differing, alone;
  for (std::size_t j = 0; j < params.size(); ++j) {
    if (overrides[a][j] == overrides[b][j]) continue;
    differing.push_back(params[j].key);
    std::vector<std::string> ov = overrides[a];
    ov[j] = overrides[b][j];
    std::optional<OfflineKeys> k;
    try {
      k = offline_keys(base.with(ov));
    } catch (const InputError&) {  // a combination of values no point has may be invalid: not this key alone
      continue;
    }
    if (!k || k->actuator != keys[a]->actuator) alone.push_back(params[j].key);
  }
  const std::vector<std::string>& culprits = alone.empty() ? differing : alone;
  std::string s;
  for (std::size_t i = 0; i < culprits.size(); ++i) s += (i ? (i + 1 == culprits.size() ? " and " : ", ") : "") + culprits[i];
  return s + (culprits.size() > 1 ? " change" : " changes");
}

/// --model applied to the points: auto takes the reduced model when every point has one actuator.
/// `solver` is the base scene's [solver]; `keys` are the points' offline keys (none with --model full).
ModelPlan plan_model(const SweepOptions& o, const Scene& base, const SolverSettings& solver, const std::vector<ParamSpec>& params,
                     const std::vector<std::vector<std::string>>& overrides,
                     const std::vector<std::optional<OfflineKeys>>& keys) {
  ModelPlan plan;
  if (o.model == "full") {
    plan.why = "full FEM (--model full)";
    return plan;
  }
  if (solver.mode != SolverSettings::Mode::QuasiStatic) {
    const std::string why = "the reduced model runs quasi-static scenes only, and solver.mode = \"" + mode_name(solver.mode) +
                            "\" (" + base.origin("solver.mode") + ")";
    if (o.model == "reduced") throw InputError("--model reduced: " + why);
    plan.why = "full FEM: " + why;
    return plan;
  }
  std::map<std::string, int> actuators, offline_parts;
  std::optional<std::size_t> first_known;
  plan.offline.assign(keys.size(), -1);
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (!keys[i]) continue;
    if (!first_known) first_known = i;
    actuators.emplace(keys[i]->actuator, static_cast<int>(actuators.size()));
    plan.offline[i] = offline_parts.emplace(keys[i]->offline, static_cast<int>(offline_parts.size())).first->second;
  }
  plan.offline_parts = static_cast<int>(offline_parts.size());
  const std::string parts = std::to_string(plan.offline_parts) + " offline part" + (plan.offline_parts == 1 ? "" : "s");
  if (actuators.size() <= 1) {
    plan.reduced = true;
    plan.why = "reduced model" + std::string(o.model == "reduced" ? " (--model reduced)" : "") +
               ": every point has the same elastic reference (the swept keys are effect constants, gravity or protocol), " +
               (plan.offline_parts <= 1 ? std::string("so the points share one offline part (elastic path and basis), built once")
                                        : "but the chambers' peak pressure (the traced range) or the basis options differ: " +
                                              parts + " (elastic path and basis), each built once") +
               " in rom_cache/";
    return plan;
  }
  const std::string culprits = keys_changing_actuator(base, params, overrides, keys, *first_known);
  const std::string distinct = std::to_string(actuators.size()) + " distinct actuators";
  if (o.model == "auto") {
    plan.offline.clear();
    plan.offline_parts = 0;
    plan.why = "full FEM: " + culprits + " the elastic reference, which the reduced model's basis is built for (" +
               distinct + "; --model reduced would build one offline part per actuator)";
    return plan;
  }
  plan.reduced = true;
  plan.why = "reduced model (--model reduced): " + culprits + " the elastic reference (" + distinct +
             "), which costs one offline part per distinct actuator: " + parts + ", in rom_cache/";
  return plan;
}

/// A `pneufem simulate` worker: the point (its index in the sweep's points) and its command.
struct Worker {
  std::size_t i = 0;
  fs::path dir;  ///< its run directory, emptied before it starts
  std::vector<std::string> argv;
};

/// Where and how a sweep's workers run.
struct WorkerSetup {
  const SweepOptions& o;
  fs::path out;           ///< the sweep directory
  std::string scene_abs;  ///< the scene file, absolute ("" = the built-in default)
  int jobs = 1;           ///< workers at a time

  /// The command of a worker writing `dir`: the scene, the sweep's --set, the point's `overrides`;
  /// with `rom_cache`, the reduced model's cache.
  std::vector<std::string> argv(const fs::path& dir, const std::vector<std::string>& overrides, bool rom_cache) const;
};

std::vector<std::string> WorkerSetup::argv(const fs::path& dir, const std::vector<std::string>& overrides, bool rom_cache) const {
  std::vector<std::string> argv = {o.exe, "simulate"};
  if (!scene_abs.empty()) argv.push_back(scene_abs);
  // Full-FEM points share one ideal elastic model per actuator (app/simulate/ideal_cache.h): a sweep
  // over damage constants computes it once instead of once per point (a reduced run computes its
  // own with the reduced model, in seconds).
  for (const std::string& a : {std::string("--out"), dir.string(), std::string("--threads"), std::to_string(o.threads_per_job),
                               std::string("--ideal-cache"), (out / "ideal_cache").string()})
    argv.push_back(a);
  if (rom_cache) argv.insert(argv.end(), {"--cache", (out / "rom_cache").string()});
  for (const std::string& s : o.sets) argv.insert(argv.end(), {"--set", s});
  for (const std::string& s : overrides) argv.insert(argv.end(), {"--set", s});
  return argv;
}

/// Runs `workers`, at most `jobs` at a time; `finished(worker, exit code, measured wall time)` as
/// each ends, in the order they end.
void run_workers(const std::vector<Worker>& workers, int jobs,
                 const std::function<void(const Worker&, int, double)>& finished) {
  struct Running {
    pid_t pid;
    const Worker* worker;
    std::chrono::steady_clock::time_point start;
  };
  std::vector<Running> running;
  std::size_t next = 0;
  while (next < workers.size() || !running.empty()) {
    while (next < workers.size() && static_cast<int>(running.size()) < jobs) {
      const Worker& w = workers[next++];
      fs::remove_all(w.dir);  // an interrupted, failed or changed point starts clean
      fs::create_directories(w.dir);
      running.push_back({launch(w.argv, w.dir / "log.txt"), &w, std::chrono::steady_clock::now()});
    }
    bool any = false;
    for (std::size_t r = 0; r < running.size();) {
      int st = 0;
      const pid_t w = waitpid(running[r].pid, &st, WNOHANG);
      if (w == 0 || (w < 0 && errno == EINTR)) {
        ++r;
        continue;
      }
      any = true;
      const Running done = running[r];
      running.erase(running.begin() + static_cast<std::ptrdiff_t>(r));
      const double measured = std::chrono::duration<double>(std::chrono::steady_clock::now() - done.start).count();
      finished(*done.worker, w < 0 ? 1 : exit_code_of(st), measured);
    }
    if (!any && !running.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

/// The points of --fem-points, each once; InputError for one the sweep does not have.
std::set<int> checked_fem_points(const std::vector<int>& given, std::size_t points) {
  std::set<int> fem_points;
  for (int index : given) {
    if (index < 1 || static_cast<std::size_t>(index) > points)
      throw InputError("--fem-points " + std::to_string(index) + ": no such point; the sweep's points are 1 to " +
                       std::to_string(points) + " (the point column of sweep.csv, or --dry-run)");
    fem_points.insert(index);
  }
  return fem_points;
}

/// The workers in two waves. The reduced model's offline part is built by the first point that
/// needs it, alone, and read from rom_cache/ by the others: started together, every point of an
/// actuator would wait on the cache's lock for it, each holding a worker slot. The first wave has
/// the first point of each offline part (distinct parts are built in parallel), the second the
/// rest; with the full FEM, the first wave is empty.
std::pair<std::vector<Worker>, std::vector<Worker>> offline_waves(std::vector<Worker> workers, const ModelPlan& plan) {
  std::vector<Worker> first, rest;
  std::set<int> started;
  for (Worker& w : workers) {
    const bool builds_offline = plan.reduced && plan.offline[w.i] >= 0 && started.insert(plan.offline[w.i]).second;
    (builds_offline ? first : rest).push_back(std::move(w));
  }
  return {std::move(first), std::move(rest)};
}

/// A finished point for the log: its values, status, model (of a reduced sweep), time, NRMSE, error.
std::string outcome_line(const std::vector<ParamSpec>& params, const SweepPoint& pt, bool reduced) {
  std::string line = "point " + point_name(pt.index) + " " + describe(params, pt) + ": " + pt.status;
  if (pt.status == "ok" && reduced) line += " (" + pt.model + ")";
  char tail[96];
  std::snprintf(tail, sizeof tail, ", %.1f s", pt.wall_s);
  line += tail;
  if (!pt.nrmse.empty()) {
    std::snprintf(tail, sizeof tail, ", final NRMSE %.4g", pt.nrmse.back());
    line += tail;
  }
  if (!pt.error.empty()) line += ": " + pt.error;
  return line;
}

/// Whether `dir` holds a finished run of the resolved scene `scene_text` (the resume check).
bool done_before(const fs::path& dir, const std::string& scene_text) {
  const std::optional<std::string> status = run_status(read_json(dir / "summary.json"));
  return status && *status == "ok" && slurp(dir / "scene.toml") == scene_text;
}

/// --fem-points: the chosen points again with the full FEM, into points/NNNN/fem/, each compared
/// with the point's own run. `overrides` are the points' (their last is solver.model).
void run_fem_points(const WorkerSetup& setup, const Scene& base, const std::vector<ParamSpec>& params,
                    const std::set<int>& fem_points, const std::vector<std::vector<std::string>>& overrides,
                    SweepResult& result) {
  std::vector<Worker> fem_runs;
  for (int index : fem_points) {
    SweepPoint& pt = result.points[static_cast<std::size_t>(index) - 1];
    const fs::path dir = setup.out / "points" / point_name(index);
    std::vector<std::string> ov = overrides[static_cast<std::size_t>(index) - 1];
    ov.back() = "solver.model=\"full\"";
    if (pt.status != "ok") {
      pt.fem = FemComparison{"failed", kNaN, kNaN, "not run: the point's own run failed"};
      ++result.fem_failed;
    } else if (done_before(dir / "fem", base.with(ov).to_toml())) {
      read_fem_comparison(pt, dir, -1);
      if (pt.fem->status != "ok") ++result.fem_failed;
      say(setup.o.log, "FEM re-run of point " + point_name(index) + " skipped (already done)");
    } else {
      fem_runs.push_back({static_cast<std::size_t>(index) - 1, dir / "fem", setup.argv(dir / "fem", ov, false)});
    }
  }
  if (!fem_runs.empty())
    say(setup.o.log, std::to_string(fem_runs.size()) + " point(s) again with the full FEM (--fem-points), into points/NNNN/fem/");
  run_workers(fem_runs, setup.jobs, [&](const Worker& w, int exit_code, double) {
    SweepPoint& pt = result.points[w.i];
    read_fem_comparison(pt, w.dir.parent_path(), exit_code);
    if (pt.fem->status != "ok") ++result.fem_failed;
    char line[200];
    std::snprintf(line, sizeof line, "FEM re-run of point %s: final NRMSE %.4g (the point's %.4g), largest |point - FEM| angle %.4g deg",
                  point_name(pt.index).c_str(), pt.fem->final_nrmse, final_nrmse(pt), pt.fem->max_abs_diff_deg);
    say(setup.o.log, pt.fem->status == "ok" ? line : "FEM re-run of point " + point_name(pt.index) + " failed: " + pt.fem->error);
    write_file_atomic((setup.out / "sweep.csv").string(), sweep_csv(params, result.points));
  });
  write_file_atomic((setup.out / "sweep.csv").string(), sweep_csv(params, result.points));  // with the skipped re-runs too
}

}  // namespace

// ---------------------------------------------------------------------------------------------

ParamSpec parse_param_spec(const std::string& text) {
  ParamSpec p;
  p.text = text;
  const auto fail = [&](const std::string& why) { throw InputError("--param " + text + ": " + why); };
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) fail(kParamForm);
  p.key = text.substr(0, eq);
  if (p.key.find_first_of(" \t\"'[]") != std::string::npos) fail("'" + p.key + "' is not a scene key; " + kParamForm);
  std::vector<std::string> f;
  std::stringstream ss(text.substr(eq + 1));
  for (std::string t; std::getline(ss, t, ':');) f.push_back(t);
  if (!text.empty() && text.back() == ':') f.emplace_back();
  if (f.size() < 2 || f.size() > 4) fail(kParamForm);
  const std::optional<double> lo = parse_double(f[0]), hi = parse_double(f[1]);
  if (!lo) fail("LO '" + f[0] + "' is not a number; " + kParamForm);
  if (!hi) fail("HI '" + f[1] + "' is not a number; " + kParamForm);
  p.lo = *lo;
  p.hi = *hi;
  std::size_t next = 2;
  if (f.size() > 2 && f[2] != "log" && f[2] != "lin") {
    const std::optional<long long> n = parse_int(f[2]);
    if (!n) fail("N '" + f[2] + "' is not a whole number; " + kParamForm);
    if (*n < 1) fail("N must be at least 1 (the number of values), got " + f[2]);
    if (*n > static_cast<long long>(kMaxPoints)) fail("N = " + f[2] + " is too many values");
    p.n = static_cast<int>(*n);
    next = 3;
  }
  if (next < f.size()) {
    if (f[next] != "log" && f[next] != "lin") fail("the spacing '" + f[next] + "' must be 'log' or 'lin'; " + kParamForm);
    p.log = f[next] == "log";
    if (++next < f.size()) fail(kParamForm);
  }
  if (p.lo > p.hi) fail("LO (" + f[0] + ") is greater than HI (" + f[1] + "); give the range as LO:HI");
  if (p.log && p.lo <= 0.0) fail("a log range needs LO > 0, got " + f[0] + " (use linear spacing, or a positive LO)");
  return p;
}

std::vector<double> grid_values(const ParamSpec& p) {
  const int n = std::max(1, p.n);
  std::vector<double> v;
  for (int i = 0; i < n; ++i) {
    double x = p.lo;
    if (i == n - 1 && n > 1) {
      x = p.hi;
    } else if (i > 0) {
      const double t = static_cast<double>(i) / (n - 1);
      x = p.log ? std::pow(10.0, std::log10(p.lo) + t * (std::log10(p.hi) - std::log10(p.lo))) : p.lo + t * (p.hi - p.lo);
    }
    if (p.integer) x = std::round(x);
    if (v.empty() || x != v.back()) v.push_back(x);
  }
  return v;
}

std::vector<std::vector<double>> grid_points(const std::vector<ParamSpec>& params) {
  std::vector<std::vector<double>> axes;
  std::size_t total = 1;
  for (const ParamSpec& p : params) {
    if (p.n < 1)
      throw InputError("--param " + p.text + ": give the number of values N (KEY=LO:HI:N), or sample with --lhs");
    axes.push_back(grid_values(p));
    total *= axes.back().size();
    if (total > kMaxPoints)
      throw InputError("--param: the grid has more than " + std::to_string(kMaxPoints) +
                       " points; use fewer values or --lhs N");
  }
  std::vector<std::vector<double>> points;
  if (params.empty()) return points;
  std::vector<std::size_t> idx(params.size(), 0);
  for (std::size_t k = 0; k < total; ++k) {
    std::vector<double> pt(params.size());
    for (std::size_t j = 0; j < params.size(); ++j) pt[j] = axes[j][idx[j]];
    points.push_back(pt);
    for (std::size_t j = params.size(); j-- > 0;) {
      if (++idx[j] < axes[j].size()) break;
      idx[j] = 0;
    }
  }
  return points;
}

std::vector<std::vector<double>> lhs_points(const std::vector<ParamSpec>& params, int n, std::uint64_t seed) {
  if (n < 1) throw InputError("--lhs " + std::to_string(n) + ": the number of samples must be at least 1");
  if (static_cast<std::size_t>(n) > kMaxPoints) throw InputError("--lhs " + std::to_string(n) + ": too many samples");
  std::mt19937_64 rng(seed);
  const auto uniform01 = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };  // [0, 1)
  std::vector<std::vector<double>> points(n, std::vector<double>(params.size()));
  for (std::size_t j = 0; j < params.size(); ++j) {
    const ParamSpec& p = params[j];
    std::vector<int> perm(n);
    for (int i = 0; i < n; ++i) perm[i] = i;
    for (int i = n - 1; i > 0; --i) std::swap(perm[i], perm[rng() % static_cast<std::uint64_t>(i + 1)]);  // Fisher-Yates
    for (int i = 0; i < n; ++i) {
      const double u = (perm[i] + uniform01()) / n;
      double x = p.log ? std::pow(10.0, std::log10(p.lo) + u * (std::log10(p.hi) - std::log10(p.lo))) : p.lo + u * (p.hi - p.lo);
      if (p.integer) x = std::round(x);
      points[i][j] = x;
    }
  }
  return points;
}

std::string format_value(double v, bool integer) {
  if (integer) return std::to_string(std::llround(v));
  std::string s = json::num(v);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

// ---------------------------------------------------------------------------------------------

namespace {

void check_sweep_options(const SweepOptions& o) {
  if (o.params.empty())
    throw InputError("--param: give at least one parameter to sweep, e.g. --param materials.silicone.fatigue.tau_s=100:1000:5:log");
  if (o.jobs < 0) throw InputError("--jobs " + std::to_string(o.jobs) + ": the number of worker processes must be at least 1");
  if (o.threads_per_job < 1)
    throw InputError("--threads-per-job " + std::to_string(o.threads_per_job) + ": must be at least 1");
  if (o.lhs < 0) throw InputError("--lhs " + std::to_string(o.lhs) + ": the number of samples must be at least 1");
  if (o.out_dir.empty() && !o.dry_run) throw InputError("--out DIR is required");
  if (!o.dry_run) check_output_dir(o.out_dir, "--out");  // before anything is read or run: a bad --out fails now
  if (o.scheduler != "local" && o.scheduler != "slurm")
    throw InputError("--scheduler " + o.scheduler + ": 'local' (worker processes here) or 'slurm' (a job array)");
  if (o.scheduler == "slurm") {
    if (o.jobs > 0) throw InputError("--jobs: with --scheduler slurm the cluster runs the points; --max-parallel N limits how many at once");
    if (!o.fem_points.empty())
      throw InputError("--fem-points: not with --scheduler slurm; when the SLURM sweep has finished, the same command "
                       "without --scheduler slurm and with --fem-points runs the FEM re-runs here (the points are done)");
    check_slurm_options(o.slurm);
  } else {
    const SlurmOptions none;
    if (o.slurm.partition != none.partition || o.slurm.time != none.time || o.slurm.mem != none.mem ||
        o.slurm.account != none.account || o.slurm.max_parallel != none.max_parallel)
      throw InputError("--partition, --time, --mem, --account and --max-parallel are sbatch options: add --scheduler slurm");
  }
}

// The parameters, checked against the scene: existing numeric keys, each once.
std::vector<ParamSpec> swept_params(const SweepOptions& o, const Scene& base) {
  std::vector<ParamSpec> params;
  for (const std::string& text : o.params) {
    ParamSpec p = parse_param_spec(text);
    for (const ParamSpec& q : params)
      if (q.key == p.key) throw InputError("--param " + text + ": the key '" + p.key + "' is already swept by --param " + q.text);
    if (!base.has(p.key))
      throw InputError("--param " + text + ": unknown scene key '" + p.key +
                       "' (`pneufem scene --defaults` lists every key; a material's keys are materials.NAME.KEY)");
    try {
      base.number(p.key);
    } catch (const InputError&) {
      throw InputError("--param " + text + ": the scene key '" + p.key + "' is not a number; only numeric keys can be swept");
    }
    try {
      base.integer(p.key);
      p.integer = true;
    } catch (const InputError&) {
    }
    params.push_back(p);
  }
  return params;
}

/// The points of the sweep (in result.points), each with its scene overrides and, unless
/// --model full, its offline keys, which decide the model (plan_model).
void add_points(const SweepOptions& o, const Scene& base, const std::vector<ParamSpec>& params,
                const std::vector<std::vector<double>>& values, SweepResult& result,
                std::vector<std::vector<std::string>>& overrides, std::vector<std::optional<OfflineKeys>>& keys) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    SweepPoint pt;
    pt.index = static_cast<int>(i) + 1;
    pt.values = values[i];
    pt.final_angle_deg = kNaN;
    std::vector<std::string> ov;
    for (std::size_t j = 0; j < params.size(); ++j) {
      pt.texts.push_back(format_value(values[i][j], params[j].integer));
      ov.push_back(params[j].key + "=" + pt.texts[j]);
    }
    ov.emplace_back("output.vtu=\"none\"");
    try {
      const Scene scene = base.with(ov);
      if (o.model != "full") keys.push_back(offline_keys(scene));
    } catch (const InputError& e) {
      std::string which;
      for (const ParamSpec& p : params) which += (which.empty() ? "" : ", ") + p.text;
      throw InputError("--param " + which + ": point " + std::to_string(pt.index) + ": " + e.what());
    }
    overrides.push_back(ov);
    result.points.push_back(pt);
  }
}

/// Resume: the points already done by an earlier invocation with the same resolved scene are
/// read back (skipped); the indices of the others, to run.
std::vector<std::size_t> points_to_run(const SweepOptions& o, const fs::path& out, const std::vector<ParamSpec>& params,
                                       const std::vector<std::string>& scene_text, SweepResult& result) {
  std::vector<std::size_t> queue;
  for (std::size_t i = 0; i < result.points.size(); ++i) {
    SweepPoint& pt = result.points[i];
    const fs::path dir = out / "points" / point_name(pt.index);
    if (done_before(dir, scene_text[i])) {
      read_point(pt, dir, -1, 0.0);
      pt.skipped = true;
      ++result.ok;
      ++result.skipped;
      say(o.log, "point " + point_name(pt.index) + " skipped (already done): " + describe(params, pt));
    } else {
      queue.push_back(i);
    }
  }
  return queue;
}

/// Runs the points of `queue` in worker processes (those building a reduced model's offline part
/// first), each read back as it finishes, with sweep.csv (`csv`) rewritten.
void run_queue(const SweepOptions& o, const WorkerSetup& setup, const ModelPlan& plan, const std::vector<ParamSpec>& params,
               const std::vector<std::size_t>& queue, const std::vector<std::vector<std::string>>& overrides,
               const fs::path& csv, int jobs, SweepResult& result) {
  std::vector<Worker> workers;
  for (std::size_t i : queue) {
    const fs::path dir = setup.out / "points" / point_name(result.points[i].index);
    workers.push_back({i, dir, setup.argv(dir, overrides[i], plan.reduced)});
  }
  const auto [first, rest] = offline_waves(std::move(workers), plan);
  if (!first.empty() && !rest.empty()) {
    std::string names;
    for (const Worker& w : first) names += (names.empty() ? "" : ", ") + point_name(result.points[w.i].index);
    say(o.log, "point" + std::string(first.size() > 1 ? "s " : " ") + names + " first, building the reduced model's offline part" +
                   (first.size() > 1 ? "s" : "") + "; then the other " + std::to_string(rest.size()) + " read it");
  }
  int finished = result.skipped;
  const int total = static_cast<int>(result.points.size());
  const auto t_start = std::chrono::steady_clock::now();
  const auto point_finished = [&](const Worker& w, int exit_code, double measured_s) {
    SweepPoint& pt = result.points[w.i];
    read_point(pt, w.dir, exit_code, measured_s);
    (pt.status == "ok" ? result.ok : result.failed)++;
    ++finished;
    char head[64];
    std::snprintf(head, sizeof head, "[%d/%d] ", finished, total);
    // Elapsed and an estimate of the time left from the points this call ran (core/progress.h).
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    const int ran = finished - result.skipped, left = total - finished;
    std::string pace = "; elapsed " + duration_text(elapsed);
    if (left > 0 && ran > 0) pace += ", ~" + duration_text(elapsed * left / ran) + " left";
    say(o.log, head + outcome_line(params, pt, plan.reduced) + pace);
    write_file_atomic(csv.string(), sweep_csv(params, result.points));
  };
  run_workers(first, jobs, point_finished);
  run_workers(rest, jobs, point_finished);
}

// --- --scheduler slurm: the controller (app/sweep/slurm.h) ---

/// A job this sweep submitted: its id and its points (DIR/slurm/jobs.tsv, "ID<TAB>1,2,5").
struct SlurmJob {
  std::string id;
  std::vector<int> points;
};

std::vector<SlurmJob> read_slurm_jobs(const fs::path& tsv) {
  std::vector<SlurmJob> jobs;
  std::istringstream in(slurp(tsv));
  for (std::string line; std::getline(in, line);) {
    const std::size_t tab = line.find('\t');
    if (tab == std::string::npos || line[0] == '#') continue;
    SlurmJob j{line.substr(0, tab), {}};
    std::istringstream ps(line.substr(tab + 1));
    for (std::string p; std::getline(ps, p, ',');)
      if (const std::optional<long long> v = parse_int(p)) j.points.push_back(static_cast<int>(*v));
    jobs.push_back(j);
  }
  return jobs;
}

/// Why a submitted point that is no longer queued or running has no result of its scene.
std::string missing_point_error(const fs::path& dir, const fs::path& slurm_dir, const std::vector<SlurmJob>& jobs, int index) {
  std::string where;
  for (auto j = jobs.rbegin(); j != jobs.rend() && where.empty(); ++j)
    if (std::find(j->points.begin(), j->points.end(), index) != j->points.end()) where = j->id + "_" + std::to_string(index);
  std::string tail = log_tail(dir / "log.txt");
  if (tail.empty() && !where.empty()) tail = log_tail(slurm_dir / (where + ".out"));
  return "no result: the task" + (where.empty() ? "" : " " + where) +
         " ended without finishing (cancelled, out of time or memory, or its node failed; sacct -j " +
         (where.empty() ? "JOB" : where) + " says which)" + (tail.empty() ? "" : ": " + tail);
}

/// The points' state on disk and in the queue; returns the indices to (re)submit: failed, missing
/// or changed points that are not queued or running.
std::vector<std::size_t> collect_slurm_points(const SweepOptions& o, const fs::path& out, const std::vector<ParamSpec>& params,
                                              const std::vector<std::string>& scene_text, const std::vector<SlurmJob>& jobs,
                                              SweepResult& result) {
  std::vector<std::string> ids;
  std::set<int> submitted_before;
  for (const SlurmJob& j : jobs) {
    ids.push_back(j.id);
    submitted_before.insert(j.points.begin(), j.points.end());
  }
  const std::set<int> active = active_array_tasks(ids);  // before the points are read: a task ending now is read as ended
  std::vector<std::size_t> to_submit;
  for (std::size_t i = 0; i < result.points.size(); ++i) {
    SweepPoint& pt = result.points[i];
    const fs::path dir = out / "points" / point_name(pt.index);
    if (active.count(pt.index)) {
      ++result.pending;
      continue;
    }
    if (done_before(dir, scene_text[i])) {
      read_point(pt, dir, -1, 0.0);
      pt.skipped = true;
      ++result.ok;
      ++result.skipped;
      continue;
    }
    to_submit.push_back(i);
    const std::optional<std::string> status = run_status(read_json(dir / "summary.json"));
    if (status && *status != "ok") {
      read_point(pt, dir, 1, 0.0);  // its error is summary.json's status
    } else if (!status && submitted_before.count(pt.index)) {
      read_point(pt, dir, 1, 0.0);
      pt.error = missing_point_error(dir, out / "slurm", jobs, pt.index);
    } else {
      continue;  // never submitted, or done with another scene: pending
    }
    ++result.failed;
    say(o.log, "point " + point_name(pt.index) + " " + describe(params, pt) + ": failed: " + pt.error);
  }
  return to_submit;
}

/// The job arrays of `to_submit`: one, or (a reduced sweep) the offline parts' builders and the
/// rest after them.
std::vector<SweepArray> slurm_arrays(const SweepOptions& o, const fs::path& out, const std::vector<ParamSpec>& params,
                                     const ModelPlan& plan, const std::vector<std::size_t>& to_submit,
                                     const std::vector<std::vector<std::string>>& overrides, const SweepResult& result) {
  const WorkerSetup setup{o, out, o.scene_path.empty() ? "" : fs::absolute(o.scene_path).string(), 1};
  // The worker's command with the point's directory and values as placeholders: the same for
  // every point, whose overrides differ only in their first params.size() entries.
  std::vector<std::string> point_tail(overrides[0].begin() + static_cast<std::ptrdiff_t>(params.size()), overrides[0].end());
  point_tail.insert(point_tail.begin(), kPointWord);
  std::vector<std::string> command = setup.argv(kDirWord, point_tail, plan.reduced);
  const auto word = std::find(command.begin(), command.end(), std::string(kPointWord));
  command.erase(word - 1);  // the "--set" before it: the script writes each --set KEY=VALUE
  std::string name = "pneufem-sweep-" + file_key(out.filename().string());
  std::vector<Worker> workers;
  for (std::size_t i : to_submit) workers.push_back({i, {}, {}});
  auto [first, rest] = offline_waves(std::move(workers), plan);
  std::vector<std::vector<Worker>> waves;
  if (!first.empty() && !rest.empty()) waves = {std::move(first), std::move(rest)};
  else waves = {first.empty() ? std::move(rest) : std::move(first)};
  std::vector<SweepArray> arrays;
  for (std::vector<Worker>& wave : waves) {
    std::sort(wave.begin(), wave.end(), [](const Worker& a, const Worker& b) { return a.i < b.i; });
    SweepArray a;
    a.job_name = name;
    for (const Worker& w : wave) {
      a.points.push_back(result.points[w.i].index);
      a.values.push_back(result.points[w.i].texts);
    }
    for (const ParamSpec& p : params) a.keys.push_back(p.key);
    a.command = command;
    a.points_dir = (out / "points").string();
    a.log_dir = (out / "slurm").string();
    a.cpus_per_task = o.threads_per_job;
    a.header = "# pneufem sweep on SLURM (docs/commands.md): one task per point, the task id is the point number.\n"
               "# " + version_string() + ": " + o.command_line + "\n";
    if (!arrays.empty()) a.dependency = "FIRST_ARRAY";  // the builders' job id, set when it is known
    arrays.push_back(std::move(a));
  }
  return arrays;
}

/// A local sweep must not run points that a SLURM job of the same directory still has queued or
/// running (both would write points/NNNN). Without squeue (a directory copied off the cluster) there
/// is nothing to ask.
void refuse_points_on_slurm(const fs::path& out) {
  const std::vector<SlurmJob> jobs = read_slurm_jobs(out / "slurm" / "jobs.tsv");
  if (jobs.empty()) return;
  std::vector<std::string> ids;
  for (const SlurmJob& j : jobs) ids.push_back(j.id);
  std::set<int> active;
  try {
    active = active_array_tasks(ids);
  } catch (const std::runtime_error&) {
    return;
  }
  if (active.empty()) return;
  throw InputError("--out " + out.string() + ": " + std::to_string(active.size()) +
                   " point(s) of this sweep are queued or running on SLURM (DIR/slurm/jobs.tsv); wait for them "
                   "or scancel them before running the sweep here, or add --scheduler slurm to collect them");
}

/// --scheduler slurm: collects the points, writes the outputs of what has finished, and submits the
/// failed, missing or changed points that are not queued or running.
void run_sweep_slurm(const SweepOptions& o, const std::vector<ParamSpec>& params, const ModelPlan& plan,
                     const std::vector<std::vector<std::string>>& overrides, const std::vector<std::string>& scene_text,
                     SweepResult& result) {
  const fs::path out = fs::absolute(o.out_dir);
  std::optional<DirLock> lock;
  if (!o.dry_run) {
    prepare_output_dir((out / "points").string(), "--out");
    prepare_output_dir((out / "slurm").string(), "--out");
    lock.emplace(out);  // one controller at a time: two would submit the same points
  }
  const fs::path jobs_tsv = out / "slurm" / "jobs.tsv";
  const std::vector<SlurmJob> jobs = read_slurm_jobs(jobs_tsv);
  const std::vector<std::size_t> to_submit = collect_slurm_points(o, out, params, scene_text, jobs, result);
  if (result.pending > 0)
    say(o.log, std::to_string(result.pending) + " point(s) still queued or running; they are collected by the next call");
  std::vector<SweepArray> arrays;
  if (!to_submit.empty()) arrays = slurm_arrays(o, out, params, plan, to_submit, overrides, result);
  const int top = to_submit.empty() ? 0 : result.points[to_submit.back()].index;
  if (const long max = top > 0 ? max_array_size() : 0; max > 0 && top >= max)
    throw InputError("--scheduler slurm: the task ids are the point numbers, up to " + std::to_string(top) +
                     ", and this cluster's MaxArraySize is " + std::to_string(max) + " (ids up to " + std::to_string(max - 1) +
                     "): sweep fewer points per --out, or ask the administrators to raise MaxArraySize");
  if (o.dry_run) {
    if (arrays.empty()) say(o.log, "nothing to submit: every point is done, queued or running");
    for (std::size_t k = 0; k < arrays.size(); ++k)
      std::fprintf(stdout, "%s# ---- sbatch script %zu of %zu%s ----\n%s", k ? "\n" : "", k + 1, arrays.size(),
                   k ? " (FIRST_ARRAY: the job id of script 1)" : "", slurm_array_script(arrays[k], o.slurm).c_str());
    return;
  }
  write_file_atomic((out / "sweep.csv").string(), sweep_csv(params, result.points));
  std::string first_id;
  for (std::size_t k = 0; k < arrays.size(); ++k) {
    SweepArray& a = arrays[k];
    if (!a.dependency.empty()) a.dependency = first_id;
    std::string stamp = std::to_string(jobs.size() + k + 1);
    const fs::path script = out / "slurm" / ("array_" + stamp + ".sh");
    write_file_atomic(script.string(), slurm_array_script(a, o.slurm));
    const std::string id = sbatch_submit(script.string());
    if (k == 0) first_id = id;
    std::string list;
    for (int p : a.points) list += (list.empty() ? "" : ",") + std::to_string(p);
    std::string tsv = slurp(jobs_tsv);
    if (tsv.empty()) tsv = "# job id\tpoints (= array task ids), one line per sbatch of this sweep\n";
    write_file_atomic(jobs_tsv.string(), tsv + id + "\t" + list + "\n");
    result.submitted_jobs.push_back(id);
    result.submitted_points.insert(result.submitted_points.end(), a.points.begin(), a.points.end());
    say(o.log, "submitted job " + id + ": array " + array_spec(a.points, o.slurm.max_parallel) + " (" +
                   std::to_string(a.points.size()) + " point(s)" + (a.dependency.empty() ? "" : ", after job " + a.dependency) +
                   "), script " + script.string());
  }
  result.pending += static_cast<int>(result.submitted_points.size());
  std::sort(result.submitted_points.begin(), result.submitted_points.end());
}

}  // namespace

SweepResult run_sweep(const SweepOptions& o) {
  const auto wall0 = std::chrono::steady_clock::now();
  check_sweep_options(o);
  const Scene base = Scene::load(o.scene_path, o.sets);
  // The scene's [solver], checked before anything runs (a scene simulate would refuse is refused here).
  const SolverSettings solver = solver_settings(base);
  const std::vector<ParamSpec> params = swept_params(o, base);
  const std::vector<std::vector<double>> values = o.lhs > 0 ? lhs_points(params, o.lhs, o.seed) : grid_points(params);

  SweepResult result;
  std::vector<std::vector<std::string>> overrides;
  std::vector<std::optional<OfflineKeys>> keys;
  add_points(o, base, params, values, result, overrides, keys);
  const std::set<int> fem_points = checked_fem_points(o.fem_points, result.points.size());
  for (int index : fem_points) result.points[static_cast<std::size_t>(index) - 1].fem.emplace();  // pending: sweep.csv's columns
  const ModelPlan plan = plan_model(o, base, solver, params, overrides, keys);
  if (!fem_points.empty() && !plan.reduced)
    throw InputError("--fem-points: the points run with the full FEM already (" + plan.why +
                     "); --fem-points compares reduced points with the FEM");
  result.model = plan.reduced ? "reduced" : "full";
  result.model_reason = plan.why;
  result.offline_parts = plan.offline_parts;
  // --model decides over the scene's own solver.model; every point's resolved scene records it.
  const std::string model_key = std::string("solver.model=\"") + result.model + "\"";
  for (std::vector<std::string>& ov : overrides) ov.push_back(model_key);
  // Each point's resolved scene: what the worker will run, and the key of the resume check.
  std::vector<std::string> scene_text;
  for (const std::vector<std::string>& ov : overrides) scene_text.push_back(base.with(ov).to_toml());

  const int jobs = o.jobs > 0 ? o.jobs : std::max(1, tbb::info::default_concurrency());
  say(o.log, plan.why);
  const std::string scene_model = model_name(solver.model);
  if (scene_model != result.model && solver.model != solver_settings(Scene::load("")).model)
    say(o.log, "--model " + o.model + " decides over the scene's solver.model = \"" + scene_model + "\" (" +
                   base.origin("solver.model") + "): the points run the " + (plan.reduced ? "reduced model" : "full FEM"));
  if (o.scheduler == "slurm") {
    if (o.exe.empty()) throw std::logic_error("run_sweep: SweepOptions::exe (the pneufem binary) is not set");
    run_sweep_slurm(o, params, plan, overrides, scene_text, result);
    if (o.dry_run) return result;
    result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    write_plots_and_json(o, fs::path(o.out_dir), params, result);
    return result;
  }
  if (o.dry_run) {
    say(o.log, std::to_string(result.points.size()) + " points (" + (o.lhs > 0 ? "Latin hypercube" : "grid") + "), " +
                   std::to_string(jobs) + " worker process(es) x " + std::to_string(o.threads_per_job) + " thread(s):");
    for (const SweepPoint& pt : result.points) say(o.log, "  " + point_name(pt.index) + "  " + describe(params, pt));
    return result;
  }
  if (o.exe.empty()) throw std::logic_error("run_sweep: SweepOptions::exe (the pneufem binary) is not set");

  const fs::path out(o.out_dir);
  prepare_output_dir((out / "points").string(), "--out");
  const DirLock lock(out);
  refuse_points_on_slurm(out);
  const WorkerSetup setup{o, out, o.scene_path.empty() ? "" : fs::absolute(o.scene_path).string(), jobs};
  const std::vector<std::size_t> queue = points_to_run(o, out, params, scene_text, result);
  const fs::path csv = out / "sweep.csv";
  write_file_atomic(csv.string(), sweep_csv(params, result.points));
  say(o.log, std::to_string(result.points.size()) + " points, " + std::to_string(queue.size()) + " to run with " +
                 std::to_string(jobs) + " worker process(es) x " + std::to_string(o.threads_per_job) + " thread(s)");
  run_queue(o, setup, plan, params, queue, overrides, csv, jobs, result);
  run_fem_points(setup, base, params, fem_points, overrides, result);

  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  SweepOptions recorded = o;
  recorded.jobs = jobs;
  recorded.fem_points.assign(fem_points.begin(), fem_points.end());
  write_plots_and_json(recorded, out, params, result);
  return result;
}

}  // namespace pneufem

// Parameter sweeps: --param parsing and its errors, grid and Latin-hypercube designs (each stratum
// hit once, deterministic for a seed), and end to end through the pneufem binary on a tiny scene:
// one row per point, plots, resume (done points skipped, changed or interrupted points rerun),
// failed points recorded without stopping the sweep, and results independent of --jobs; the
// model of the points (reduced when only effect constants change, its offline part built once;
// full when the elastic reference changes) and --fem-points' comparison with the full FEM.
#include "app/sweep/command.h"

#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/app/cli_helpers.h"

#include "core/errors.h"

namespace {

using namespace pneufem;
namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// Specs and designs (in process)

TEST(SweepSpec, ParsesKeyRangeCountAndSpacing) {
  ParamSpec p = parse_param_spec("materials.silicone.fatigue.tau_s=100:1000:5:log");
  EXPECT_EQ(p.key, "materials.silicone.fatigue.tau_s");
  EXPECT_EQ(p.lo, 100.0);
  EXPECT_EQ(p.hi, 1000.0);
  EXPECT_EQ(p.n, 5);
  EXPECT_TRUE(p.log);
  p = parse_param_spec("mesh.h_mm=1.5e0:3:4");
  EXPECT_EQ(p.lo, 1.5);
  EXPECT_EQ(p.n, 4);
  EXPECT_FALSE(p.log);
  p = parse_param_spec("materials.silicone.fatigue.q=-1:2:lin");  // N may be left out (for --lhs)
  EXPECT_EQ(p.n, 0);
  EXPECT_EQ(p.lo, -1.0);
  EXPECT_EQ(parse_param_spec("a.b=2:2:1").hi, 2.0);
}

void expect_error(const std::string& spec, const std::string& fragment) {
  try {
    parse_param_spec(spec);
    ADD_FAILURE() << spec << " was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("--param " + spec + ": ", 0), 0u) << what;  // names the option and the spec
    EXPECT_NE(what.find(fragment), std::string::npos) << what;
  }
}

TEST(SweepSpec, RejectsMalformedSpecsNamingTheOption) {
  expect_error("materials.silicone.fatigue.tau_s", "expected KEY=LO:HI:N[:log]");
  expect_error("=1:2:3", "expected KEY=LO:HI:N[:log]");
  expect_error("a.b=1", "expected KEY=LO:HI:N[:log]");
  expect_error("a.b=1:2:3:log:x", "expected KEY=LO:HI:N[:log]");
  expect_error("a.b=x:2:3", "LO 'x' is not a number");
  expect_error("a.b=1:2e:3", "HI '2e' is not a number");
  expect_error("a.b=1:2:2.5", "N '2.5' is not a whole number");
  expect_error("a.b=1:2:0", "N must be at least 1");
  expect_error("a.b=1:2:-3", "N must be at least 1");
  expect_error("a.b=1:2:3:logarithmic", "must be 'log' or 'lin'");
  expect_error("a.b=5:1:3", "LO (5) is greater than HI (1)");
  expect_error("a.b=0:10:3:log", "a log range needs LO > 0");
  expect_error("a.b=-1:10:3:log", "a log range needs LO > 0");
  expect_error("a.b=1:nan:3", "HI 'nan' is not a number");
}

TEST(SweepDesign, GridValuesAndProduct) {
  ParamSpec lin = parse_param_spec("x=0:1:5");
  EXPECT_EQ(grid_values(lin), (std::vector<double>{0.0, 0.25, 0.5, 0.75, 1.0}));
  ParamSpec lg = parse_param_spec("x=100:10000:3:log");
  const std::vector<double> v = grid_values(lg);
  ASSERT_EQ(v.size(), 3u);
  EXPECT_EQ(v[0], 100.0);
  EXPECT_NEAR(v[1], 1000.0, 1e-9);
  EXPECT_EQ(v[2], 10000.0);  // end points exact
  ParamSpec one = parse_param_spec("x=3:7:1");
  EXPECT_EQ(grid_values(one), std::vector<double>{3.0});
  ParamSpec ints = parse_param_spec("geometry.chambers=2:4:5");
  ints.integer = true;
  EXPECT_EQ(grid_values(ints), (std::vector<double>{2.0, 3.0, 4.0}));  // rounded, repeats dropped

  const auto pts = grid_points({parse_param_spec("a=1:2:2"), parse_param_spec("b=10:30:3")});
  ASSERT_EQ(pts.size(), 6u);
  EXPECT_EQ(pts[0], (std::vector<double>{1, 10}));
  EXPECT_EQ(pts[1], (std::vector<double>{1, 20}));  // the last parameter varies fastest
  EXPECT_EQ(pts[5], (std::vector<double>{2, 30}));
  EXPECT_THROW(grid_points({parse_param_spec("a=1:2:lin")}), InputError);  // N needed without --lhs
}

TEST(SweepDesign, LatinHypercubeHitsEachStratumOnceAndIsDeterministic) {
  const std::vector<ParamSpec> params = {parse_param_spec("a=0:1:lin"), parse_param_spec("b=10:1000:log"),
                                         parse_param_spec("c=-5:5")};
  for (int n : {1, 7, 50}) {
    const auto pts = lhs_points(params, n, 42);
    ASSERT_EQ(pts.size(), static_cast<std::size_t>(n));
    for (std::size_t j = 0; j < params.size(); ++j) {
      std::set<int> strata;
      for (const auto& p : pts) {
        const ParamSpec& s = params[j];
        const double u = s.log ? std::log(p[j] / s.lo) / std::log(s.hi / s.lo) : (p[j] - s.lo) / (s.hi - s.lo);
        ASSERT_GE(u, 0.0);
        ASSERT_LT(u, 1.0);
        strata.insert(static_cast<int>(std::floor(u * n)));
      }
      EXPECT_EQ(strata.size(), static_cast<std::size_t>(n)) << "parameter " << j << ", n = " << n;
    }
  }
  EXPECT_EQ(lhs_points(params, 20, 7), lhs_points(params, 20, 7));
  EXPECT_NE(lhs_points(params, 20, 7), lhs_points(params, 20, 8));
  // The pairing is random: the columns are not all in the same order.
  const auto pts = lhs_points(params, 20, 7);
  int same_order = 0;
  for (std::size_t i = 1; i < pts.size(); ++i) same_order += (pts[i][0] > pts[i - 1][0]) == (pts[i][2] > pts[i - 1][2]);
  EXPECT_LT(same_order, 19);
  EXPECT_THROW(lhs_points(params, 0, 1), InputError);
}

TEST(SweepDesign, ValuesAreWrittenAsSceneText) {
  EXPECT_EQ(format_value(100.0, false), "100.0");
  EXPECT_EQ(format_value(-500.0, false), "-500.0");
  EXPECT_EQ(format_value(0.019, false), "0.019");
  EXPECT_EQ(format_value(1e-5, false), "1e-05");
  EXPECT_EQ(format_value(std::sqrt(10.0) * 100.0, false), "316.22776601683796");  // reads back exactly
  EXPECT_EQ(format_value(3.0, true), "3");
}

// ---------------------------------------------------------------------------------------------
// End to end through the binary

using Result = pneufem::test::CliResult;
inline Result run(const std::string& args) { return pneufem::test::run_cli(args); }
using pneufem::test::slurp;


fs::path fresh_dir(const std::string& name) { return pneufem::test::fresh_dir("sweep_" + name); }

std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> f(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == '"') {
      if (quoted && i + 1 < line.size() && line[i + 1] == '"') f.back() += '"', ++i;
      else quoted = !quoted;
    } else if (c == ',' && !quoted) {
      f.emplace_back();
    } else {
      f.back() += c;
    }
  }
  return f;
}

/// sweep.csv as rows of column -> value.
std::vector<std::map<std::string, std::string>> read_csv(const fs::path& p) {
  std::istringstream in(slurp(p));
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> head = split_csv_line(line);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    const std::vector<std::string> f = split_csv_line(line);
    EXPECT_EQ(f.size(), head.size()) << line;
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < head.size() && i < f.size(); ++i) row[head[i]] = f[i];
    rows.push_back(row);
  }
  return rows;
}

// A tiny fatigue scene: two chambers, coarse mesh, 0-10 kPa, two trials; a low damage threshold
// so that tau_s changes the result. About 1.5 s per point with the full FEM; a sweep over tau_s runs
// the reduced model (--model auto), whose offline part adds ~12 s once.
const std::string kTiny =
    "--set geometry.chambers=2 --set mesh.h_mm=6.0 --set load.max_kPa=10.0 --set load.trials=2 "
    "--set materials.silicone.fatigue.enabled=true --set materials.silicone.fatigue.W_th_MPa=0.002";
const std::string kTau = "materials.silicone.fatigue.tau_s";

TEST(SweepCli, GridSweepResumesAndDoesNotDependOnJobs) {
  const fs::path d = fresh_dir("grid");
  // The full FEM: its points share the ideal elastic model through the sweep's ideal cache (a
  // reduced run computes its own, in seconds, with the reduced model).
  const std::string args = "sweep --param " + kTau + "=100:1000:3:log " + kTiny + " --model full --threads-per-job 1 --out ";
  const Result r = run(args + d.string() + " --jobs 2");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("3 points, 3 ok (0 skipped), 0 failed"), std::string::npos) << r.out;

  // One row per point with its parameter value, metrics per trial, and a plot.
  const auto rows = read_csv(d / "sweep.csv");
  ASSERT_EQ(rows.size(), 3u);
  const std::vector<std::string> taus = {"100.0", "316.22776601683796", "1000.0"};
  std::set<std::string> nrmse;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].at("point"), std::to_string(i + 1));
    EXPECT_EQ(rows[i].at(kTau), taus[i]);
    EXPECT_EQ(rows[i].at("status"), "ok");
    EXPECT_EQ(rows[i].at("error"), "");
    EXPECT_FALSE(rows[i].at("nrmse_trial_1").empty());
    EXPECT_EQ(rows[i].at("final_nrmse"), rows[i].at("nrmse_trial_2"));
    EXPECT_GT(std::stod(rows[i].at("final_nrmse")), 0.0);
    nrmse.insert(rows[i].at("final_nrmse"));
    EXPECT_TRUE(fs::exists(d / "points" / ("000" + std::to_string(i + 1)) / "summary.json"));
  }
  EXPECT_EQ(nrmse.size(), 3u);  // tau_s matters
  // The points share one ideal elastic model (tau_s is not part of it): one computes, the others
  // read the cache, and all compare against the same angles.
  int computed = 0, cached = 0;
  for (int i = 1; i <= 3; ++i) {
    const fs::path pd = d / "points" / ("000" + std::to_string(i));
    const std::string summary = slurp(pd / "summary.json");
    computed += summary.find("\"ideal_model\": \"computed\"") != std::string::npos;
    cached += summary.find("\"ideal_model\": \"cache ") != std::string::npos;
    EXPECT_EQ(slurp(pd / "ideal_angles.csv"), slurp(d / "points" / "0001" / "ideal_angles.csv"));
  }
  EXPECT_EQ(computed, 1);
  EXPECT_EQ(cached, 2);
  const std::string svg = slurp(d / ("sweep_" + kTau + ".svg"));
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_EQ(count(svg, "<circle"), 3u + 1u);  // three points and the legend sample
  const std::string json = slurp(d / "sweep.json");
  for (const char* k : {"\"mode\": \"grid\"", "\"ok\": 3", "\"failed\": 0", "\"best_point\": 3", "\"points\""})
    EXPECT_NE(json.find(k), std::string::npos) << k;
  EXPECT_FALSE(fs::exists(d / "sweep.csv.tmp"));

  // Again: every point is done, nothing runs, the table is the same.
  const std::string csv1 = slurp(d / "sweep.csv");
  const auto mtime = [&](int i) { return fs::last_write_time(d / "points" / ("000" + std::to_string(i)) / "summary.json"); };
  const auto m1 = mtime(1), m2 = mtime(2), m3 = mtime(3);
  const Result again = run(args + d.string() + " --jobs 2");
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_EQ(count(again.out, "skipped (already done)"), 3u) << again.out;
  EXPECT_EQ(mtime(1), m1);
  EXPECT_EQ(mtime(2), m2);
  EXPECT_EQ(mtime(3), m3);
  EXPECT_EQ(slurp(d / "sweep.csv"), csv1);

  // An interrupted point (no summary.json) runs again; the others are skipped.
  fs::remove(d / "points" / "0002" / "summary.json");
  const Result resumed = run(args + d.string() + " --jobs 2");
  ASSERT_EQ(resumed.code, 0) << resumed.out;
  EXPECT_EQ(count(resumed.out, "skipped (already done)"), 2u) << resumed.out;
  EXPECT_NE(resumed.out.find("point 0002 " + kTau + "=316.22776601683796: ok"), std::string::npos) << resumed.out;
  EXPECT_EQ(mtime(1), m1);

  // Changed values rerun only the points whose scene changed (point 1 is still tau = 100).
  const Result changed = run("sweep --param " + kTau + "=100:1000:2:log " + kTiny + " --model full --jobs 2 --out " + d.string());
  ASSERT_EQ(changed.code, 0) << changed.out;
  EXPECT_EQ(count(changed.out, "skipped (already done)"), 1u) << changed.out;
  EXPECT_EQ(read_csv(d / "sweep.csv")[1].at(kTau), "1000.0");
  EXPECT_EQ(mtime(1), m1);

  // --jobs 1 gives the same table, apart from the wall-clock times.
  const fs::path d1 = fresh_dir("grid_j1");
  const Result serial = run(args + d1.string() + " --jobs 1");
  ASSERT_EQ(serial.code, 0) << serial.out;
  auto strip_wall = [](std::vector<std::map<std::string, std::string>> table) {
    for (auto& row : table) row.erase("wall_s");
    return table;
  };
  const std::string csv_j1 = slurp(d1 / "sweep.csv");
  std::ofstream(d / "sweep_j2.csv") << csv1;
  EXPECT_EQ(strip_wall(read_csv(d1 / "sweep.csv")), strip_wall(read_csv(d / "sweep_j2.csv"))) << csv_j1 << "\n" << csv1;
  fs::remove_all(d);
  fs::remove_all(d1);
}

/// The ideal_model entry of a run's summary.json ("computed", "cache <file>", ...).
std::string ideal_source(const fs::path& run_dir) {
  const std::string s = slurp(run_dir / "summary.json");
  const std::string key = "\"ideal_model\": \"";
  const std::size_t p = s.find(key);
  if (p == std::string::npos) return "";
  return s.substr(p + key.size(), s.find('"', p + key.size()) - p - key.size());
}

std::vector<fs::path> cache_files(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".csv") out.push_back(e.path());
  return out;
}

TEST(IdealCache, SharedBetweenRunsKeyedByTheElasticModelAndRepairedWhenDamaged) {
  const fs::path d = fresh_dir("ideal_cache"), cache = d / "cache";
  auto simulate = [&](const std::string& name, const std::string& extra, bool use_cache) {
    const Result r = run("simulate " + kTiny + " " + extra + " --threads 1 --out " + (d / name).string() +
                         (use_cache ? " --ideal-cache " + cache.string() : ""));
    EXPECT_EQ(r.code, 0) << r.out;
    return d / name;
  };
  // First run computes and stores; a run with other damage constants reads it, and its metrics are
  // those of a run that computes its own ideal model (the cache only saves the time).
  const fs::path a = simulate("a", "", true);
  EXPECT_EQ(ideal_source(a), "computed");
  ASSERT_EQ(cache_files(cache).size(), 1u);
  const fs::path b = simulate("b", "--set " + kTau + "=300", true);
  EXPECT_EQ(ideal_source(b), "cache " + cache_files(cache)[0].string());
  EXPECT_EQ(slurp(b / "ideal_angles.csv"), slurp(a / "ideal_angles.csv"));
  const fs::path b_own = simulate("b_own", "--set " + kTau + "=300", false);
  EXPECT_EQ(ideal_source(b_own), "computed");
  EXPECT_EQ(slurp(b / "metrics.json"), slurp(b_own / "metrics.json"));

  // An elastic change (the silicone's stiffness) is another ideal model: a second entry.
  const fs::path c = simulate("c", "--set materials.silicone.stiffness_scale=0.9", true);
  EXPECT_EQ(ideal_source(c), "computed");
  EXPECT_EQ(cache_files(cache).size(), 2u);
  EXPECT_NE(slurp(c / "ideal_angles.csv"), slurp(a / "ideal_angles.csv"));

  // A damaged entry (a line lost) is not trusted: recomputed, replaced, and said so.
  const fs::path entry = fs::path(ideal_source(b).substr(6));
  const std::string original = slurp(entry);
  std::string text = original;
  text.erase(text.rfind('\n', text.size() - 2) + 1);
  std::ofstream(entry, std::ios::trunc) << text;
  const fs::path b2 = simulate("b2", "--set " + kTau + "=300", true);
  EXPECT_EQ(ideal_source(b2), "computed");
  EXPECT_NE(slurp(b2 / "summary.json").find("recomputed and replaced"), std::string::npos);
  EXPECT_EQ(slurp(b2 / "metrics.json"), slurp(b_own / "metrics.json"));
  EXPECT_EQ(slurp(entry), original);  // the same model again, deterministically
  fs::remove_all(d);
}

TEST(SweepCli, FailedPointIsRecordedAndTheOthersRun) {
  const fs::path d = fresh_dir("fail");
  // tau_s = -500 is rejected by the fatigue law; 250 and 1000 run.
  const Result r = run("sweep --param " + kTau + "=-500:1000:3 " + kTiny + " --jobs 2 --out " + d.string());
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("3 points, 2 ok (0 skipped), 1 failed"), std::string::npos) << r.out;
  const auto rows = read_csv(d / "sweep.csv");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].at(kTau), "-500.0");
  EXPECT_EQ(rows[0].at("status"), "failed");
  EXPECT_NE(rows[0].at("error").find("tau must be > 0"), std::string::npos) << rows[0].at("error");
  EXPECT_NE(rows[0].at("error").find("exit code 2"), std::string::npos) << rows[0].at("error");
  EXPECT_EQ(rows[0].at("final_nrmse"), "");
  for (int i : {1, 2}) {
    EXPECT_EQ(rows[i].at("status"), "ok");
    EXPECT_FALSE(rows[i].at("final_nrmse").empty());
  }
  const std::string svg = slurp(d / ("sweep_" + kTau + ".svg"));
  EXPECT_NE(svg.find(">failed</text>"), std::string::npos);  // failed points are marked
  EXPECT_NE(slurp(d / "sweep.json").find("\"failed\": 1"), std::string::npos);
  fs::remove_all(d);
}

TEST(SweepCli, BadOptionsAreRejectedBeforeAnythingRuns) {
  const fs::path d = fresh_dir("bad");
  struct Case {
    std::string args, message;
  };
  const std::vector<Case> cases = {
      {"--param " + kTau + "=100:1000", "give the number of values N"},
      {"--param " + kTau + "=100:1000:0", "--param: " + kTau + "=100:1000:0: N must be at least 1"},
      {"--param " + kTau + "=1000:100:3", "LO (1000) is greater than HI (100)"},
      {"--param " + kTau + "=0:100:3:log", "a log range needs LO > 0"},
      {"--param " + kTau + "=100/1000/3", "expected KEY=LO:HI:N[:log]"},
      {"--param materials.silicone.fatigue.tau=1:2:2", "--param materials.silicone.fatigue.tau=1:2:2: unknown scene key"},
      {"--param solver.method=1:2:2", "is not a number"},
      {"--param " + kTau + "=1:2:2 --param " + kTau + "=3:4:2", "already swept"},
      {"--param " + kTau + "=1:2:2 --jobs 0", "--jobs"},
      {"--param " + kTau + "=1:2:2 --threads-per-job 0", "--threads-per-job"},
      {"--param " + kTau + "=1:2:2 --set solver.metod=newton", "did you mean 'solver.method'"},
      {"--param " + kTau + "=1:2:2 --partition gpu", "sbatch options: add --scheduler slurm"},
      {"--param " + kTau + "=1:2:2 --scheduler slurm --jobs 2", "--max-parallel N limits how many at once"},
      {"--param " + kTau + "=1:2:2 --scheduler slurm --fem-points 1", "--fem-points: not with --scheduler slurm"},
      {"--param " + kTau + "=1:2:2 --scheduler slurm --time 2h", "--time '2h': SLURM's form is MINUTES, HH:MM:SS"},
      {"--param " + kTau + "=1:2:2 --scheduler slurm --mem 4GB", "--mem '4GB': memory per task"},
      {"--param " + kTau + "=1:2:2 --scheduler slurm --partition 'a b'", "--partition 'a b': a partition name"},
      {"--param " + kTau + "=1:2:2 --scheduler pbs", "--scheduler: pbs not in {local,slurm}"},
  };
  for (const Case& c : cases) {
    const Result r = run("sweep " + c.args + " --out " + d.string());
    EXPECT_NE(r.code, 0) << c.args;
    EXPECT_NE(r.out.find(c.message), std::string::npos) << c.args << "\n" << r.out;
  }
  EXPECT_FALSE(fs::exists(d / "points"));

  // --lhs needs no N; --dry-run lists the points and writes nothing.
  const Result dry = run("sweep --param " + kTau + "=100:1000:log --param load.max_kPa=5:15 --lhs 4 --seed 3 --dry-run --out " +
                         d.string());
  ASSERT_EQ(dry.code, 0) << dry.out;
  EXPECT_NE(dry.out.find("4 points (Latin hypercube)"), std::string::npos) << dry.out;
  EXPECT_EQ(count(dry.out, "load.max_kPa="), 4u);
  EXPECT_FALSE(fs::exists(d));

  // With --scheduler slurm, --dry-run prints the array script (no SLURM needed) and writes nothing:
  // the task id selects the point, whose run is the local worker's command.
  const Result script = run("sweep --param " + kTau + "=100:1000:3:log " + kTiny +
                            " --model full --scheduler slurm --partition short --time 1:00:00 --mem 2G --account lab "
                            "--max-parallel 2 --threads-per-job 3 --dry-run --out " + d.string());
  ASSERT_EQ(script.code, 0) << script.out;
  for (const std::string& line :
       {std::string("#SBATCH --array=1-3%2\n"), std::string("#SBATCH --partition=short\n"), std::string("#SBATCH --time=1:00:00\n"),
        std::string("#SBATCH --mem=2G\n"), std::string("#SBATCH --account=lab\n"), std::string("#SBATCH --cpus-per-task=3\n"),
        "keys=('" + kTau + "')\n", std::string("  2) values=('316.22776601683796') ;;\n"),
        std::string("'--threads' '3' '--ideal-cache' '") + fs::absolute(d).string() + "/ideal_cache'",
        std::string("\"${sets[@]}\" '--set' 'output.vtu=\"none\"' '--set' 'solver.model=\"full\"' > \"$dir/log.txt\" 2>&1\n")})
    EXPECT_NE(script.out.find(line), std::string::npos) << line << "\n" << script.out;
  EXPECT_FALSE(fs::exists(d));

  const Result help = run("sweep --help");
  for (const char* opt : {"--param", "--lhs", "--seed", "--out", "--jobs", "--threads-per-job", "--set", "--dry-run", "--model",
                          "--fem-points", "--scheduler", "--partition", "--time", "--mem", "--account", "--max-parallel"})
    EXPECT_NE(help.out.find(opt), std::string::npos) << opt;
}

// ---------------------------------------------------------------------------------------------
// The model of the points

// The small story scene of tests/app/simulate/test_reduced.cpp: 3 chambers, h = 6 mm, Mullins,
// fatigue and viscoelasticity, one trial with 4 s holds; ~5 s per reduced run once its offline
// part is built.
const std::string kStory = std::string(PNEUFEM_TEST_DATA_DIR) + "/../../scenes/examples/paper_story.toml";
const std::string kSmallStory = kStory +
                                " --set geometry.chambers=3 --set mesh.h_mm=6.0 --set load.trials=1 --set load.hold_s=4.0 "
                                "--set load.mark_s=2.0 --threads-per-job 1";

/// A field of a run's summary.json reduced_model.offline ("basis" or "path").
std::string offline_source(const fs::path& run_dir, const std::string& field) {
  const nlohmann::json s = nlohmann::json::parse(slurp(run_dir / "summary.json"), nullptr, false);
  if (s.is_discarded() || !s.contains("reduced_model") || !s["reduced_model"].is_object()) return "";
  return s["reduced_model"]["offline"].value(field, "");
}

TEST(SweepModel, EffectConstantsRunTheReducedModelWithOneOfflinePart) {
  const fs::path d = fresh_dir("rom_fatigue");
  const Result r = run("sweep " + kSmallStory + " --param " + kTau + "=80:160:2 --jobs 2 --out " + d.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("reduced model: every point has the same elastic reference (the swept keys are effect constants, "
                       "gravity or protocol), so the points share one offline part"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("point 0001 first, building the reduced model's offline part; then the other 1 read it"),
            std::string::npos)
      << r.out;
  // Point 1 ran alone and built the basis; point 2 read it from rom_cache/.
  EXPECT_EQ(offline_source(d / "points" / "0001", "basis"), "computed");
  EXPECT_EQ(offline_source(d / "points" / "0002", "basis").rfind("cache " + (d / "rom_cache").string(), 0), 0u)
      << offline_source(d / "points" / "0002", "basis");
  const auto rows = read_csv(d / "sweep.csv");
  ASSERT_EQ(rows.size(), 2u);
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("status"), "ok");
    EXPECT_EQ(row.at("model"), "reduced");
    EXPECT_FALSE(row.at("final_nrmse").empty());
    EXPECT_EQ(row.count("fem_final_nrmse"), 0u);  // no --fem-points, no FEM columns
  }
  EXPECT_NE(rows[0].at("final_nrmse"), rows[1].at("final_nrmse"));  // tau_s matters
  const nlohmann::json j = nlohmann::json::parse(slurp(d / "sweep.json"));
  EXPECT_EQ(j["model"], "reduced");
  EXPECT_EQ(j["offline_parts"], 1);
  EXPECT_EQ(j["points"][1]["model"], "reduced");
  fs::remove_all(d);
}

TEST(SweepModel, AnElasticModulusRunsTheFullFemUnderAuto) {
  const fs::path d = fresh_dir("rom_modulus");
  const std::string modulus = "materials.silicone.C10_MPa";
  const Result r = run("sweep --param " + modulus + "=0.018:0.02:2 " + kTiny + " --jobs 2 --out " + d.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("full FEM: " + modulus + " changes the elastic reference, which the reduced model's basis is built for"),
            std::string::npos)
      << r.out;
  for (const auto& row : read_csv(d / "sweep.csv")) EXPECT_EQ(row.at("model"), "full");
  EXPECT_FALSE(fs::exists(d / "points" / "0001" / "reduced_check.csv"));
  EXPECT_EQ(nlohmann::json::parse(slurp(d / "sweep.json"))["model"], "full");

  // --model reduced is allowed, at the price of one offline part per actuator, and said so; --model
  // decides over the scene's own solver.model, and says that too.
  const Result forced = run("sweep --param " + modulus + "=0.018:0.02:2 " + kTiny +
                            " --model reduced --dry-run --out " + d.string());
  ASSERT_EQ(forced.code, 0) << forced.out;
  EXPECT_NE(forced.out.find("costs one offline part per distinct actuator: 2 offline parts"), std::string::npos) << forced.out;
  const Result over = run("sweep --param " + kTau + "=100:1000:2 " + kTiny +
                          " --set solver.model=reduced --model full --dry-run --out " + d.string());
  ASSERT_EQ(over.code, 0) << over.out;
  EXPECT_NE(over.out.find("--model full decides over the scene's solver.model = \"reduced\" (--set solver.model): the points run the full FEM"),
            std::string::npos)
      << over.out;
  fs::remove_all(d);
}

// The reduced model's verified accuracy on this scene: every report within 0.1 deg of the full
// FEM (tests/app/simulate/test_reduced.cpp, the same scene and bound), and the trials' NRMSE
// within the 0.5 points (tests/engine/test_rom.cpp, measured 0.28 points on the default
// actuator). The sweep must record a difference within those bounds, read from both runs' angles.csv.
TEST(SweepModel, FemPointsRecordTheFemNrmseAndTheReducedError) {
  const fs::path d = fresh_dir("rom_fem_points");
  const Result r = run("sweep " + kSmallStory + " --param " + kTau + "=80:80:1 --fem-points 1 --jobs 2 --out " + d.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("FEM re-run of point 0001: final NRMSE"), std::string::npos) << r.out;
  const fs::path fem = d / "points" / "0001" / "fem";
  EXPECT_EQ(nlohmann::json::parse(slurp(fem / "summary.json"))["solver"]["model"], "full");
  const auto rows = read_csv(d / "sweep.csv");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].at("model"), "reduced");
  ASSERT_FALSE(rows[0].at("fem_final_nrmse").empty()) << slurp(d / "sweep.csv");
  ASSERT_FALSE(rows[0].at("max_abs_reduced_minus_fem_deg").empty());
  const double diff = std::stod(rows[0].at("max_abs_reduced_minus_fem_deg"));
  EXPECT_GT(diff, 0.0);  // two different models
  EXPECT_LT(diff, 0.1);
  EXPECT_NEAR(std::stod(rows[0].at("final_nrmse")), std::stod(rows[0].at("fem_final_nrmse")), 0.005);
  const nlohmann::json j = nlohmann::json::parse(slurp(d / "sweep.json"));
  EXPECT_EQ(j["points"][0]["fem"]["status"], "ok");
  EXPECT_EQ(j["points"][0]["fem"]["max_abs_reduced_minus_fem_deg"].get<double>(), diff);

  // Again: the point and its FEM re-run are done, nothing runs, the table is the same.
  const std::string csv = slurp(d / "sweep.csv");
  const Result again = run("sweep " + kSmallStory + " --param " + kTau + "=80:80:1 --fem-points 1 --jobs 2 --out " + d.string());
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_NE(again.out.find("FEM re-run of point 0001 skipped (already done)"), std::string::npos) << again.out;
  EXPECT_EQ(slurp(d / "sweep.csv"), csv);
  fs::remove_all(d);
}

// The base scene's [solver] is read once into its typed settings (scenes/scene_settings.h): the
// model plan and its messages use them, with the keys' origins; a [solver] that simulate would
// refuse is refused before any point runs (before, a bad solver.mode sent every point to fail in
// its worker, and solver.model = "reduced" in an explicit scene ran as the full FEM unsaid).
TEST(SweepModel, TheScenesSolverIsReadOnceAndCheckedBeforeAnythingRuns) {
  const fs::path d = fresh_dir("rom_solver");
  const std::string sweep = "sweep --param " + kTau + "=100:1000:2 " + kTiny + " --dry-run --out " + d.string() + " ";
  const std::string why = "the reduced model runs quasi-static scenes only, and solver.mode = \"explicit\" (--set solver.mode)";
  const Result auto_model = run(sweep + "--set solver.mode=explicit");
  ASSERT_EQ(auto_model.code, 0) << auto_model.out;
  EXPECT_NE(auto_model.out.find("full FEM: " + why), std::string::npos) << auto_model.out;
  struct Case {
    std::string args, message;
  };
  const std::vector<Case> cases = {
      {"--set solver.mode=explicit --model reduced", "--model reduced: " + why},
      {"--set solver.mode=explict",
       "--set solver.mode: key 'solver.mode': must be \"quasi_static\" or \"explicit\", got \"explict\""},
      {"--set solver.mode=explicit --set solver.model=reduced",
       "--set solver.model: key 'solver.model': \"reduced\" needs solver.mode = \"quasi_static\""},
      {"--set solver.rel_tol=-1", "--set solver.rel_tol: key 'solver.rel_tol'"},
  };
  for (const Case& c : cases) {
    const Result r = run(sweep + c.args);
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.out;
    EXPECT_NE(r.out.find(c.message), std::string::npos) << c.args << "\n" << r.out;
  }
  EXPECT_FALSE(fs::exists(d / "points"));
}

TEST(SweepModel, BadFemPointsAndModelAreRejectedBeforeAnythingRuns) {
  const fs::path d = fresh_dir("rom_bad");
  struct Case {
    std::string args, message;
  };
  const std::vector<Case> cases = {
      {"--fem-points 3", "--fem-points 3: no such point; the sweep's points are 1 to 2"},
      {"--fem-points 1,0", "--fem-points 0: no such point"},
      {"--fem-points x", "--fem-points"},
      {"--model tiny", "--model: tiny not in {auto,full,reduced}"},
      {"--model full --fem-points 1", "--fem-points: the points run with the full FEM already"},
  };
  for (const Case& c : cases) {
    const Result r = run("sweep --param " + kTau + "=100:1000:2 " + kTiny + " " + c.args + " --out " + d.string());
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.out;
    EXPECT_NE(r.out.find(c.message), std::string::npos) << c.args << "\n" << r.out;
  }
  EXPECT_FALSE(fs::exists(d / "points"));
}

}  // namespace

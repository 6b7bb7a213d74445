// The CLI as a product: a tiny scene runs end to end and writes every output; bad input gives a
// clear message and exit code 2 without leaving partial files; --help is helpful.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "tests/app/cli_helpers.h"

namespace {

namespace fs = std::filesystem;

using Result = pneufem::test::CliResult;
inline Result run(const std::string& args) { return pneufem::test::run_cli(args); }
using pneufem::test::slurp;


fs::path fresh_dir(const std::string& name) { return pneufem::test::fresh_dir("cli_" + name); }

const std::string kTiny =
    "--set geometry.chambers=2 --set mesh.h_mm=6.0 --set load.max_kPa=5.0 --set mesh.element=\\\"tet10\\\"";

TEST(Cli, SimulateTinySceneWritesAllOutputs) {
  const fs::path d = fresh_dir("sim");
  const Result r = run("simulate --out " + d.string() + " " + kTiny + " --threads 2");
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* f : {"angles.csv", "states.csv", "summary.json", "scene.toml", "results.pvd"})
    EXPECT_TRUE(fs::exists(d / f)) << f;
  const std::string angles = slurp(d / "angles.csv");
  EXPECT_EQ(angles.rfind("trial,time_s,pressure_kPa,angle_deg\n", 0), 0u);
  // 2 levels (0, 5 kPa) x (2.5 s mark + end of hold) = 4 rows + header
  EXPECT_EQ(std::count(angles.begin(), angles.end(), '\n'), 5);
  // The console says what the run found (issue 31 item 4): the angle at the top pressure, the
  // last row of angles.csv, to two decimals.
  const std::string last_row = angles.substr(angles.rfind('\n', angles.size() - 2) + 1);
  char expect[96];
  std::snprintf(expect, sizeof expect, "angle at the top pressure, 5.0 kPa (the last report there): trial 1 %.2f deg",
                std::stod(last_row.substr(last_row.rfind(',') + 1)));
  EXPECT_NE(r.out.find(expect), std::string::npos) << r.out;
  const std::string summary = slurp(d / "summary.json");
  for (const char* key : {"\"pneufem_version\"", "\"status\": \"ok\"", "\"mesh\"", "\"nodes\"", "\"solver\"", "\"timings\"",
                          "\"scene\"", "\"elements_per_region\""})
    EXPECT_NE(summary.find(key), std::string::npos) << key;
  EXPECT_FALSE(fs::exists(d / "angles.csv.tmp"));
  // The resolved scene re-runs as is and gives the same angles (determinism).
  const fs::path d2 = fresh_dir("sim2");
  const Result r2 = run("simulate " + (d / "scene.toml").string() + " --out " + d2.string() + " --threads 1");
  ASSERT_EQ(r2.code, 0) << r2.out;
  EXPECT_EQ(slurp(d2 / "angles.csv"), angles);
}

TEST(Cli, BadInputGivesExitCode2AndAMessage) {
  const fs::path d = fresh_dir("bad");
  Result r = run("simulate --out " + d.string() + " --set solver.metod=newton");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("did you mean 'solver.method'"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(d / "angles.csv"));

  const fs::path scene = fs::temp_directory_path() / "pneufem_cli_bad.toml";
  std::ofstream(scene) << "[mesh]\nh_mm = -1.0\n";
  r = run("simulate " + scene.string() + " --out " + d.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("mesh.h"), std::string::npos) << r.out;

  r = run("mesh --out /tmp/pneufem_cli_x.stl");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find(".vtu"), std::string::npos) << r.out;

  // Malformed command lines (an option out of range, an unknown option) are bad input too.
  r = run("simulate --threads 0 --out " + d.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--threads"), std::string::npos) << r.out;
  r = run("diagnose --data " + std::string(PNEUFEM_TEST_DATA_DIR) + "/hidden/none.csv --out " + d.string() + " --fem-calibrate -1");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--fem-calibrate"), std::string::npos) << r.out;
  r = run("simulate --no-such-option");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_FALSE(fs::exists(d / "angles.csv"));
}

TEST(Cli, HelpListsTheSubcommands) {
  const Result r = run("--help");
  EXPECT_EQ(r.code, 0);
  for (const char* s : {"simulate", "mesh", "scene"}) EXPECT_NE(r.out.find(s), std::string::npos) << s;
  const Result rs = run("simulate --help");
  EXPECT_NE(rs.out.find("--set"), std::string::npos);
  EXPECT_NE(rs.out.find("--threads"), std::string::npos);
}

// Every output file of a run directory: the run-level files and each VTU state.
std::vector<std::string> output_files(const fs::path& dir) {
  std::vector<std::string> files = {"angles.csv", "states.csv", "metrics.json", "results.pvd"};
  for (const auto& e : fs::directory_iterator(dir / "vtu")) files.push_back("vtu/" + e.path().filename().string());
  std::sort(files.begin() + 4, files.end());
  return files;
}

TEST(Cli, KilledRunResumesToTheUninterruptedResult) {
  // Two trials with creep and fatigue (history-dependent, adaptive time steps). The interrupted
  // run dies abruptly after its k-th checkpoint (as if killed: no clean-up, exit 137); resuming
  // must give the uninterrupted run's outputs. All physical-time controls: the error controls
  // carries its last step across checkpoints (a checkpoint inside a hold, between report times).
  // Two ramps per trial and a time_tol that rejects a whole ramp: the first ramp's start is
  // remembered for the second (engine/quasi_static.cpp), and the cut falls between the two.
  //
  // Issue 30 item 1: EVERY output, the VTU fields included, to the byte, whatever the segment the
  // checkpoint precedes: a hold (k = 3), a ramp (k = 5), the release into trial 2 (k = 8), the rest
  // after it (k = 9). Before 2026-11-28 the VTU fields after a resume differed by 1e-13-1e-9: from
  // k = 8 because the resumed solver had forgotten that it had reached an equilibrium and did not
  // try the direct release (StaticSolver::set_path), and from k = 3 (and 9) because the
  // factorisation that preconditions the Krylov steps at constant pressure was not in the
  // checkpoint; every segment now starts without it (StaticSolver::forget_factor, engine/quasi_static.h).
  for (const std::string control : {"change", "error", "drive"}) {
    SCOPED_TRACE(control);
    const std::string fx = kTiny + " --set load.trials=2 --set materials.silicone.viscoelastic.enabled=true"
                           " --set materials.silicone.fatigue.enabled=true --set materials.silicone.fatigue.W_th_MPa=0.001"
                           " --set materials.silicone.fatigue.tau_s=200.0 --set output.vtu=\\\"steps\\\""
                           " --set solver.time_control=\\\"" + control + "\\\"" +
                           " --set load.max_kPa=10.0 --set solver.time_tol=0.004";
    const fs::path full = fresh_dir("full_" + control);
    const Result a = run("simulate --out " + full.string() + " " + fx);
    ASSERT_EQ(a.code, 0) << a.out;
    EXPECT_NE(slurp(full / "metrics.json").find("\"trial\": 2"), std::string::npos);
    const std::vector<std::string> files = output_files(full);
    ASSERT_GT(files.size(), 6u);
    for (int k : {3, 5, 8, 9}) {
      SCOPED_TRACE("killed after checkpoint " + std::to_string(k));
      const fs::path cut = fresh_dir("cut_" + control + std::to_string(k));
      const Result b = run("simulate --out " + cut.string() + " " + fx + " --checkpoint-every 0 --abort-after-checkpoints " +
                           std::to_string(k));
      ASSERT_EQ(b.code, 137) << b.out;
      ASSERT_TRUE(fs::exists(cut / "checkpoint.bin"));
      EXPECT_FALSE(fs::exists(cut / "summary.json"));  // the killed run never finished
      const Result c = run("simulate --resume " + cut.string());
      ASSERT_EQ(c.code, 0) << c.out;
      EXPECT_EQ(output_files(cut), files);
      for (const std::string& f : files)
        EXPECT_TRUE(slurp(cut / f) == slurp(full / f)) << f << " differs from the uninterrupted run's";
    }
  }
}

// Issue 30 item 6: selective mass scaling cannot silently change the answer. Before, explicit mode
// with solver.target_dt_s = 1e-5 added 1039 times this actuator's mass without a word, and its
// angle at the end of the hold came out 12 % below the same run's with 35 % added mass. Now the
// added mass is in the console and summary.json, a warning says it is over 5 %, and the run is
// refused (exit 2, its reports so far and the solver statistics kept) at the first report where
// the added mass takes more than 2 % of the loads (here 12.5 %) — unless forced.
TEST(Cli, ExplicitMassScalingIsReportedAndRefusedWhereItChangesTheAnswer) {
  const std::string ex = kTiny + " --set solver.mode=\\\"explicit\\\" --set solver.time_scale=1000"
                         " --set solver.adaptive_damping=true --set solver.target_dt_s=1e-5";
  const fs::path d = fresh_dir("mass_scaled");
  Result r = run("simulate --out " + d.string() + " " + ex);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("selective mass scaling (solver.target_dt_s = 1e-05 s) adds 4.413 kg to the model's 0.004246 kg "
                       "(1039 times it)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("warning: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("that mass takes 12.5 % of the loads (limit 2 %)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("solver.force_mass_scaling = true runs it anyway"), std::string::npos) << r.out;
  std::string summary = slurp(d / "summary.json");
  EXPECT_NE(summary.find("\"status\": \"solver.target_dt_s = 1e-05: selective mass scaling added"), std::string::npos) << summary;
  for (const char* key : {"\"steps\"", "\"added_mass_kg\"", "\"added_mass_fraction\"", "\"added_mass_max_force_share\""})
    EXPECT_NE(summary.find(key), std::string::npos) << key << summary;
  const std::string angles = slurp(d / "angles.csv");
  EXPECT_EQ(std::count(angles.begin(), angles.end(), '\n'), 3) << angles;  // the two unloaded reports before it
  // Forced: it runs, with the warning in the console and in summary.json.
  r = run("simulate --out " + d.string() + " " + ex + " --set solver.force_mass_scaling=true");
  EXPECT_EQ(r.code, 0) << r.out;
  summary = slurp(d / "summary.json");
  EXPECT_NE(summary.find("\"mass_scaling_forced\": true"), std::string::npos) << summary;
  EXPECT_NE(summary.find("more than 5 %"), std::string::npos) << summary;
  EXPECT_NE(r.out.find("added 4.413 kg to the model's 0.004246 kg"), std::string::npos) << r.out;
}

// Issue 30 item 6: a failed run's summary.json keeps the full solver statistics of what ran.
// Before, it kept only "states": a run that stalls in its third load segment (a creeping silicone,
// a time_tol that needs more than 5 steps per hold) said nothing of the Newton iterations,
// factorisations and rejected steps it had spent.
TEST(Cli, AFailedRunKeepsItsSolverStatistics) {
  const fs::path d = fresh_dir("failed_stats");
  const Result r = run("simulate --out " + d.string() + " " + kTiny +
                       " --set load.max_kPa=10.0 --set materials.silicone.viscoelastic.enabled=true"
                       " --set solver.time_tol=0.001 --set solver.max_segment_steps=5");
  EXPECT_EQ(r.code, 3) << r.out;
  const std::string summary = slurp(d / "summary.json");
  EXPECT_NE(summary.find("\"status\": \"physical time stepping stalled"), std::string::npos) << summary;
  for (const char* key : {"\"states\": ", "\"rejected_time_steps\": ", "\"newton_iterations\": ", "\"factorizations\": ",
                          "\"increments\": "}) {
    const std::size_t at = summary.find(key);
    ASSERT_NE(at, std::string::npos) << key << summary;
    EXPECT_NE(summary[at + std::string(key).size()], '0') << key << " of what ran is not zero: " << summary;
  }
}

// Issue 30 item 1: a resume never mixes two runs. Before, a changed scene killed before its first
// checkpoint resumed from the old run's checkpoint and exited 0 with a mixed result; a flipped bit
// resumed silently; a directory without a checkpoint said only "no checkpoint.bin there".
TEST(Cli, ResumeNeverMixesRuns) {
  const fs::path a = fresh_dir("mix_a"), b = fresh_dir("mix_b");
  const std::string kill = " --checkpoint-every 0 --abort-after-checkpoints 1";
  ASSERT_EQ(run("simulate --out " + a.string() + " " + kTiny + kill).code, 137);
  ASSERT_EQ(run("simulate --out " + b.string() + " " + kTiny + " --set load.hold_s=12.0" + kill).code, 137);
  const std::string checkpoint = slurp(a / "checkpoint.bin"), scene = slurp(a / "scene.toml");
  auto write = [](const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; };

  // A flipped bit anywhere (here: in the middle of the state) is an error, not a silent resume.
  std::string flipped = checkpoint;
  flipped[flipped.size() / 2] ^= 0x10;
  write(a / "checkpoint.bin", flipped);
  Result r = run("simulate --resume " + a.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("damaged (its checksum does not match"), std::string::npos) << r.out;
  write(a / "checkpoint.bin", checkpoint);

  // Another run's scene.toml beside the checkpoint (what a changed scene killed before its first
  // checkpoint left behind before a fresh run removed old checkpoints): refused, naming the scene.
  write(a / "scene.toml", slurp(b / "scene.toml"));
  r = run("simulate --resume " + a.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("belongs to another run: its scene differs"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("run it again: pneufem simulate " + a.string() + "/scene.toml"), std::string::npos) << r.out;
  write(a / "scene.toml", scene);
  r = run("simulate --resume " + a.string());  // its own scene: resumes
  EXPECT_EQ(r.code, 0) << r.out;

  // A fresh run into a directory with an old checkpoint removes it, with a note; its own run here
  // ends before any checkpoint, so there is then nothing to resume.
  write(b / "checkpoint.bin", checkpoint);
  r = run("simulate --out " + b.string() + " " + kTiny + " --checkpoint-every 1e6");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("note: removed checkpoint.bin of an earlier run"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(b / "checkpoint.bin"));
  r = run("simulate --resume " + b.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("nothing to resume"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("run it again"), std::string::npos) << r.out;
}

// diagnose --cache on the command line: the second run reads the elastic path the first stored and
// writes the same diagnosis; a cache directory that cannot be made is bad input (exit 2, nothing
// written). (The cache itself: tests/app/simulate/test_result_cache.cpp, DiagnoseCache in
// tests/app/diagnose/test_command.cpp.)
TEST(Cli, DiagnoseReadsItsCacheOnTheSecondRun) {
  const std::string data = std::string(PNEUFEM_TEST_DATA_DIR) + "/hidden/stiffness.csv";
  const std::string args = " --set geometry.chambers=5 --set mesh.h_mm=6.0 --set load.max_kPa=30.0 --set load.step_kPa=10.0"
                           " --set load.hold_s=4.0 --set load.trials=3 --candidates stiffness --max-effects 1"
                           " --evaluations 5 --progress --threads 2";
  const fs::path d = fresh_dir("diag_cache");
  const Result bad = run("diagnose --data " + data + " --out " + (d / "bad").string() + args + " --cache /dev/null/cache");
  EXPECT_EQ(bad.code, 2) << bad.out;
  EXPECT_NE(bad.out.find("--cache /dev/null/cache"), std::string::npos) << bad.out;
  EXPECT_FALSE(fs::exists(d / "bad" / "diagnosis.json"));
  const std::string cache = (d / "cache").string();
  const Result a = run("diagnose --data " + data + " --out " + (d / "a").string() + args + " --cache " + cache);
  ASSERT_EQ(a.code, 0) << a.out;
  EXPECT_NE(a.out.find("path computed"), std::string::npos) << a.out;
  const Result b = run("diagnose --data " + data + " --out " + (d / "b").string() + args + " --cache " + cache);
  ASSERT_EQ(b.code, 0) << b.out;
  EXPECT_NE(b.out.find("path cache " + cache), std::string::npos) << b.out;
  EXPECT_EQ(slurp(d / "a" / "diagnosis.csv"), slurp(d / "b" / "diagnosis.csv"));
  EXPECT_EQ(slurp(d / "a" / "fitted.toml"), slurp(d / "b" / "fitted.toml"));
}

// compare, diagnose, synth, sweep (and simulate) check --out before computing (issue 30, item 3):
// an --out that is a regular file, or lies under one, fails at once with exit code 2 and names
// the path and the cause. Each command is given a run that would take tens of seconds, so an
// answer within seconds, without a progress line, shows nothing was computed first.
TEST(Cli, UnwritableOutFailsBeforeAnyWork) {
  const fs::path d = fresh_dir("bad_out");
  fs::create_directories(d);
  const fs::path file = d / "a_file.csv";
  std::ofstream(file) << "not a directory\n";
  const std::string data = std::string(PNEUFEM_TEST_DATA_DIR) + "/hidden/stiffness.csv";
  const std::string scene = " --set geometry.chambers=5 --set mesh.h_mm=6.0 --set load.max_kPa=30.0 --set load.step_kPa=10.0"
                            " --set load.hold_s=4.0 --set load.trials=3";
  struct Case {
    std::string command;  // everything but --out
    bool out_is_file;     // synth writes a file: --out a_file.csv is valid there
  };
  const Case cases[] = {
      {"compare --data " + data + scene + " --threads 2", false},
      {"diagnose --data " + data + scene + " --threads 2 --candidates stiffness --max-effects 1 --progress", false},
      {"synth --hidden stiffness" + scene + " --threads 2", true},
      {"sweep --param load.max_kPa=10:30:3 --jobs 1 --threads-per-job 2" + scene, false},
      {"simulate" + scene + " --threads 2", false},
  };
  for (const Case& c : cases) {
    std::vector<std::pair<std::string, std::string>> outs = {{(file / "sub").string(), "is a file, not a directory"}};
    if (!c.out_is_file) outs.push_back({file.string(), "is a file, not a directory"});
    else outs.push_back({(file / "sub" / "data.csv").string(), "is a file, not a directory"});
    for (const auto& [out, cause] : outs) {
      const auto t0 = std::chrono::steady_clock::now();
      const Result r = run(c.command + " --out " + out);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      EXPECT_EQ(r.code, 2) << c.command << "\n" << r.out;
      EXPECT_NE(r.out.find("--out " + out + ": "), std::string::npos) << r.out;
      EXPECT_NE(r.out.find(cause), std::string::npos) << r.out;
      EXPECT_EQ(r.out.find("tracing the elastic path"), std::string::npos) << r.out;  // diagnose's first progress line
      EXPECT_LT(seconds, 10.0) << c.command;
    }
  }
  EXPECT_EQ(slurp(file), "not a directory\n");
}

TEST(Cli, MeshExportsARunnableCalculixDeck) {
  const fs::path f = fs::temp_directory_path() / "pneufem_cli_mesh.inp";
  const Result r = run("mesh --out " + f.string() + " " + kTiny);
  ASSERT_EQ(r.code, 0) << r.out;
  const std::string deck = slurp(f);
  for (const char* k : {"*NODE", "*ELEMENT, TYPE=C3D10", "*HYPERELASTIC, YEOH", "*ELASTIC", "*BOUNDARY", "*DLOAD",
                        "*STEP, NLGEOM", "*NSET, NSET=PNEUFEM_TIP"})
    EXPECT_NE(deck.find(k), std::string::npos) << k;
}

}  // namespace

// The pieces of `sweep --scheduler slurm` that need no cluster (app/sweep/slurm.h): the --array
// value, shell quoting, the sbatch options' checks and the array script. The scheduler itself is
// tested against a real SLURM by test_slurm.sh.
#include "app/sweep/slurm.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/errors.h"

namespace {

using namespace pneufem;

TEST(SlurmArray, SpecJoinsConsecutivePointsIntoRanges) {
  EXPECT_EQ(array_spec({1, 2, 3, 4}, 0), "1-4");
  EXPECT_EQ(array_spec({1, 4}, 1), "1,4%1");
  EXPECT_EQ(array_spec({2, 3, 5, 7, 8, 9}, 4), "2-3,5,7-9%4");
  EXPECT_EQ(array_spec({7}, 0), "7");
}

TEST(SlurmArray, ShellQuotingSurvivesBash) {
  // Each word through bash's own parser: printf prints it back unchanged.
  for (const std::string w : {"plain", "with space", "it's", "solver.model=\"full\"", "$HOME `x` \\ ;|&", ""}) {
    const std::filesystem::path f = std::filesystem::temp_directory_path() / "pneufem_quote.sh";
    std::ofstream(f) << "printf '%s' " << shell_quote(w) << "\n";
    FILE* p = popen(("bash " + f.string()).c_str(), "r");
    std::string out;
    char buf[256];
    while (p && fgets(buf, sizeof buf, p)) out += buf;
    ASSERT_EQ(pclose(p), 0) << w;
    EXPECT_EQ(out, w);
    std::filesystem::remove(f);
  }
}

TEST(SlurmArray, OptionsInSlurmsFormsOnly) {
  SlurmOptions ok;
  ok.partition = "short,long";
  ok.account = "lab-1";
  for (const char* t : {"30", "30:00", "2:00:00", "1-12", "1-12:30", "1-12:30:00"}) {
    ok.time = t;
    ok.mem = "4G";
    EXPECT_NO_THROW(check_slurm_options(ok)) << t;
  }
  const auto refused = [](SlurmOptions s, const std::string& fragment) {
    try {
      check_slurm_options(s);
      ADD_FAILURE() << "accepted: " << fragment;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  SlurmOptions s;
  s.time = "2h";
  refused(s, "--time '2h'");
  s.time = "1:2:3:4";
  refused(s, "--time '1:2:3:4'");
  s.time = "";
  s.mem = "G4";
  refused(s, "--mem 'G4'");
  s.mem = "";
  s.partition = "a\n#SBATCH --x";
  refused(s, "--partition");
  s.partition = "";
  s.account = "a b";
  refused(s, "--account 'a b'");
}

TEST(SlurmArray, ScriptSelectsThePointByTaskIdAndRunsItsCommand) {
  SweepArray a;
  a.job_name = "pneufem-sweep-t";
  a.points = {2, 5};
  a.values = {{"1.0", "3"}, {"2.5", "4"}};
  a.keys = {"a.x", "b.n"};
  a.command = {"/bin/echo", "simulate", "--out", kDirWord, kPointWord, "--set", "solver.model=\"full\""};
  const std::filesystem::path d = std::filesystem::temp_directory_path() / "pneufem_slurm_script";
  std::filesystem::remove_all(d);
  a.points_dir = (d / "points").string();
  a.log_dir = (d / "slurm").string();
  const std::string script = slurm_array_script(a, SlurmOptions{});
  EXPECT_NE(script.find("#SBATCH --array=2,5\n"), std::string::npos) << script;
  // Run the script as task 5 would: the point's directory is made and its command gets its values.
  std::filesystem::create_directories(d);
  std::ofstream(d / "job.sh") << script;
  ASSERT_EQ(std::system(("SLURM_ARRAY_TASK_ID=5 bash " + (d / "job.sh").string()).c_str()), 0);
  std::ifstream log(d / "points" / "0005" / "log.txt");
  std::string line;
  std::getline(log, line);
  EXPECT_EQ(line, "simulate --out " + (d / "points" / "0005").string() + " --set a.x=2.5 --set b.n=4 --set solver.model=\"full\"");
  // A task id the array does not have is an error, not some other point.
  EXPECT_NE(std::system(("SLURM_ARRAY_TASK_ID=3 bash " + (d / "job.sh").string() + " 2>/dev/null").c_str()), 0);
  EXPECT_FALSE(std::filesystem::exists(d / "points" / "0003"));
  std::filesystem::remove_all(d);
}

}  // namespace

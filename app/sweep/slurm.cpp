#include "app/sweep/slurm.h"

#include <pwd.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "core/errors.h"

namespace pneufem {

namespace {

/// Runs `argv` (found on PATH), returns its stdout and stderr together; `exit_code` gets its exit
/// code, 127 when it could not be started.
std::string capture(const std::vector<std::string>& argv, int& exit_code) {
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("sweep: cannot create a pipe: " + std::string(strerror(errno)));
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("sweep: cannot start " + argv[0] + " (fork failed): " + strerror(errno));
  if (pid == 0) {
    dup2(fds[1], STDOUT_FILENO);
    dup2(fds[1], STDERR_FILENO);
    close(fds[0]);
    close(fds[1]);
    execvp(args[0], args.data());
    _exit(127);
  }
  close(fds[1]);
  std::string out;
  char buf[4096];
  for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) != 0;) {
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) break;
    out.append(buf, static_cast<std::size_t>(n));
  }
  close(fds[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  return out;
}

std::string trimmed(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  std::size_t b = 0;
  while (b < s.size() && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  return s.substr(b);
}

bool all_of_chars(const std::string& s, const char* allowed_punct) {
  return std::all_of(s.begin(), s.end(), [&](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || std::strchr(allowed_punct, c) != nullptr;
  });
}

}  // namespace

void check_slurm_options(const SlurmOptions& s) {
  // Names: what SLURM allows in partition and account names, and nothing a script line could misread.
  if (!all_of_chars(s.partition, "_-.,"))
    throw InputError("--partition '" + s.partition + "': a partition name (letters, digits, _ - . and , between names)");
  if (!all_of_chars(s.account, "_-."))
    throw InputError("--account '" + s.account + "': an account name (letters, digits, _ - .)");
  // --time: minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM or D-HH:MM:SS (sbatch(1)).
  if (!s.time.empty()) {
    const bool digits_and_seps = all_of_chars(s.time, ":-") &&
                                 std::none_of(s.time.begin(), s.time.end(), [](char c) { return std::isalpha(static_cast<unsigned char>(c)); });
    const auto colons = std::count(s.time.begin(), s.time.end(), ':');
    const auto dashes = std::count(s.time.begin(), s.time.end(), '-');
    if (!digits_and_seps || colons > 2 || dashes > 1 || s.time.front() == ':' || s.time.front() == '-' ||
        s.time.back() == ':' || s.time.back() == '-' || s.time.find("::") != std::string::npos)
      throw InputError("--time '" + s.time + "': SLURM's form is MINUTES, HH:MM:SS or D-HH:MM:SS, e.g. --time 2:00:00");
  }
  // --mem: a whole number with an optional unit K, M, G or T (sbatch(1); megabytes without one).
  if (!s.mem.empty()) {
    std::size_t digits = 0;
    while (digits < s.mem.size() && std::isdigit(static_cast<unsigned char>(s.mem[digits]))) ++digits;
    const std::string unit = s.mem.substr(digits);
    if (digits == 0 || !(unit.empty() || (unit.size() == 1 && std::strchr("KMGTkmgt", unit[0]))))
      throw InputError("--mem '" + s.mem + "': memory per task as a number with an optional unit K, M, G or T, e.g. --mem 4G");
  }
  if (s.max_parallel < 0) throw InputError("--max-parallel " + std::to_string(s.max_parallel) + ": must be at least 1");
}

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string array_spec(const std::vector<int>& points, int max_parallel) {
  std::string s;
  for (std::size_t i = 0; i < points.size();) {
    std::size_t j = i;
    while (j + 1 < points.size() && points[j + 1] == points[j] + 1) ++j;
    if (!s.empty()) s += ',';
    s += std::to_string(points[i]);
    if (j > i) {
      s += '-';
      s += std::to_string(points[j]);
    }
    i = j + 1;
  }
  if (max_parallel > 0) {
    s += '%';
    s += std::to_string(max_parallel);
  }
  return s;
}

std::string slurm_array_script(const SweepArray& a, const SlurmOptions& s) {
  std::ostringstream o;
  o << "#!/bin/bash\n" << a.header;
  o << "#SBATCH --job-name=" << a.job_name << "\n";
  o << "#SBATCH --array=" << array_spec(a.points, s.max_parallel) << "\n";
  o << "#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=" << a.cpus_per_task << "\n";
  o << "#SBATCH --output=" << a.log_dir << "/%A_%a.out\n";
  if (!s.partition.empty()) o << "#SBATCH --partition=" << s.partition << "\n";
  if (!s.time.empty()) o << "#SBATCH --time=" << s.time << "\n";
  if (!s.mem.empty()) o << "#SBATCH --mem=" << s.mem << "\n";
  if (!s.account.empty()) o << "#SBATCH --account=" << s.account << "\n";
  if (!a.dependency.empty()) o << "#SBATCH --dependency=afterany:" << a.dependency << "\n";
  o << "set -u\n";
  o << "# The task id is the point number; its values, in the order of keys:\n";
  o << "keys=(";
  for (std::size_t j = 0; j < a.keys.size(); ++j) o << (j ? " " : "") << shell_quote(a.keys[j]);
  o << ")\ncase \"$SLURM_ARRAY_TASK_ID\" in\n";
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    o << "  " << a.points[i] << ") values=(";
    for (std::size_t j = 0; j < a.values[i].size(); ++j) o << (j ? " " : "") << shell_quote(a.values[i][j]);
    o << ") ;;\n";
  }
  o << "  *) echo \"pneufem sweep: this array has no point $SLURM_ARRAY_TASK_ID\" >&2; exit 2 ;;\nesac\n";
  o << "sets=()\nfor j in \"${!keys[@]}\"; do sets+=(--set \"${keys[j]}=${values[j]}\"); done\n";
  o << "dir=" << shell_quote(a.points_dir) << "/$(printf '%04d' \"$SLURM_ARRAY_TASK_ID\")\n";
  o << "# A failed, cancelled or changed point starts clean, as in a local sweep.\n";
  o << "rm -rf \"$dir\" && mkdir -p \"$dir\" || exit 1\n";
  o << "exec";
  for (const std::string& w : a.command) {
    if (w == kDirWord) o << " \"$dir\"";
    else if (w == kPointWord) o << " \"${sets[@]}\"";
    else o << " " << shell_quote(w);
  }
  o << " > \"$dir/log.txt\" 2>&1\n";
  return o.str();
}

std::string sbatch_submit(const std::string& script_path) {
  int code = 0;
  const std::string out = trimmed(capture({"sbatch", "--parsable", script_path}, code));
  if (code == 127)
    throw std::runtime_error("--scheduler slurm: cannot run sbatch (is SLURM's client installed and on PATH? Debian: slurm-client)");
  if (code != 0) throw std::runtime_error("--scheduler slurm: sbatch refused " + script_path + ": " + out);
  // --parsable prints "jobid" or "jobid;cluster", after any warnings on their own lines.
  std::string id = out.substr(out.find_last_of('\n') == std::string::npos ? 0 : out.find_last_of('\n') + 1);
  id = id.substr(0, id.find(';'));
  if (id.empty() || !all_of_chars(id, ""))
    throw std::runtime_error("--scheduler slurm: sbatch did not print a job id: " + out);
  return id;
}

std::set<int> active_array_tasks(const std::vector<std::string>& job_ids) {
  std::set<int> active;
  if (job_ids.empty()) return active;
  // The user's jobs, one line per array task (-r), as "ARRAY_JOB_ID TASK_ID": jobs SLURM has
  // forgotten are simply absent (squeue --jobs would fail on them).
  const passwd* pw = getpwuid(getuid());
  std::vector<std::string> argv = {"squeue", "--noheader", "--array", "--format=%F %K"};
  if (pw) argv.push_back(std::string("--user=") + pw->pw_name);
  int code = 0;
  const std::string out = capture(argv, code);
  if (code == 127)
    throw std::runtime_error("--scheduler slurm: cannot run squeue (is SLURM's client installed and on PATH? Debian: slurm-client)");
  if (code != 0)
    throw std::runtime_error("--scheduler slurm: squeue failed, so which points still run is unknown and nothing was "
                             "resubmitted; try again when the scheduler answers: " + trimmed(out));
  std::istringstream in(out);
  for (std::string job, task; in >> job >> task;) {
    if (std::find(job_ids.begin(), job_ids.end(), job) == job_ids.end()) continue;
    // A pending array's tasks may still be listed as a range ("3-5%2", "1,4"): expand it.
    std::istringstream ranges(task.substr(0, task.find('%')));
    for (std::string r; std::getline(ranges, r, ',');) {
      const std::size_t dash = r.find('-');
      try {
        const int lo = std::stoi(r.substr(0, dash)), hi = dash == std::string::npos ? lo : std::stoi(r.substr(dash + 1));
        for (int t = lo; t <= hi; ++t) active.insert(t);
      } catch (const std::exception&) {  // "N/A": not an array task
      }
    }
  }
  return active;
}

long max_array_size() {
  int code = 0;
  const std::string out = capture({"scontrol", "show", "config"}, code);
  if (code != 0) return 0;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("MaxArraySize", 0) != 0) continue;
    const std::size_t eq = line.find('=');
    try {
      return eq == std::string::npos ? 0 : std::stol(line.substr(eq + 1));
    } catch (const std::exception&) {
      return 0;
    }
  }
  return 0;
}

}  // namespace pneufem

// pneufem._core: the C++ side of the Python package (python/pneufem/). Two things live here:
//
//  * scene resolution: a scene file plus "key=value" overrides into the resolved scene (JSON and
//    TOML text), checked as the commands check it (the settings readers and every material), so a
//    bad key or value is an InputError with the CLI's message the moment it is set;
//  * run_command: one pneufem command (the CLI's argument list) run in a forked child process of
//    the Python interpreter. The child parses the arguments with the CLI's own option definitions
//    (app/<command>/cli.h: the same options, checks and messages) and calls the command's run
//    function in-process (no exec, no binary needed except the sweep's worker processes). The
//    parent waits with the GIL released, forwards the child's output to Python's sys.stdout/stderr
//    when asked (Jupyter), and on Ctrl-C (SIGINT: Python's handler sets a flag that the wait loop
//    checks every 50 ms) interrupts the child's process group. The child then dies exactly as the
//    CLI dies on Ctrl-C (the default SIGINT action; the CLI installs no handler): every output is
//    written atomically (core/atomic_file.h), so nothing is half-written, and a simulate run keeps
//    its checkpoint for --resume.
//
// Why a child process: the engine has no cancellation hook, and a solve cannot be stopped inside
// the interpreter's process without one; the child also keeps TBB's thread pool and any fatal
// error out of the interpreter (a Jupyter kernel survives a crash of the run). The parent never
// starts TBB itself (the scene readers do not use it), so fork is safe for the children.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "app/compare/cli.h"
#include "app/diagnose/cli.h"
#include "app/fit_material/cli.h"
#include "app/simulate/cli.h"
#include "app/sweep/cli.h"
#include "app/synth/cli.h"
#include "core/errors.h"
#include "core/version.h"
#include "scenes/build_model.h"
#include "scenes/key_limits.h"
#include "scenes/scene.h"
#include "scenes/scene_settings.h"

namespace py = pybind11;
using namespace pneufem;

namespace {

/// Which error ended a command (the tiers of core/errors.h plus a parse error of the options).
enum class Outcome { Ok = 0, Input = 1, Physics = 2, Other = 3 };

/// Whether the default scene holds `key` as an integer (the commands read it with Scene::integer).
bool integer_key(const std::string& key) {
  static const Scene defaults = Scene::load("");
  if (!defaults.has(key)) return false;
  try {
    (void)defaults.integer(key);
    return true;
  } catch (const InputError&) {
    return false;
  }
}

/// Scene file + overrides, resolved and checked as every command reads it.
Scene checked_scene(const std::string& path, const std::vector<std::string>& sets) {
  Scene scene = Scene::load(path, sets);
  for (const std::string& set : sets) {  // each overridden number against its declared range
    const std::string key = set.substr(0, set.find('='));
    if (find_key_limit(key) == nullptr || !scene.has(key)) continue;
    if (integer_key(key)) {  // read as the commands read it, so the message is theirs
      (void)scene.integer(key);
      continue;
    }
    try {
      (void)scene.number(key);
    } catch (const InputError& as_number) {
      try {
        (void)scene.numbers(key);  // a list: each element in the range
      } catch (const InputError& as_list) {
        if (std::string(as_list.what()).find("expected an array") != std::string::npos) throw as_number;
        throw;
      }
    }
  }
  (void)mesh_settings(scene);
  (void)load_settings(scene);
  (void)solver_settings(scene);
  (void)output_settings(scene);
  (void)inlet_load(scene);  // the protocol: trials, levels, their limits
  for (const std::string& m : scene.table_keys("materials")) (void)make_material(scene, m);
  return scene;
}

std::string join(const std::vector<std::string>& args) {
  std::string s = "pneufem";
  for (const std::string& a : args) s += " " + (a.find_first_of(" \"'") == std::string::npos ? a : "'" + a + "'");
  return s;
}

/// app/main.cpp's dispatch, in the child: the exit code, and the error's tier and message.
int run_in_child(const std::vector<std::string>& args, const std::string& exe, Outcome& outcome, std::string& message) {
  CLI::App app{"pneufem"};
  app.require_subcommand(1);
  std::unique_ptr<SimulateCommand> sim = add_simulate_command(app);
  std::unique_ptr<MeshCommand> mesh = add_mesh_command(app);
  std::unique_ptr<SceneCommand> sc = add_scene_command(app);
  std::unique_ptr<SweepCommand> sw = add_sweep_command(app);
  std::unique_ptr<SynthCommand> sy = add_synth_command(app);
  std::unique_ptr<CompareCommand> cmp = add_compare_command(app);
  std::unique_ptr<DiagnoseCommand> dia = add_diagnose_command(app);
  std::unique_ptr<FitMaterialCommand> fm = add_fit_material_command(app);
  std::vector<std::string> argv_s{"pneufem"};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_s) argv.push_back(a.data());
  const std::string command_line = join(args);
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError& e) {
    outcome = Outcome::Input;
    message = e.what();
    return 2;
  }
  try {
    if (sim->cmd->parsed()) return run_simulate_command(*sim, command_line);
    if (cmp->cmd->parsed()) return run_compare_command(*cmp, command_line);
    if (dia->cmd->parsed()) return run_diagnose_command(*dia, command_line);
    if (sw->cmd->parsed()) {
      if (exe.empty()) throw InputError("sweep: the pneufem binary that runs the points was not found; set PNEUFEM_EXE to its path");
      return run_sweep_command(*sw, command_line, exe);
    }
    if (sy->cmd->parsed()) return run_synth_command(*sy, command_line);
    if (mesh->cmd->parsed()) return run_mesh_command(*mesh);
    if (sc->cmd->parsed()) return run_scene_command(*sc);
    if (fm->cmd->parsed()) return run_fit_material_command(*fm);
  } catch (const InputError& e) {
    outcome = Outcome::Input;
    message = e.what();
    return 2;
  } catch (const PhysicsError& e) {
    outcome = Outcome::Physics;
    message = e.what();
    return 3;
  } catch (const std::exception& e) {
    outcome = Outcome::Other;
    message = e.what();
    return 1;
  }
  return 0;
}

void write_all(int fd, const std::string& s) {
  std::size_t done = 0;
  while (done < s.size()) {
    const ssize_t n = write(fd, s.data() + done, s.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    done += static_cast<std::size_t>(n);
  }
}

/// The child after fork: its own process group (the parent forwards Ctrl-C to it), the default
/// SIGINT/SIGTERM actions (as the CLI has), dies with the parent, runs, reports, _exit (no Python
/// or static destructors in the copy of the interpreter).
[[noreturn]] void child_main(const std::vector<std::string>& args, const std::string& exe, pid_t parent, int status_fd,
                             int out_fd, int err_fd) {
  setpgid(0, 0);
  sigset_t none;
  sigemptyset(&none);
  sigprocmask(SIG_SETMASK, &none, nullptr);
  signal(SIGINT, SIG_DFL);
  signal(SIGTERM, SIG_DFL);
  signal(SIGPIPE, SIG_DFL);
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (getppid() != parent) _exit(137);
  if (out_fd >= 0) dup2(out_fd, STDOUT_FILENO);
  if (err_fd >= 0) dup2(err_fd, STDERR_FILENO);
  Outcome outcome = Outcome::Ok;
  std::string message;
  const int rc = run_in_child(args, exe, outcome, message);
  std::cout.flush();
  std::fflush(nullptr);
  write_all(status_fd, std::to_string(static_cast<int>(outcome)) + "\n" + message);
  _exit(rc);
}

struct Pipe {
  int r = -1, w = -1;
  void open() {
    int fd[2];
    if (pipe2(fd, O_CLOEXEC) != 0) throw std::runtime_error(std::string("pneufem: pipe failed: ") + std::strerror(errno));
    r = fd[0];
    w = fd[1];
  }
  void close_r() { if (r >= 0) ::close(r); r = -1; }
  void close_w() { if (w >= 0) ::close(w); w = -1; }
};

/// Interrupts the child's process group (the command and any sweep workers) and reaps it; a child
/// that has not died after 10 s is killed.
int interrupt_and_reap(pid_t pid) {
  kill(-pid, SIGINT);
  int status = 0;
  for (int i = 0; i < 1000; ++i) {
    const pid_t w = waitpid(pid, &status, WNOHANG);
    if (w == pid) return status;
    usleep(10000);
  }
  kill(-pid, SIGKILL);
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return status;
}

/// Runs `args` (a pneufem command line without the program name) in a child. capture: the
/// child's stdout/stderr go through pipes to write_out/write_err (Python callables taking str),
/// else to the interpreter's own file descriptors. Returns (exit code, outcome, message,
/// signal that killed it or 0); KeyboardInterrupt after a Ctrl-C.
py::tuple run_command(const std::vector<std::string>& args, const std::string& exe, bool capture, py::object write_out,
                      py::object write_err) {
  Pipe status, out, err;
  status.open();
  if (capture) {
    out.open();
    err.open();
  }
  std::fflush(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("pneufem: fork failed: ") + std::strerror(errno));
  if (pid == 0) child_main(args, exe, parent, status.w, out.w, err.w);
  setpgid(pid, pid);  // also here: no race with a Ctrl-C right after the fork
  status.close_w();
  out.close_w();
  err.close_w();

  std::string status_text;
  bool interrupted = false;
  int wait_status = 0;
  {
    py::gil_scoped_release nogil;
    std::vector<pollfd> fds{{status.r, POLLIN, 0}};
    if (capture) {
      fds.push_back({out.r, POLLIN, 0});
      fds.push_back({err.r, POLLIN, 0});
    }
    int open_fds = static_cast<int>(fds.size());
    char buf[65536];
    while (open_fds > 0) {
      const int n = poll(fds.data(), fds.size(), 50);
      if (n < 0 && errno != EINTR) break;
      for (std::size_t i = 0; n > 0 && i < fds.size(); ++i) {
        if (fds[i].fd < 0 || !(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
        const ssize_t got = read(fds[i].fd, buf, sizeof buf);
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) {
          fds[i].fd = -1;
          --open_fds;
          continue;
        }
        if (i == 0) {
          status_text.append(buf, static_cast<std::size_t>(got));
        } else {
          py::gil_scoped_acquire gil;
          const py::str text = py::reinterpret_steal<py::str>(PyUnicode_DecodeUTF8(buf, got, "replace"));
          try {
            (i == 1 ? write_out : write_err)(text);
          } catch (py::error_already_set&) {  // a closed stream: the output is lost, the run goes on
          }
        }
      }
      py::gil_scoped_acquire gil;
      if (PyErr_CheckSignals() != 0) {  // Ctrl-C (or another handler raised): stop the child
        interrupted = true;
        break;
      }
    }
    if (interrupted) {
      wait_status = interrupt_and_reap(pid);
    } else {
      while (waitpid(pid, &wait_status, 0) < 0 && errno == EINTR) {
      }
    }
  }
  status.close_r();
  out.close_r();
  err.close_r();
  if (interrupted) throw py::error_already_set();
  int code = 1, outcome = static_cast<int>(Outcome::Other), sig = 0;
  std::string message;
  if (WIFSIGNALED(wait_status)) {
    sig = WTERMSIG(wait_status);
    code = 128 + sig;
  } else if (WIFEXITED(wait_status)) {
    code = WEXITSTATUS(wait_status);
    const std::size_t nl = status_text.find('\n');
    if (nl != std::string::npos) {
      outcome = std::atoi(status_text.substr(0, nl).c_str());
      message = status_text.substr(nl + 1);
    }
  }
  return py::make_tuple(code, outcome, message, sig);
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "pneufem's C++ side: scene resolution and the commands run in a child process (see python/src/module.cpp)";
  py::register_exception<InputError>(m, "InputError", PyExc_ValueError);
  py::register_exception<PhysicsError>(m, "PhysicsError", PyExc_RuntimeError);
  m.attr("build_exe") = PNEUFEM_BUILD_EXE;
  m.attr("exe_from_package") = PNEUFEM_EXE_FROM_PACKAGE;
  m.def("version", &version_string, "The version string every output records");
  m.def("default_scene_text", &Scene::default_text, "The built-in default scene (TOML, with comments)");
  m.def(
      "resolve_scene",
      [](const std::string& path, const std::vector<std::string>& sets) {
        const Scene scene = checked_scene(path, sets);
        return py::make_tuple(scene.to_json(), scene.to_toml());
      },
      py::arg("path"), py::arg("sets"),
      "The resolved scene (JSON text, TOML text) of a scene file (\"\" = the built-in default) and key=value "
      "overrides; InputError with the CLI's message for a bad file, key or value");
  m.def("run_command", &run_command, py::arg("args"), py::arg("exe"), py::arg("capture"), py::arg("write_out"),
        py::arg("write_err"));
}

"""The commands as Python functions: the CLI's options as keyword arguments, results read back from
the files the command wrote (the same files the CLI leaves, so a run from Python and one from the
shell are interchangeable)."""
import json
import os
import pathlib
import shutil
import sys
import tempfile
import warnings

import numpy as np

from . import _core
from ._scene import Scene, toml_value
from ._vtu import read_vtu

InputError = _core.InputError
PhysicsError = _core.PhysicsError

# Options that the CLI takes as one comma-separated value.
_COMMA_LISTS = {"candidates", "hidden"}


def find_exe():
    """The pneufem binary (a sweep's points run as its worker processes): $PNEUFEM_EXE, else the
    one installed beside this package, else the build tree's, else the PATH's."""
    env = os.environ.get("PNEUFEM_EXE")
    if env:
        return env
    here = os.path.dirname(os.path.abspath(__file__))
    for cand in (os.path.normpath(os.path.join(here, _core.exe_from_package)), _core.build_exe):
        if os.path.isfile(cand) and os.access(cand, os.X_OK):
            return cand
    return shutil.which("pneufem") or ""


def _option_args(options):
    """Keyword arguments as CLI options: threads=2 -> --threads 2, regions=True -> --regions,
    sets={"k": v} or ["k=v"] -> --set k=v ..., lists -> the option repeated (or joined by commas
    where the CLI wants that)."""
    args = []
    for key, value in options.items():
        if value is None or value is False:
            continue
        flag = "--" + key.replace("_", "-")
        if key == "sets":
            items = value.items() if isinstance(value, dict) else None
            for s in ([f"{k}={toml_value(v)}" for k, v in items] if items is not None else list(value)):
                args += ["--set", s]
        elif value is True:
            args.append(flag)
        elif isinstance(value, (list, tuple)):
            if key in _COMMA_LISTS:
                args += [flag, ",".join(str(v) for v in value)]
            else:
                for v in value:
                    args += [flag, os.fspath(v) if isinstance(v, os.PathLike) else str(v)]
        else:
            args += [flag, os.fspath(value) if isinstance(value, os.PathLike) else str(value)]
    return args


def _is_fd(stream, fd):
    try:
        return stream.fileno() == fd
    except Exception:
        return False


def run(args, quiet=False):
    """Runs a pneufem command line (without the program name) in a child process; returns its exit
    code. InputError / PhysicsError / RuntimeError with the CLI's message when it fails;
    KeyboardInterrupt after Ctrl-C (the child is interrupted as the CLI would be). The child's
    output goes to sys.stdout/sys.stderr (through pipes when they are not the process's own, as
    in Jupyter), or nowhere with quiet."""
    for s in (sys.stdout, sys.stderr):
        try:
            s.flush()
        except Exception:
            pass
    capture = quiet or not (_is_fd(sys.stdout, 1) and _is_fd(sys.stderr, 2))
    sink = (lambda text: None) if quiet else None
    code, outcome, message, sig = _core.run_command(
        [str(a) for a in args], find_exe(), capture, sink or (lambda t: sys.stdout.write(t)),
        sink or (lambda t: sys.stderr.write(t)))
    if outcome == 1:
        raise InputError(message)
    if outcome == 2:
        raise PhysicsError(message)
    if outcome == 3:
        raise RuntimeError(message)
    if sig:
        raise RuntimeError(f"pneufem {args[0]}: the run was killed by signal {sig}")
    return code


def _as_scene(scene):
    if scene is None:
        return Scene.defaults()
    if isinstance(scene, Scene):
        return scene
    return Scene.load(scene)


def _out_dir(out, prefix):
    return os.fspath(out) if out is not None else tempfile.mkdtemp(prefix=f"pneufem-{prefix}-")


def read_csv(path):
    """A CSV with a header row as a numpy structured array (integers where a column holds only
    integers, empty cells as NaN)."""
    with open(path) as f:
        header = f.readline().strip().split(",")
        rows = [line.rstrip("\n").split(",") for line in f if line.strip()]
    cols = []
    for j, name in enumerate(header):
        cells = [r[j] if j < len(r) else "" for r in rows]
        try:
            cols.append((name, np.array([int(c) for c in cells], dtype=np.int64)))
            continue
        except ValueError:
            pass
        try:
            cols.append((name, np.array([float(c) if c != "" else np.nan for c in cells], dtype=np.float64)))
        except ValueError:
            cols.append((name, np.array(cells, dtype=object)))
    arr = np.empty(len(rows), dtype=[(n, c.dtype) for n, c in cols])
    for n, c in cols:
        arr[n] = c
    return arr


def _to_pandas(arr):
    try:
        import pandas
    except ImportError as e:
        raise ImportError("to_pandas() needs pandas (Debian: apt-get install python3-pandas); the numpy "
                          "structured array has the same columns") from e
    return pandas.DataFrame({n: arr[n] for n in arr.dtype.names})


def _json(path):
    with open(path) as f:
        return json.load(f)


def _remove_temporaries(out):
    """Removes the "<file>.tmp" of an atomic write that a Ctrl-C cut short (core/atomic_file.h): the
    finished files are whole; only such a temporary can be partial."""
    for d in (pathlib.Path(out), pathlib.Path(out) / "vtu"):
        if d.is_dir():
            for p in d.glob("*.tmp"):
                try:
                    p.unlink()
                except OSError:
                    pass


class StateFields:
    """The fields of one reported state (a VTU of the run): point_data on the mesh's nodes
    (displacement_m (n, 3), nodal means of the stresses), cell_data on its elements
    (cauchy_stress_Pa (m, 3, 3), von_mises_Pa, damage, W_max_J_m3, viscous_strain, ...),
    time_s, trial, pressure_kPa, angle_deg, and the mesh (points (n, 3), connectivity)."""

    def __init__(self, path):
        v = read_vtu(path)
        self.path = pathlib.Path(path)
        self.point_data, self.cell_data, self.field_data = v["point"], v["cell"], v["field"]
        self.points = v["points"]
        self.connectivity, self.offsets, self.cell_types = v["connectivity"], v["offsets"], v["types"]
        self.time_s = float(self.field_data.get("time_s", np.nan))
        self.trial = int(self.field_data.get("trial", 0))
        self.pressure_kPa = float(self.field_data.get("pressure_kPa", np.nan))
        self.angle_deg = float(self.field_data.get("angle_deg", np.nan))

    @property
    def displacement(self):
        return self.point_data["displacement_m"]

    @property
    def stress(self):
        return self.cell_data["cauchy_stress_Pa"]

    @property
    def damage(self):
        return self.cell_data["damage"]

    @property
    def cells(self):
        """Element node lists (m, nodes per element) when all elements have the same node count."""
        sizes = np.diff(np.concatenate([[0], self.offsets]))
        if len(set(sizes.tolist())) != 1:
            raise ValueError("mixed element types: use connectivity and offsets")
        return self.connectivity.reshape(-1, int(sizes[0]))

    def __repr__(self):
        return f"StateFields(trial {self.trial}, t = {self.time_s} s, {len(self.points)} nodes, {len(self.offsets)} cells)"


class SimulationResult:
    """A run directory of `pneufem simulate` (docs/commands.md#outputs-of-simulate) read back:
    angles / states (structured arrays), summary / metrics (dicts), the VTU states' fields."""

    def __init__(self, run_dir):
        self.run_dir = pathlib.Path(run_dir)
        self.summary = _json(self.run_dir / "summary.json")
        self.status = self.summary.get("status")
        self.angles = read_csv(self.run_dir / "angles.csv")
        self.states = read_csv(self.run_dir / "states.csv")
        m = self.run_dir / "metrics.json"
        self.metrics = _json(m) if m.exists() else None

    @property
    def scene(self):
        """The resolved scene of the run (its scene.toml)."""
        return Scene.load(self.run_dir / "scene.toml")

    def to_pandas(self):
        """The angles as a pandas DataFrame (needs pandas)."""
        return _to_pandas(self.angles)

    @property
    def state_files(self):
        """[(time_s, path)] of the VTU states, from results.pvd."""
        pvd = self.run_dir / "results.pvd"
        if not pvd.exists():
            return []
        import xml.etree.ElementTree as ET
        return [(float(e.get("timestep")), self.run_dir / e.get("file")) for e in ET.parse(pvd).iter("DataSet")]

    def fields(self, index=-1):
        """The fields of state `index` of state_files (default: the last) as numpy arrays."""
        files = self.state_files
        if not files:
            raise InputError(f"{self.run_dir}: the run wrote no VTU states (output.vtu = \"none\")")
        return StateFields(files[index][1])

    def __repr__(self):
        return f"SimulationResult({str(self.run_dir)!r}, status {self.status!r}, {len(self.angles)} reports)"


def simulate(scene=None, out=None, threads=None, resume=False, quiet=False, **options):
    """`pneufem simulate`: runs a scene (a Scene, a TOML path, or None for the default) into `out`
    (default: a new temporary directory). Other CLI options as keyword arguments: sets=...,
    checkpoint_every=, ideal_cache=, cache=. resume=True continues a killed or interrupted run in
    `out` from its checkpoint (the scene is then the run's own). PhysicsError carries .result with
    what was solved before the failure."""
    out = _out_dir(out, "run")
    if resume:
        if scene is not None or options.get("sets"):
            raise InputError("--resume continues a run with its own scene.toml; do not give a scene or --set")
        args = ["simulate", "--resume", out]
    else:
        args = ["simulate"] + _as_scene(scene).cli_args() + ["--out", out]
    args += _option_args(dict(threads=threads, **options))
    try:
        run(args, quiet)
    except KeyboardInterrupt:
        _remove_temporaries(out)
        raise
    except PhysicsError as e:
        e.result = SimulationResult(out) if (pathlib.Path(out) / "summary.json").exists() else None
        raise
    return SimulationResult(out)


class CompareResult:
    """`pneufem compare`'s directory: metrics (metrics.json as a dict), table (metrics.csv), and
    the main numbers: nrmse, noise_floor_nrmse, trial_nrmse; report (report.html)."""

    def __init__(self, out):
        self.out = pathlib.Path(out)
        self.metrics = _json(self.out / "metrics.json")
        self.table = read_csv(self.out / "metrics.csv")
        self.nrmse = self.metrics.get("nrmse")
        self.noise_floor_nrmse = self.metrics.get("noise_floor_nrmse")
        self.trial_nrmse = self.metrics.get("trial_nrmse")
        self.report = self.out / "report.html"

    def to_pandas(self):
        return _to_pandas(self.table)

    def __repr__(self):
        return f"CompareResult({str(self.out)!r}, NRMSE {self.nrmse:.4f}, noise floor {self.noise_floor_nrmse:.4f})"


def compare(scene=None, data=None, out=None, threads=None, quiet=False, **options):
    """`pneufem compare`: the scene's model against a recording (data: canonical CSV). Options as
    the CLI's: dlc_map=, regions=True, label=, model="full"|"reduced", cache=, sets=. A model run
    that stops early raises PhysicsError with .result (the frames solved before, compared)."""
    if data is None:
        raise InputError("compare: data= (the recording, canonical CSV) is required")
    out = _out_dir(out, "compare")
    args = ["compare"] + _as_scene(scene).cli_args() + ["--data", os.fspath(data), "--out", out]
    code = run(args + _option_args(dict(threads=threads, **options)), quiet)
    result = CompareResult(out)
    if code == 3:
        err = PhysicsError(result.metrics.get("simulation", {}).get("failure", "the model run stopped early"))
        err.result = result
        raise err
    return result


class DiagnoseResult:
    """`pneufem diagnose`'s directory: diagnosis (diagnosis.json as a dict), the main findings
    (missing_effect, selected, baseline_nrmse, final_nrmse, noise_floor_nrmse), fitted (the
    scene with the selected effects, a Scene), report (report.md), candidates (diagnosis.csv)."""

    def __init__(self, out):
        self.out = pathlib.Path(out)
        self.diagnosis = _json(self.out / "diagnosis.json")
        d = self.diagnosis
        self.missing_effect = d.get("missing_effect") or None
        self.selected = d.get("selected", [])
        self.baseline_nrmse = (d.get("baseline") or {}).get("nrmse")
        self.final_nrmse = d.get("final_nrmse")
        self.noise_floor_nrmse = d.get("noise_floor_nrmse")
        self.candidates = read_csv(self.out / "diagnosis.csv")
        self.report = self.out / "report.md"
        self.fitted_toml = self.out / "fitted.toml"

    @property
    def fitted(self):
        return Scene.load(self.fitted_toml)

    def __repr__(self):
        return (f"DiagnoseResult({str(self.out)!r}, missing effect {self.missing_effect!r}, NRMSE "
                f"{self.baseline_nrmse:.4f} -> {self.final_nrmse:.4f})")


def diagnose(scene=None, data=None, out=None, threads=None, quiet=False, **options):
    """`pneufem diagnose`: which effect the model misses. Options as the CLI's: candidates=[...],
    max_effects=, evaluations=, aic_threshold=, min_removed=, min_static_change=, all_rounds=True,
    trust_elastic_model=True, rom_points=, verify=True, refine=, refine_model=, fem_calibrate=,
    calibration_h=, cache=, progress=True, sets=."""
    if data is None:
        raise InputError("diagnose: data= (the recording, canonical CSV) is required")
    out = _out_dir(out, "diagnose")
    args = ["diagnose"] + _as_scene(scene).cli_args() + ["--data", os.fspath(data), "--out", out]
    run(args + _option_args(dict(threads=threads, **options)), quiet)
    return DiagnoseResult(out)


class SynthResult:
    """`pneufem synth`'s files: data (OUT.csv), truth (OUT.truth.csv) as structured arrays,
    truth_info (OUT.truth.json as a dict), and their paths (csv, truth_csv, truth_json)."""

    def __init__(self, csv):
        self.csv = pathlib.Path(csv)
        stem = str(self.csv)[:-4] if str(self.csv).endswith(".csv") else str(self.csv)
        self.truth_csv = pathlib.Path(stem + ".truth.csv")
        self.truth_json = pathlib.Path(stem + ".truth.json")
        self.data = read_csv(self.csv)
        self.truth = read_csv(self.truth_csv)
        self.truth_info = _json(self.truth_json)

    def to_pandas(self):
        return _to_pandas(self.data)

    def __repr__(self):
        return f"SynthResult({str(self.csv)!r}, {len(self.data)} rows)"


def synth(scene=None, hidden=("none",), out=None, threads=None, quiet=False, **options):
    """`pneufem synth`: a recording with known hidden effects (hidden: names, or "none"). out is
    the CSV to write (default: recording.csv in a new temporary directory). Options as the CLI's:
    seed=, pressure_rate=, angle_rate=, controller_hz=, controller_damping=, pressure_noise=,
    angle_noise=, outliers=, report_every=, inlet_tolerance=, sets=."""
    out = os.fspath(out) if out is not None else os.path.join(_out_dir(None, "synth"), "recording.csv")
    hidden = [hidden] if isinstance(hidden, str) else list(hidden)
    args = ["synth"] + _as_scene(scene).cli_args() + ["--out", out]
    run(args + _option_args(dict(hidden=hidden, threads=threads, **options)), quiet)
    return SynthResult(out)


class SweepResult:
    """`pneufem sweep`'s directory: table (sweep.csv, one row per point), sweep (sweep.json as a
    dict), points (its list of points), ok / failed counts, and the plots (sweep_<key>.svg)."""

    def __init__(self, out):
        self.out = pathlib.Path(out)
        self.sweep = _json(self.out / "sweep.json")
        self.table = read_csv(self.out / "sweep.csv")
        self.points = self.sweep.get("points", [])
        self.ok = sum(1 for p in self.points if p.get("status") == "ok")
        self.failed = sum(1 for p in self.points if p.get("status") == "failed")
        self.plots = sorted(self.out.glob("sweep_*.svg"))

    def point_dir(self, index):
        """The run directory of point `index` (1-based, the table's point column)."""
        return self.out / "points" / f"{index:04d}"

    def point(self, index):
        """Point `index`'s run, read back as a SimulationResult."""
        return SimulationResult(self.point_dir(index))

    def to_pandas(self):
        return _to_pandas(self.table)

    def __repr__(self):
        return f"SweepResult({str(self.out)!r}, {len(self.points)} points, {self.ok} ok, {self.failed} failed)"


def sweep(scene=None, param=(), out=None, jobs=None, quiet=False, **options):
    """`pneufem sweep`: the scene over a grid (param: "KEY=LO:HI:N[:log]" strings) or --lhs N
    samples. Options as the CLI's: lhs=, seed=, jobs=, threads_per_job=, model=, fem_points=[..],
    dry_run=True, sets=. Failed points are in the result (failed, table) and a warning, as the
    CLI's exit code 1; dry_run returns None."""
    out = _out_dir(out, "sweep")
    param = [param] if isinstance(param, str) else list(param)
    args = ["sweep"] + _as_scene(scene).cli_args() + ["--out", out]
    opts = dict(param=param, jobs=jobs, **options)
    try:
        code = run(args + _option_args(opts), quiet)
    except KeyboardInterrupt:
        _remove_temporaries(out)
        raise
    if options.get("dry_run"):
        return None
    result = SweepResult(out)
    if code != 0:
        warnings.warn(f"pneufem sweep: {result.failed} of {len(result.points)} points failed (their errors are in "
                      f"{out}/sweep.csv)", RuntimeWarning, stacklevel=2)
    return result

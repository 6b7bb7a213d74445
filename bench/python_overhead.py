"""The Python call path's overhead against the CLI for one small run (issue 31: <= 5 %).

    PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py [--reps 7] [--threads 1]

A/B in one session, interleaved (A, B, C, A, B, C, ...), so drifts of a shared machine hit all alike:
  A  the CLI:               pneufem simulate SCENE --set ... --out DIR       (a process, as a shell runs it)
  B  the Python call:       pneufem.simulate(scene, out=DIR) in a running interpreter (Jupyter, a script's loop)
  C  a Python process:      python3 -c "import pneufem; pneufem.simulate(...)"  (B + interpreter start + import)
Each repetition writes a fresh directory. Prints the median and minimum wall time of each and the
overheads of B and C against A (medians). The scene: the default pneu-net with 3 chambers on a 4 mm
mesh through the 0 -> 5 kPa staircase, ten trials (~2 s: "one small run").
"""
import argparse
import statistics
import subprocess
import sys
import tempfile
import time

import pneufem

ap = argparse.ArgumentParser()
ap.add_argument("--reps", type=int, default=7)
ap.add_argument("--threads", type=int, default=1)
a = ap.parse_args()

VALUES = {"geometry.chambers": 3, "mesh.h_mm": 4.0, "load.max_kPa": 5.0, "mesh.element": "tet10", "load.trials": 10}
scene = pneufem.Scene.defaults().update(VALUES)
exe = pneufem._commands.find_exe()
sets = [x for k, v in VALUES.items() for x in ("--set", f"{k}={pneufem._scene.toml_value(v)}")]
tmp = tempfile.mkdtemp(prefix="pneufem-bench-")
script = (f"import pneufem; pneufem.simulate(pneufem.Scene.defaults().update({VALUES!r}), out=OUT, "
          f"threads={a.threads}, quiet=True)")


def cli(out):
    subprocess.run([exe, "simulate", *sets, "--out", out, "--threads", str(a.threads)], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def call(out):
    pneufem.simulate(scene, out=out, threads=a.threads, quiet=True)


def process(out):
    subprocess.run([sys.executable, "-c", script.replace("OUT", repr(out))], check=True)


ways = {"A CLI": cli, "B Python call": call, "C Python process": process}
times = {k: [] for k in ways}
call(f"{tmp}/warm")  # page cache, first import
for i in range(a.reps):
    for name, f in ways.items():
        t0 = time.perf_counter()
        f(f"{tmp}/{name[0]}{i}")
        times[name].append(time.perf_counter() - t0)

base = statistics.median(times["A CLI"])
print(f"pneufem {pneufem.__version__}; {a.reps} repetitions, --threads {a.threads}, interleaved")
for name, t in times.items():
    med = statistics.median(t)
    print(f"  {name:18s} median {med:6.3f} s  min {min(t):6.3f} s  overhead vs CLI {100 * (med / base - 1):+5.1f} %")

"""Shared set-up of the binding's tests: the tiny scene every run uses (seconds), the CLI binary
the results are checked against, and the recording made once for compare/diagnose."""
import os
import subprocess

import pytest

import pneufem

# A 2-chamber actuator on the coarse 6 mm mesh through 0 -> 5 kPa (tests/app/test_cli.cpp's kTiny):
# ~0.2 s a run.
TINY = {"geometry.chambers": 2, "mesh.h_mm": 6.0, "load.max_kPa": 5.0, "mesh.element": "tet10"}
# The same through two trials with 5 s holds: the recording of compare/diagnose (synth with hidden
# creep, nearly noise-free so that 0.17 deg of bending carries the creep's signal), seconds each.
SMALL = dict(TINY, **{"load.trials": 2, "load.hold_s": 5.0})
SYNTH_OPTIONS = dict(seed=3, angle_noise=0.002, outliers=0, report_every=0.5)


def scene_of(values):
    return pneufem.Scene.defaults().update(values)


def cli_sets(values):
    args = []
    for k, v in values.items():
        args += ["--set", f"{k}={pneufem._scene.toml_value(v)}"]
    return args


@pytest.fixture(scope="session")
def exe():
    return pneufem._commands.find_exe()


def run_cli(exe, *args, check=True):
    r = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"pneufem {' '.join(map(str, args))} failed ({r.returncode}): {r.stderr}")
    return r


@pytest.fixture(scope="session")
def recording(tmp_path_factory):
    """A synthetic recording of SMALL with hidden viscoelasticity (pneufem.synth)."""
    out = tmp_path_factory.mktemp("rec") / "creep.csv"
    return pneufem.synth(scene_of(SMALL), hidden="viscoelastic", out=out, threads=2, quiet=True, **SYNTH_OPTIONS)

"""pneufem from Python: scenes as dicts, and the commands as functions returning Python objects.

    import pneufem
    scene = pneufem.Scene.defaults().set("load.trials", 2)
    run = pneufem.simulate(scene, out="out/run", threads=2)
    run.angles            # numpy structured array: trial, time_s, pressure_kPa, angle_deg
    run.fields(-1)        # displacement, stresses, damage, ... of the last state as numpy arrays

Every command runs the CLI's own code (same options, checks and messages) in a child process of
the interpreter: the GIL is released while it runs, Ctrl-C stops it (KeyboardInterrupt) the way it
stops the CLI, and its outputs are read back from the directory it wrote. docs/python.md has the
whole interface.
"""
from ._core import InputError, PhysicsError, version
from ._scene import Scene
from . import style
from ._commands import (CompareResult, DiagnoseResult, SimulationResult, SweepResult, SynthResult, compare,
                        diagnose, simulate, sweep, synth)

__version__ = version()
__all__ = ["Scene", "simulate", "compare", "diagnose", "synth", "sweep", "SimulationResult", "CompareResult",
           "DiagnoseResult", "SynthResult", "SweepResult", "InputError", "PhysicsError", "version", "style"]

"""viz/paraview/open_run.py against a real run directory, with a stand-in for paraview.simple.

ParaView is not needed to build or test pneufem, so the script cannot be run for real here. This
test runs it end to end against a recording stand-in of the paraview.simple calls it makes, on
the run directory of a tiny `pneufem simulate` (a few seconds), and checks what the stand-in
cannot: that every array the script warps or colours by is in the run's last VTU with the
association the script names, that the state shown is the one that bends most (states.csv), that the stress view's field is the silicone's alone (finite at
every silicone node, NaN at fabric-only nodes, its range far below the fabric's), that the chart's
columns are in angles.csv, and that a half model is mirrored.

    /usr/bin/python3 tests/viz/paraview/test_open_run.py PNEUFEM_EXE WORK_DIR
"""
import csv
import math
import os
import runpy
import shutil
import subprocess
import sys
import types
import xml.etree.ElementTree as ET

import numpy
import vtk
from vtk.util.numpy_support import vtk_to_numpy

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
SCRIPT = os.path.join(REPO, "viz", "paraview", "open_run.py")
TINY = ["--set", "geometry.chambers=2", "--set", "mesh.h_mm=6.0", "--set", "load.max_kPa=5.0", "--set", "load.trials=1"]


class Proxy:
    """A ParaView proxy: properties are plain attributes; methods the stand-in does not define return None."""

    def __init__(self, kind, calls, **props):
        self.__dict__.update(kind=kind, calls=calls, **props)

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return lambda *a, **k: self.calls.append((self.kind + "." + name, a, k))


def stand_in(run, calls):
    """A paraview.simple whose readers report the bounds and times of `run`'s files."""
    pvd_times = [float(d.get("timestep")) for d in ET.parse(os.path.join(run, "results.pvd")).iter("DataSet")]
    bounds = last_grid(run).GetBounds()
    m = types.ModuleType("paraview.simple")

    def record(name, result=None):
        def f(*a, **k):
            calls.append((name, a, k))
            return result() if callable(result) else result
        return f

    def reader(**k):
        calls.append(("PVDReader", (), k))
        info = types.SimpleNamespace(GetBounds=lambda: bounds)
        return Proxy("reader", calls, TimestepValues=pvd_times, GetDataInformation=lambda: info, **k)

    grid = last_grid(run)
    data = {"PointData": grid.GetPointData(), "CellData": grid.GetCellData()}

    class Arrays(dict):
        def __init__(self, kind):
            super().__init__()
            self.kind = kind

        def __missing__(self, name):
            v = array(data[self.kind], name)
            v = v[numpy.isfinite(v)]
            return types.SimpleNamespace(GetRange=lambda: (float(v.min()), float(v.max())))

    def source(name):
        return lambda **k: calls.append((name, (), k)) or Proxy(name, calls, PointData=Arrays("PointData"),
                                                                CellData=Arrays("CellData"), **k)

    layout = Proxy("layout", calls)
    m.PVDReader = reader
    m.WarpByVector = source("WarpByVector")
    m.Reflect = source("Reflect")
    m.CSVReader = source("CSVReader")
    scene = Proxy("scene", calls)
    m.GetAnimationScene = record("GetAnimationScene", scene)
    m.GetActiveViewOrCreate = record("GetActiveViewOrCreate", lambda: Proxy("view", calls))
    m.CreateView = lambda kind: calls.append(("CreateView", (kind,), {})) or Proxy(kind, calls)
    m.GetLayout = record("GetLayout", None)  # as in pvpython: no layout until one is made
    m.CreateLayout = record("CreateLayout", layout)
    m.AssignViewToLayout = record("AssignViewToLayout")

    def show(src, view):
        display = Proxy("display", calls, source=src)
        calls.append(("Show", (src, view), {"display": display}))
        return display

    m.Show = show
    m.ColorBy = record("ColorBy")
    m.GetColorTransferFunction = lambda field: Proxy("lut " + field, calls)
    m.GetScalarBar = lambda lut, view: Proxy("bar", calls)
    for name in ("ResetCamera", "SetActiveView", "Render", "SaveScreenshot"):
        setattr(m, name, record(name))
    return m


def last_grid(run):
    """The run's last reported state, the one the script shows."""
    files = [d.get("file") for d in ET.parse(os.path.join(run, "results.pvd")).iter("DataSet")]
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(os.path.join(run, files[-1]))
    r.Update()
    return r.GetOutput()


def array(data, name):
    a = data.GetArray(name)
    assert a is not None, "no array %s" % name
    return vtk_to_numpy(a)


def check_silicone_field(grid):
    """von_mises_Pa at the points is the silicone's alone: the fabric is in its own range."""
    fabric_cells = ~numpy.isnan(array(grid.GetCellData(), "fabric_von_mises_Pa"))
    silicone_node = [False] * grid.GetNumberOfPoints()
    for c in range(grid.GetNumberOfCells()):
        if not fabric_cells[c]:
            ids = grid.GetCell(c).GetPointIds()
            for i in range(ids.GetNumberOfIds()):
                silicone_node[ids.GetId(i)] = True
    vm = array(grid.GetPointData(), "von_mises_Pa")
    fabric = array(grid.GetPointData(), "fabric_von_mises_Pa")
    assert fabric_cells.any() and not fabric_cells.all(), "the run has both silicone and fabric"
    assert any(not s for s in silicone_node), "some nodes are the fabric's alone"
    for n, s in enumerate(silicone_node):
        assert math.isfinite(vm[n]) == s, "node %d: von_mises_Pa %g, silicone node %s" % (n, vm[n], s)
    vm_max = max(v for v in vm if math.isfinite(v))
    fabric_max = max(v for v in fabric if math.isfinite(v))
    assert vm_max < 0.1 * fabric_max, "silicone max %g Pa vs fabric max %g Pa" % (vm_max, fabric_max)


def main():
    exe, work = sys.argv[1], os.path.abspath(sys.argv[2])
    shutil.rmtree(work, ignore_errors=True)
    run = os.path.join(work, "run")
    subprocess.run([exe, "simulate", *TINY, "--threads", "1", "--out", run], check=True, stdout=subprocess.DEVNULL)

    calls = []
    sys.modules["paraview"] = types.ModuleType("paraview")
    sys.modules["paraview.simple"] = stand_in(run, calls)
    sys.argv = [SCRIPT, run, "--no-screenshot"]
    runpy.run_path(SCRIPT, run_name="__main__")
    names = [c[0] for c in calls]
    assert "Render" in names and "SaveScreenshot" not in names, names

    grid = last_grid(run)
    data = {"POINTS": grid.GetPointData(), "CELLS": grid.GetCellData()}
    assert abs(grid.GetBounds()[0]) < 1e-9, "the default scene is a half model on x = 0"
    shown = [c[1][0] for c in calls if c[0] == "Show"]
    mirrored = [s for s in shown if s.kind == "Reflect"]
    assert mirrored, "the half model is shown unmirrored: %s" % [s.kind for s in shown]
    warp = mirrored[0].Input
    assert warp.kind == "WarpByVector", warp.kind
    association, vectors = warp.Vectors
    warped = array(data[association], vectors)
    assert warped.ndim == 2 and warped.shape[1] == 3, "%s is not a vector field" % vectors
    coloured = [c[1][1] for c in calls if c[0] == "ColorBy"]
    assert ("POINTS", "von_mises_Pa") in coloured and ("CELLS", "damage") in coloured, coloured
    for association, field in coloured:
        assert data[association].GetArray(field) is not None, "%s %s not in the VTU" % (association, field)
    check_silicone_field(grid)

    # The state shown is the one that bends most (states.csv), in every render view and the time slider.
    times = [float(d.get("timestep")) for d in ET.parse(os.path.join(run, "results.pvd")).iter("DataSet")]
    with open(os.path.join(run, "states.csv")) as f:
        angle = {float(r["global_time_s"]): abs(float(r["angle_deg"])) for r in csv.DictReader(f)}
    most_bent = max((t for t in times if t in angle), key=lambda t: (angle[t], t))
    assert sys.modules["paraview.simple"].GetAnimationScene().AnimationTime == most_bent
    render_views = {id(c[1][1]): c[1][1] for c in calls if c[0] == "Show" and c[1][1].kind in ("view", "RenderView")}
    assert len(render_views) == 2, "stress and damage views"
    for view in render_views.values():
        assert view.ViewTime == most_bent, "a view shows t = %s, not the most bent state's %s" % (view.ViewTime, most_bent)

    chart = next(c for c in calls if c[0] == "Show" and c[1][0].kind == "CSVReader")
    with open(chart[1][0].FileName[0]) as f:
        header = next(csv.reader(f))
    line = chart[2]["display"]
    for column in [line.XArrayName, *line.SeriesVisibility]:
        assert column in header, "%s not in angles.csv (%s)" % (column, header)
    print("open_run.py: %d paraview.simple calls; arrays %s; chart columns %s" % (len(calls), coloured, header))


if __name__ == "__main__":
    main()

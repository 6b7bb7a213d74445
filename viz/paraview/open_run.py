"""Opens a pneufem run directory in ParaView with the standard views.

    pvpython viz/paraview/open_run.py out/default            # opens, then saves views.png there
    pvbatch viz/paraview/open_run.py out/default             # no window: views.png only
    paraview --script=viz/paraview/open_run.py                # GUI; run directory from PNEUFEM_RUN
                                                              # or the current directory

Views (the reported state where the actuator bends most, usually the top pressure of the last trial,
from states.csv; the time slider walks through the states of results.pvd):
  * left:  the deformed actuator (Warp By Vector, displacement_m), mirrored about x = 0 when the
           run is a half model, coloured by the silicone's von Mises stress (point data
           von_mises_Pa; the fabric has its own field, fabric_von_mises_Pa, and is left grey);
  * right: the same shape coloured by damage (cell data; its range is 0 to 1 when the run has none);
  * below: angle against pressure from angles.csv, through the reports of all trials in turn.
Colour maps are Viridis (perceptually uniform, readable by colour-blind readers). Needs ParaView
5.9 or later (paraview.simple); pneufem itself does not need ParaView. tests/viz/paraview/test_open_run.py
runs this script against a stand-in for paraview.simple (the arrays it names must be in the run).
"""
import csv
import os
import sys

from paraview.simple import (AssignViewToLayout, ColorBy, CreateLayout, CreateView, CSVReader, GetActiveViewOrCreate,
                             GetAnimationScene, GetColorTransferFunction, GetLayout, GetScalarBar, PVDReader, Reflect,
                             Render, ResetCamera, SaveScreenshot, SetActiveView, Show, WarpByVector)


def run_directory():
    args = [a for a in sys.argv[1:] if not a.startswith("-")]
    return os.path.abspath(args[0] if args else os.environ.get("PNEUFEM_RUN", os.getcwd()))


def most_bent_time(run, times):
    """The time of results.pvd whose state bends most (states.csv's |angle_deg| at the nearest
    global_time_s; the latest of equal ones), or the last time when states.csv cannot tell."""
    path = os.path.join(run, "states.csv")
    if not times or not os.path.exists(path):
        return times[-1] if times else None
    try:
        with open(path) as f:
            rows = [(float(r["global_time_s"]), abs(float(r["angle_deg"]))) for r in csv.DictReader(f)]
    except (KeyError, TypeError, ValueError):  # a states.csv of another layout (an older run): the last state
        rows = []
    if not rows:
        return times[-1]
    angle = {t: min(rows, key=lambda r: abs(r[0] - t))[1] for t in times}
    most = max(angle.values())
    return [t for t in times if angle[t] == most][-1]


def shape(reader):
    """The deformed actuator, mirrored when the run modelled the half x >= 0."""
    warp = WarpByVector(Input=reader)
    warp.Vectors = ["POINTS", "displacement_m"]
    warp.ScaleFactor = 1.0
    reader.UpdatePipeline()
    x_min = reader.GetDataInformation().GetBounds()[0]
    span = reader.GetDataInformation().GetBounds()[1] - x_min
    if abs(x_min) <= 1e-9 * max(span, 1e-12):  # a half model sits on its symmetry plane x = 0
        mirrored = Reflect(Input=warp)
        mirrored.Plane = "X Min"
        mirrored.CopyInput = 1
        return mirrored
    return warp


def coloured(source, view, association, field, title):
    display = Show(source, view)
    ColorBy(display, (association, field))
    lut = GetColorTransferFunction(field)
    lut.ApplyPreset("Viridis (matplotlib)", True)
    lut.NanColor = [0.75, 0.75, 0.75]
    display.RescaleTransferFunctionToDataRange(True, False)
    values = (source.PointData if association == "POINTS" else source.CellData)[field].GetRange()
    if values[1] - values[0] <= 1e-9 * max(abs(values[1]), 1.0):  # one value (no damage): a range that means something
        lut.RescaleTransferFunction(values[0], values[0] + 1.0)
        title += " (%g everywhere)" % values[0]
    display.SetScalarBarVisibility(view, True)
    GetScalarBar(lut, view).Title = title
    view.OrientationAxesVisibility = 1
    return display


def main():
    run = run_directory()
    pvd = os.path.join(run, "results.pvd")
    if not os.path.exists(pvd):
        sys.exit("open_run.py: no results.pvd in %s (run `pneufem simulate --out DIR` with output.vtu other than "
                 "\"none\")" % run)
    reader = PVDReader(FileName=pvd)
    shown = most_bent_time(run, list(reader.TimestepValues or []))
    actuator = shape(reader)
    if shown is not None:
        actuator.UpdatePipeline(shown)  # the colour ranges below are those of the shown state

    stress_view = GetActiveViewOrCreate("RenderView")
    layout = GetLayout(stress_view)
    if layout is None:  # pvpython: views have no layout until given one
        layout = CreateLayout("pneufem")
        AssignViewToLayout(view=stress_view, layout=layout, hint=0)
    damage_view = CreateView("RenderView")
    layout.SplitHorizontal(0, 0.5)
    layout.AssignView(2, damage_view)
    if shown is not None:  # also set below as the scene's time; each view's own, so that the ranges are the shown state's
        stress_view.ViewTime = shown
        damage_view.ViewTime = shown
    coloured(actuator, stress_view, "POINTS", "von_mises_Pa", "von Mises, silicone (Pa)")
    coloured(actuator, damage_view, "CELLS", "damage", "damage")
    for view in (stress_view, damage_view):
        view.CameraPosition = [0.25, -0.15, 0.12]  # metres: in front of the clamped end, above
        view.CameraFocalPoint = [0.0, 0.06, 0.0]
        view.CameraViewUp = [0.0, 0.0, 1.0]
        ResetCamera(view)

    angles = os.path.join(run, "angles.csv")
    if os.path.exists(angles):
        chart = CreateView("XYChartView")
        layout.SplitVertical(1, 0.6)
        layout.AssignView(4, chart)
        table = CSVReader(FileName=[angles])
        line = Show(table, chart)
        line.UseIndexForXAxis = 0
        line.XArrayName = "pressure_kPa"
        line.SeriesVisibility = ["angle_deg"]
        chart.LeftAxisTitle = "bending angle (deg)"
        chart.BottomAxisTitle = "pressure (kPa)"

    scene = GetAnimationScene()  # the time slider walks through the states, starting at the shown one
    scene.UpdateAnimationUsingDataTimeSteps()
    if shown is not None:
        scene.AnimationTime = shown
    SetActiveView(stress_view)
    Render()
    if "--no-screenshot" not in sys.argv and not hasattr(sys, "ps1"):
        try:
            SaveScreenshot(os.path.join(run, "views.png"), layout, ImageResolution=[1600, 1000])
        except Exception as err:  # an on-screen GUI session need not save; say why and go on
            print("open_run.py: views.png not saved (%s)" % err)


main()

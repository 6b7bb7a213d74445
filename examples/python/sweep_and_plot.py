"""A small parameter sweep from Python and its plot (a few seconds): how the silicone's stiffness
(materials.silicone.stiffness_scale) changes the angle at the top of the staircase.

    /usr/bin/python3 examples/python/sweep_and_plot.py [OUT_DIR]

Writes OUT_DIR/sweep/ (as `pneufem sweep` writes it) and OUT_DIR/sweep.png.
"""
import pathlib
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import pneufem
from pneufem import style

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "out/python_example")
scene = pneufem.Scene.defaults().update({
    "geometry.chambers": 2, "mesh.h_mm": 6.0, "mesh.element": "tet10", "load.max_kPa": 5.0,
})
key = "materials.silicone.stiffness_scale"
sweep = pneufem.sweep(scene, param=f"{key}=0.8:1.2:3", out=out / "sweep", jobs=2, model="full")

scales, top_angles = [], []
for row in sweep.table:
    run = sweep.point(int(row["point"]))  # each point's run directory, read back
    scales.append(run.scene[key])
    top_angles.append(run.angles["angle_deg"].max())
style.use()  # pneufem's figures' palette (Okabe & Ito, colour-blind safe)
fig, ax = plt.subplots(figsize=(5, 4))
ax.plot(scales, top_angles, "o-", color=style.color(0))
ax.set(xlabel="silicone stiffness scale", ylabel="angle at the top (deg)")
fig.tight_layout()
fig.savefig(out / "sweep.png", dpi=100)
print(f"{sweep.ok} points: angle at the top {np.round(top_angles, 3).tolist()} deg; figure {out / 'sweep.png'}")

"""Simulate a small pneu-net from Python and plot its bending angle (a few seconds).

    /usr/bin/python3 examples/python/simulate_and_plot.py [OUT_DIR]

Writes OUT_DIR/run/ (the run directory, as `pneufem simulate` writes it) and OUT_DIR/angles.png.
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
    "geometry.chambers": 3, "mesh.h_mm": 6.0,           # a small, coarse actuator: seconds
    "load.max_kPa": 15.0, "load.step_kPa": 5.0, "load.trials": 2,
    "materials.silicone.viscoelastic.enabled": True,    # creep during the holds
})
run = pneufem.simulate(scene, out=out / "run", threads=2)

style.use()  # pneufem's figures' palette (Okabe & Ito, colour-blind safe)
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
for k, trial in enumerate(np.unique(run.angles["trial"])):
    rows = run.states[run.states["trial"] == trial]
    c = style.color(k)  # one colour per trial in both panels
    ax1.plot(rows["time_s"], rows["angle_deg"], color=c, label=f"trial {trial}")
    ax2.plot(rows["pressure_kPa"], rows["angle_deg"], "o-", color=c, label=f"trial {trial}")
ax1.set(xlabel="time in trial (s)", ylabel="bending angle (deg)")
ax2.set(xlabel="pressure (kPa)", ylabel="bending angle (deg)")
ax1.legend()
last = run.fields()  # the last reported state: numpy arrays on the mesh
tip = np.linalg.norm(last.displacement, axis=1).max()
fig.suptitle(f"{run.summary['mesh']['elements']} elements; at {last.pressure_kPa:g} kPa the largest "
             f"displacement is {tip * 1e3:.2f} mm, the largest von Mises stress {np.nanmax(last.cell_data['von_mises_Pa']) / 1e3:.1f} kPa")
fig.tight_layout()
fig.savefig(out / "angles.png", dpi=100)
print(f"angle at {run.angles['pressure_kPa'].max():g} kPa: {run.angles['angle_deg'].max():.2f} deg; "
      f"figure {out / 'angles.png'}, run {run.run_dir}")

"""The verification manual's figure of CalculixReference.GmshDeckBendsAsCalculixSolvesIt: the default
pneu-net meshed by gmsh (tests/data/ccx_gmsh/, a deck pneufem did not make), bent by CalculiX 2.20
(ccx_angles.csv, every 1 kPa) and by pneufem (`pneufem simulate tests/data/ccx_gmsh/scene.toml`, every
5 kPa), with their relative difference. Writes the SVG and, beside it, every plotted series as CSV.
Made by docs/figures/make_figures.sh; Debian's python3 with matplotlib (a test dependency).

    /usr/bin/python3 docs/figures/calculix_gmsh.py RUN_DIR/angles.csv docs/figures/verification_calculix_gmsh.svg
"""
import csv
import sys

import matplotlib

matplotlib.use("svg")
import matplotlib.pyplot as plt  # noqa: E402

REFERENCE = "tests/data/ccx_gmsh/ccx_angles.csv"
BLUE, BLACK, VERMILION = "#0072B2", "#000000", "#D55E00"  # Okabe & Ito, as viz/svg_plot.h


def read(path, x, y):
    with open(path) as f:
        return [(float(r[x]), float(r[y])) for r in csv.DictReader(f)]


def main():
    run_angles, out_svg = sys.argv[1], sys.argv[2]
    ccx = read(REFERENCE, "pressure_kPa", "angle_planefit_deg")
    pneufem = sorted(dict(read(run_angles, "pressure_kPa", "angle_deg")).items())  # one angle per level
    at = dict(ccx)
    steps = [(p, a) for p, a in pneufem if p > 0 and p in at]
    diff = [(p, 100.0 * (a - at[p]) / at[p]) for p, a in steps]

    plt.rcParams.update({"svg.hashsalt": "pneufem", "font.size": 8, "font.family": "DejaVu Sans"})
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(3.5, 3.6), sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    top.plot([p for p, _ in ccx if p <= 45], [a for p, a in ccx if p <= 45], color=BLACK, lw=1.0, label="CalculiX 2.20")
    top.plot([p for p, _ in pneufem], [a for _, a in pneufem], "o", color=BLUE, ms=3.5, label="pneufem")
    top.set_ylabel("bending angle (deg)")
    top.set_ylim(bottom=0)
    top.legend(frameon=False, loc="upper left")
    bottom.plot([p for p, _ in diff], [d for _, d in diff], "o-", color=VERMILION, ms=3, lw=1.0)
    bottom.axhline(0.0, color="#999999", lw=0.6)
    bottom.set_ylabel("pneufem − CalculiX (%)")
    bottom.set_xlabel("pressure (kPa)")
    bottom.set_xlim(0, 46)
    for ax in (top, bottom):
        ax.spines[["top", "right"]].set_visible(False)
    fig.tight_layout()
    fig.savefig(out_svg, metadata={"Date": None})

    with open(out_svg[:-4] + ".csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["series", "pressure_kPa", "value", "unit"])
        w.writerows([["CalculiX 2.20", repr(p), repr(a), "deg"] for p, a in ccx if p <= 45])
        w.writerows([["pneufem", repr(p), repr(a), "deg"] for p, a in pneufem])
        w.writerows([["pneufem - CalculiX", repr(p), repr(d), "percent"] for p, d in diff])
    print("largest |pneufem - CalculiX|: %.3f %% (at %g kPa)" % max((abs(d), p) for p, d in diff))


main()

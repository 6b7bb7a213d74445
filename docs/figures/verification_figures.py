"""Figures of the verification manual (docs/verification.md), each a test against its truth:

    cylinder    CylinderInflation.ObservedConvergenceOrderOfTet10: the bore's error against the
                incompressible solution under refinement, with the O(h^2) slope
    creep       Creep.HomogeneousBlockFollowsTheStandardLinearSolid and
                Creep.InstantaneousModuliStartOnTheElasticStrainAndCreepBeyondIt: the block's strain
                against the standard linear solid, in both moduli conventions
    derivative  MaterialBattery.TangentDifferenceErrorIsAVInTheStep: the tangent's
                central-difference error against the step, for every law, with the battery's step
    mullins     Mullins.UniaxialLoadUnloadReloadMatchesOgdenRoxburgh1D: load, unload, reload and
                further load against the 1-D Ogden-Roxburgh curve
    fatigue     Fatigue.ConstantDriverMatchesExactSolutionAtFirstOrder and
                Fatigue.SaturatingLawSolvesItsUpdateAndConvergesToTheExactSolution: the integrity's
                error against the number of steps (first order), n = 1 and n = 3
    energy      Explicit.UndampedFreeVibrationConservesEnergyWithoutDrift: the cantilever's kinetic
                and strain energy over three periods of free vibration, and their sum
    lag         PressureLag2.BreakpointsMeetTheToleranceWithoutWaste: the chamber pressure behind a
                step and a ramp of the inlet, closed forms and the emitted breakpoints, three regimes
    jump        CycleJump.ThreePointRuleBeatsTheLinearOneForGeometricIncrements: the error of a
                one-cycle jump by either rule against the ratio of successive increments
    calculix    the default actuator on pneufem's own mesh (h = 4 and 2 mm) against CalculiX 2.20,
                from the cross-check's results in bench/results/ccx_h4 and ccx_h2

All but calculix read the lines the tests print ("cylinder level: ...", "creep series ...",
"fd series ...", "mullins series ...", "fatigue series ...", "energy series ...", "lag ...", "jump series ..."); calculix reads committed results. Each writes the SVG and, beside it, every
plotted series as CSV. Made by docs/figures/make_figures.sh; Debian's python3 with matplotlib.

    /usr/bin/python3 docs/figures/verification_figures.py cylinder TEST_OUTPUT.txt OUT.svg
    /usr/bin/python3 docs/figures/verification_figures.py calculix OUT.svg
"""
import csv
import json
import math
import re
import sys

import matplotlib

matplotlib.use("svg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

# Okabe & Ito, as viz/svg_plot.h
BLACK, ORANGE, SKY, GREEN, YELLOW, BLUE, VERMILION, PURPLE = (
    "#000000", "#E69F00", "#56B4E9", "#009E73", "#F0E442", "#0072B2", "#D55E00", "#CC79A7")
GREY = "#999999"
EPS = 2.0 ** -52


def style():
    plt.rcParams.update({"svg.hashsalt": "pneufem", "font.size": 8, "font.family": "DejaVu Sans"})


def finish(fig, axes, out_svg):
    for ax in axes:
        ax.spines[["top", "right"]].set_visible(False)
    fig.tight_layout()
    fig.savefig(out_svg, metadata={"Date": None})


def write_csv(out_svg, header, rows):
    with open(out_svg[:-4] + ".csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)


def fields(path, prefix):
    """The lines of a test's output that start with `prefix`, as (rest-of-prefix, {name: value})."""
    out = []
    with open(path) as f:
        for line in f:
            if line.startswith(prefix):
                head, _, rest = line[len(prefix):].partition(":")
                words = rest.split()
                out.append((head.strip(), {words[i]: float(words[i + 1]) for i in range(0, len(words) - 1, 2)}))
    if not out:
        sys.exit("%s: no line starts with %r" % (path, prefix))
    return out


def cylinder(test_output, out_svg):
    levels = [v for _, v in fields(test_output, "cylinder level")]
    h = [v["h_m"] * 1e3 for v in levels]
    err = [v["error"] for v in levels]
    style()
    fig, ax = plt.subplots(figsize=(3.5, 2.6))
    ax.loglog(h, err, "o-", color=BLUE, ms=4, lw=1.0, label="Tet10, bore displacement")
    slope = [err[0] * (x / h[0]) ** 2 for x in h]
    ax.loglog(h, slope, "--", color=GREY, lw=0.8, label="slope 2 (O(h²))")
    for x, e, v in zip(h, err, levels):
        ax.annotate("%d cell%s" % (v["cells_through_wall"], "" if v["cells_through_wall"] == 1 else "s"), (x, e),
                    textcoords="offset points", xytext=(5, -2), ha="left", va="top", fontsize=7)
    ax.set_xlim(0.8 * h[-1], 1.6 * h[0])
    ax.set_xticks(h, ["%g" % x for x in h])
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    orders = [math.log(err[i] / err[i + 1]) / math.log(h[i] / h[i + 1]) for i in range(len(h) - 1)]
    ax.set_xlabel("element size through the wall (mm)")
    ax.set_ylabel("relative error of the bore")
    ax.set_title("observed orders " + ", ".join("%.2f" % o for o in orders), fontsize=8)
    ax.legend(frameon=False, loc="upper left")
    finish(fig, [ax], out_svg)
    write_csv(out_svg, ["series", "cells_through_wall", "h_mm", "bore_m", "exact_m", "relative_error"],
              [["Tet10", int(v["cells_through_wall"]), repr(x), repr(v["bore_m"]), repr(v["exact_m"]), repr(e)]
               for x, e, v in zip(h, err, levels)]
              + [["slope 2", int(v["cells_through_wall"]), repr(x), "", "", repr(s)] for x, s, v in zip(h, slope, levels)])
    print("cylinder: errors %s, observed orders %s" % (["%.3e" % e for e in err], ["%.2f" % o for o in orders]))


def creep(test_output, out_svg):
    series = {}
    for name, v in fields(test_output, "creep series"):
        series.setdefault(name, []).append((v["t_s"], v["strain"], v["sls"]))
    style()
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(3.5, 3.6), sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    colours = {"long_term": BLUE, "instantaneous": VERMILION}
    rows = []
    for name, rs in series.items():
        c, final = colours.get(name, BLACK), max(r[2] for r in rs)
        t = [r[0] for r in rs]
        top.plot(t, [r[2] * 1e4 for r in rs], "-", color=c, lw=1.0, label="standard linear solid, " + name.replace("_", "-"))
        top.plot(t, [r[1] * 1e4 for r in rs], "o", color=c, ms=2.5, mfc="none", mew=0.8, label="pneufem, " + name.replace("_", "-"))
        bottom.plot(t, [100.0 * (r[1] - r[2]) / final for r in rs], "o-", color=c, ms=2.5, lw=0.8)
        rows += [[name, repr(a), repr(b), repr(s), repr(100.0 * (b - s) / final)] for a, b, s in rs]
    top.set_ylabel("strain (10⁻⁴)")
    top.set_ylim(bottom=0)
    top.legend(frameon=False, loc="lower right", fontsize=6.5)
    bottom.axhline(0.0, color=GREY, lw=0.6)
    bottom.axhline(0.5, color=GREY, lw=0.6, ls=":")
    bottom.set_ylabel("error (% of final)")
    bottom.set_xlabel("time under constant stress (s)")
    bottom.set_xlim(left=0)
    finish(fig, [top, bottom], out_svg)
    write_csv(out_svg, ["moduli", "t_s", "pneufem_strain", "sls_strain", "error_percent_of_final"], rows)
    worst = max(abs(float(r[4])) for r in rows)
    print("creep: worst error %.3f %% of the final strain (tolerance 0.5 %%)" % worst)


def derivative(test_output, out_svg):
    series = {}
    for name, v in fields(test_output, "fd series"):
        series.setdefault(name, []).append((v["step"], v["error"]))
    battery = {name: v for name, v in fields(test_output, "fd battery")}
    style()
    fig, ax = plt.subplots(figsize=(3.5, 2.9))
    palette = [BLUE, VERMILION, GREEN, ORANGE, PURPLE, SKY, BLACK, YELLOW, GREY]
    rows = []
    for (name, pts), c in zip(sorted(series.items()), palette):
        ax.loglog([s for s, _ in pts], [max(e, 1e-17) for _, e in pts], "-", color=c, lw=0.9, label=name.replace("_", " "))
        rows += [[name, repr(s), repr(e)] for s, e in pts]
    step = next(iter(battery.values()))["step"]
    ax.axvline(step, color=GREY, lw=0.6, ls=":")
    ax.axhline(1e-7, color=GREY, lw=0.6, ls="--")
    ax.annotate("battery's step ∛ε", (step, 1e-13), textcoords="offset points", xytext=(3, 2), fontsize=7)
    ax.annotate("tolerance 1e-7", (1e-7, 1e-7), textcoords="offset points", xytext=(0, 3), fontsize=7)
    ax.set_xlabel("step h / s (s: the RMS stretch)")
    ax.set_ylabel("tangent error / M")
    ax.legend(frameon=False, fontsize=6, ncol=2, loc="upper left")
    ax.set_ylim(1e-13, 1e4)
    finish(fig, [ax], out_svg)
    rows += [[name + " (battery's step)", repr(v["step"]), repr(v["error"])] for name, v in sorted(battery.items())]
    write_csv(out_svg, ["law", "step_over_s", "tangent_error_over_M"], rows)
    print("derivative: at the battery's step, worst %.2e of M (tolerance 1e-7)" % max(v["error"] for v in battery.values()))


def mullins(test_output, out_svg):
    legs = {}
    for name, v in fields(test_output, "mullins series"):
        legs.setdefault(name, []).append((v["stretch"], v["P11_Pa"] / 1e3, v["reference_Pa"] / 1e3, v["elastic_Pa"] / 1e3))
    style()
    fig, ax = plt.subplots(figsize=(3.5, 2.8))
    colours = [BLUE, VERMILION, GREEN, PURPLE]
    markers = ["o", "v", "^", "s"]
    rows, elastic = [], sorted({(r[0], r[3]) for rs in legs.values() for r in rs})
    ax.plot([x for x, _ in elastic], [p for _, p in elastic], "-", color=GREY, lw=0.8, label="elastic base (Yeoh)")
    for (name, rs), c, m in zip(legs.items(), colours, markers):
        ax.plot([r[0] for r in rs], [r[2] for r in rs], "-", color=c, lw=1.0)
        ax.plot([r[0] for r in rs], [r[1] for r in rs], m, color=c, ms=3, mfc="none", mew=0.8, label=name.replace("->", "→"))
        rows += [[name, repr(a), repr(b * 1e3), repr(r * 1e3), repr(e * 1e3)] for a, b, r, e in rs]
    ax.set_xlabel("stretch λ")
    ax.set_ylabel("nominal stress P₁₁ (kPa)")
    ax.set_xlim(1.0, None)
    ax.set_ylim(bottom=0)
    ax.legend(frameon=False, loc="upper left", fontsize=7, title="pneufem (markers), 1-D reference (lines)", title_fontsize=7)
    finish(fig, [ax], out_svg)
    write_csv(out_svg, ["leg", "stretch", "pneufem_P11_Pa", "reference_P11_Pa", "elastic_P11_Pa"], rows)
    worst = max(abs(float(r[2]) - float(r[3])) for r in rows) / max(abs(float(r[3])) for r in rows)
    print("mullins: largest |pneufem - reference| %.1e of the largest stress" % worst)


def fatigue(test_output, out_svg):
    series = {}
    for name, v in fields(test_output, "fatigue series"):
        series.setdefault(name, []).append(v)
    style()
    fig, ax = plt.subplots(figsize=(3.5, 2.7))
    rows = []
    for (name, vs), c in zip(sorted(series.items()), (BLUE, VERMILION)):
        n = [v["steps"] for v in vs]
        err = [abs(v["integrity"] - v["exact"]) for v in vs]
        ax.loglog(n, err, "o-", color=c, ms=3.5, lw=1.0, label="backward Euler, " + name)
        if "leading" in vs[0]:
            ax.loglog(n, [v["leading"] for v in vs], "--", color=GREY, lw=0.8, label="leading term s (gT/τ)² / 2N")
        rows += [[name, int(v["steps"]), repr(v["integrity"]), repr(v["exact"]), repr(e), repr(v.get("leading", ""))]
                 for v, e in zip(vs, err)]
    ax.set_xticks([10, 20, 40, 80, 160, 320], ["10", "20", "40", "80", "160", "320"])
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlabel("steps N over the history")
    ax.set_ylabel("|integrity − exact|")
    ax.legend(frameon=False, loc="lower left", fontsize=7)
    finish(fig, [ax], out_svg)
    write_csv(out_svg, ["law", "steps", "integrity", "exact", "abs_error", "leading_term"], rows)
    for name, vs in sorted(series.items()):
        e = [abs(v["integrity"] - v["exact"]) for v in vs]
        print("fatigue %s: observed order on the finest pair %.3f" % (name, math.log2(e[-2] / e[-1])))


def energy(test_output, out_svg):
    pts = [v for _, v in fields(test_output, "energy series")]
    t = [v["t_over_T"] for v in pts]
    ke, ie = [v["kinetic_over_E0"] for v in pts], [v["internal_over_E0"] for v in pts]
    dev = [100.0 * (k + i - 1.0) for k, i in zip(ke, ie)]
    style()
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(3.5, 3.6), sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    top.plot(t, ie, "-", color=BLUE, lw=1.0, label="strain energy")
    top.plot(t, ke, "-", color=VERMILION, lw=1.0, label="kinetic energy")
    top.plot(t, [k + i for k, i in zip(ke, ie)], "-", color=BLACK, lw=1.0, label="sum")
    top.set_ylabel("energy / initial energy")
    top.set_ylim(0, 1.25)
    top.legend(frameon=False, loc="upper center", ncol=3, fontsize=7)
    bottom.plot(t, dev, "-", color=BLACK, lw=0.8)
    for y in (0.3, -0.3):
        bottom.axhline(y, color=GREY, lw=0.6, ls=":")
    bottom.axhline(0.0, color=GREY, lw=0.6)
    bottom.set_ylabel("sum − 1 (%)")
    bottom.set_xlabel("time / first period")
    bottom.set_xlim(0, max(t))
    finish(fig, [top, bottom], out_svg)
    write_csv(out_svg, ["t_over_T", "kinetic_over_E0", "internal_over_E0", "sum_minus_1_percent"],
              [[repr(a), repr(k), repr(i), repr(d)] for a, k, i, d in zip(t, ke, ie, dev)])
    print("energy: largest |sum - 1| %.3f %% (tolerance 0.3 %%)" % max(abs(d) for d in dev))


def lag(test_output, out_svg):
    exact, points = {}, {}
    for name, v in fields(test_output, "lag exact"):
        exact.setdefault(name, []).append(v)
    for name, v in fields(test_output, "lag breakpoint"):
        points.setdefault(name, []).append(v)
    style()
    fig, axes = plt.subplots(2, 1, figsize=(3.5, 4.0), sharex=True)
    regimes = sorted({n.split(" trial")[0] for n in exact})  # "zeta 0.450", "zeta 1.000", "zeta 1.250"
    rows = []
    for ax, trial, title in ((axes[0], "1", "a step of 5 kPa at 1 s"), (axes[1], "0", "a ramp to 10 kPa over 2 s, then a hold")):
        inlet = exact[regimes[0] + " trial " + trial]
        ax.plot([v["t_s"] for v in inlet], [v["inlet_Pa"] / 1e3 for v in inlet], "--", color=GREY, lw=0.8, label="inlet")
        for regime, c in zip(regimes, (BLUE, VERMILION, GREEN)):
            key = regime + " trial " + trial
            label = "ζ = " + regime.split()[1].rstrip("0").rstrip(".")
            ax.plot([v["t_s"] for v in exact[key]], [v["p_Pa"] / 1e3 for v in exact[key]], "-", color=c, lw=1.0,
                    label=label)
            ax.plot([v["t_s"] for v in points[key]], [v["p_Pa"] / 1e3 for v in points[key]], "o", color=c, ms=2.2,
                    mfc="none", mew=0.7)
            rows += [[key, "closed form", repr(v["t_s"]), repr(v["p_Pa"]), repr(v["inlet_Pa"])] for v in exact[key]]
            rows += [[key, "breakpoint", repr(v["t_s"]), repr(v["p_Pa"]), ""] for v in points[key]]
        ax.set_title(title, fontsize=8)
        ax.set_ylabel("chamber pressure (kPa)")
        ax.set_ylim(bottom=0)
    axes[1].legend(*axes[0].get_legend_handles_labels(), frameon=False, loc="lower right", fontsize=7,
                   title="lines: closed form\ncircles: breakpoints", title_fontsize=7)
    axes[1].set_xlabel("time (s)")
    axes[1].set_xlim(0, 6)
    finish(fig, axes, out_svg)
    write_csv(out_svg, ["regime_and_trial", "series", "t_s", "pressure_Pa", "inlet_Pa"], rows)
    print("lag: %d regimes, %s breakpoints per trial" % (len(regimes), sorted(len(v) for v in points.values())))


def jump(test_output, out_svg):
    pts = [v for _, v in fields(test_output, "jump series")]
    r = [v["r"] for v in pts]
    style()
    fig, ax = plt.subplots(figsize=(3.5, 2.7))
    for key, name, c, m in (("linear", "linear rule (1)", VERMILION, "s"), ("three_point", "three-point rule (1′)", BLUE, "o")):
        ax.semilogy(r, [v[key + "_analytic"] for v in pts], "-", color=c, lw=1.0, label=name + ", analytic")
        ax.semilogy(r, [v[key] for v in pts], m, color=c, ms=3.5, mfc="none", mew=0.9, label=name + ", computed")
    ax.axvline(1.0, color=GREY, lw=0.6, ls=":")
    ax.set_xlabel("ratio r of successive per-cycle increments")
    ax.set_ylabel("jump error / last increment")
    ax.legend(frameon=False, loc="lower right", fontsize=6.5)
    ax.set_ylim(1e-3, 10)
    finish(fig, [ax], out_svg)
    write_csv(out_svg, ["r", "three_point", "linear", "three_point_analytic", "linear_analytic"],
              [[repr(v["r"]), repr(v["three_point"]), repr(v["linear"]), repr(v["three_point_analytic"]),
                repr(v["linear_analytic"])] for v in pts])
    print("jump: %d ratios, the three-point rule smaller at every one: %s" % (len(pts), all(v["three_point"] < v["linear"] for v in pts)))


def calculix(out_svg):
    style()
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(3.5, 3.6), sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    rows = []
    for h, c in (("4", ORANGE), ("2", BLUE)):
        with open("bench/results/ccx_h%s/crosscheck.json" % h) as f:
            pts = [(0.0, 0.0, 0.0)] + [(r["p_kPa"], r["ccx_deg"], r["pneufem_deg"]) for r in json.load(f)["rows"]]
        p = [x for x, _, _ in pts]
        top.plot(p, [a for _, a, _ in pts], "-", color=c, lw=1.0, label="CalculiX 2.20, h = %s mm" % h)
        top.plot(p[1:], [b for _, _, b in pts[1:]], "o", color=c, ms=3.5, mfc="none", mew=0.9, label="pneufem, h = %s mm" % h)
        diff = [(x, 100.0 * (b - a) / a) for x, a, b in pts[1:]]
        bottom.plot([x for x, _ in diff], [d for _, d in diff], "o-", color=c, ms=3, lw=1.0)
        rows += [["h = %s mm" % h, repr(x), repr(a), repr(b), repr(100.0 * (b - a) / a) if x else ""] for x, a, b in pts]
    top.set_ylabel("bending angle (deg)")
    top.set_ylim(bottom=0)
    top.legend(frameon=False, loc="upper left", fontsize=7)
    bottom.axhline(0.0, color=GREY, lw=0.6)
    bottom.set_ylabel("pneufem − CalculiX (%)")
    bottom.set_xlabel("pressure (kPa)")
    bottom.set_xlim(0, 46)
    finish(fig, [top, bottom], out_svg)
    write_csv(out_svg, ["mesh", "pressure_kPa", "calculix_deg", "pneufem_deg", "pneufem_minus_calculix_percent"], rows)
    print("calculix: largest |pneufem - CalculiX| %.3f %%" % max(abs(float(r[4])) for r in rows if r[4]))


def main():
    what = sys.argv[1] if len(sys.argv) > 1 else ""
    makers = {"cylinder": cylinder, "creep": creep, "derivative": derivative, "mullins": mullins, "fatigue": fatigue,
              "energy": energy, "lag": lag, "jump": jump,
              "calculix": calculix}
    if what not in makers:
        sys.exit(__doc__)
    makers[what](*sys.argv[2:])


main()

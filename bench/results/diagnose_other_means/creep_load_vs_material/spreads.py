# Per-level creep (2.5 s mark -> end of hold, summed over the three trials) and 2.5 s-mark error of
# the full FEM at two viscoelastic constant pairs, against the creep recording made by other means
# (make_recordings.py --effect creep: quasi-linear viscoelasticity in the LOAD, g = 0.08, tau = 6 s).
#   metrics_fitted.csv        pneufem compare fitted.toml           (diagnose's gamma 0.0203, tau 9.46 s)
#   metrics_load_analogy.csv  ... --set gamma=[0.087] tau_s=[6.0]   (g/(1-g), the load analogy's gamma)
# usage: python3 spreads.py   (stdlib only)
import csv, collections, os
here = os.path.dirname(os.path.abspath(__file__))
runs = {"load analogy (0.087, 6 s)": "metrics_load_analogy.csv", "diagnosed (0.0203, 9.46 s)": "metrics_fitted.csv"}
meas = collections.defaultdict(float); model = {k: collections.defaultdict(float) for k in runs}
mark = {k: collections.defaultdict(list) for k in runs}
for name, f in runs.items():
    for r in csv.DictReader(open(os.path.join(here, f))):
        L = round(float(r["level_kPa"]))
        if L <= 0: continue
        if name == next(iter(runs)): meas[L] += float(r["spread_measured_deg"])
        model[name][L] += float(r["spread_model_deg"])
        mark[name][L].append(float(r["model_mark_deg"]) - float(r["measured_mark_deg"]))
print("level_kPa  creep_measured_deg  " + "  ".join("creep/ratio/mark_err[%s]" % n for n in runs))
for L in sorted(meas):
    cells = ["%6.2f %5.2f %+6.2f" % (model[n][L], model[n][L] / meas[L], sum(mark[n][L]) / len(mark[n][L])) for n in runs]
    print("%5d %10.2f      " % (L, meas[L]) + "      ".join(cells))

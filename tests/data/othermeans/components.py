#!/usr/bin/env python3
"""Per-trial size of each hidden effect of a recording made by make_recordings.py (noise-free).

For each trial: the angle at the end of its top hold and at the end of its first (0 kPa) hold,
from the whole model minus the model without that effect (the lag stays in every model, as the
diagnosis fits it first or beside the others). What grows from trial to trial is the signature
a diagnosis has to leave to the right effect (bench/notes/2026-11-29-diag5.md).
Usage: /usr/bin/python3 tests/data/othermeans/components.py NAME   (e.g. creep_fatigue_lag)
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_recordings as mr  # noqa: E402


def main(name):
    spec = mr.RECORDINGS[name]
    theta_e = mr.Elastic(*mr.load_curve(spec.get("curve", "small_h6")))
    t, u, trial = mr.commanded(spec["protocol"])
    rig = spec["rig"]
    p_in = mr.second_order(u, rig["regulator_hz"], rig["regulator_zeta"])
    lag = spec["effects"].get("lag")
    if lag is None:
        pc = p_in
    elif lag["form"] == "first_order":
        pc = mr.first_order(p_in, lag["tau_s"])
    else:
        pc = mr.second_order(p_in, lag["f_n_hz"], lag["zeta"])
    p_ref = max(max(tr["levels"]) for tr in spec["protocol"]["trials"])
    hidden = {k: v for k, v in spec["effects"].items() if k != "lag"}
    full = mr.structure(t, pc, theta_e, hidden, p_ref)
    ends = []  # (rest end, top end) sample index per trial
    for k, tr in enumerate(spec["protocol"]["trials"]):
        idx = np.nonzero(trial == k)[0]
        hold = int(round(tr["hold_s"] / mr.DT))
        ends.append((idx[0] + hold - 1, idx[0] + hold * len(tr["levels"]) - 1))
    print("%s: angle (deg) each effect adds, per trial, at the end of the top hold / of the 0 kPa hold" % name)
    for effect in hidden:
        without = mr.structure(t, pc, theta_e, {k: v for k, v in hidden.items() if k != effect}, p_ref)
        d = full - without
        print("  %-8s " % effect + "  ".join("%6.3f/%6.3f" % (d[b], d[a]) for a, b in ends))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "creep_fatigue_lag")
